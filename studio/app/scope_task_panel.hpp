#pragma once
/// The "Laparoscope and task" panel [issue 57 item 1]: the case's laparoscope (its port: position,
/// insertion range, angle limit, shaft length; the optic, 0° or 30°; the field of view; the master
/// that steers it; its motion scale; the tip at rest, which sets the start view) and the task the
/// trainee is shown (the case title, the instructions, the ordered steps). Every typed value is one
/// undo step through Document::editLaparoscope / editTask, checked by the scene reader's rules; a
/// refused value shows the rule under the fields and the field shows the model's value again.
///
/// "Set scope view from here" takes the studio viewport's camera (eye E, looking at its target T)
/// and sets the scope's rest tip, one undo step. The rule: the shaft runs from the port P towards
/// where the camera looks, d = (T − P)/|T − P|, and the tip lies on it as deep as the eye,
///   tip = P + d · clamp((E − P)·d, insertion min, insertion max),
/// so the rest tip is always within the port's insertion (restTipError holds) and a 0° optic then
/// looks at T; a 30° optic looks 30° below that line (towards the scene's −z), as in the player.
/// Refused (model unchanged) when the camera looks at the port itself (|T − P| < 1 mm).
/// Checking "Case has a laparoscope" gives a scope whose port lies 0.15 m above the camera's target
/// and whose tip is 0.08 m below the port (the defaults of laparoscope.hpp otherwise).
#include "sim/scene/laparoscope.hpp"

#include <QString>
#include <QWidget>

#include <functional>
#include <optional>

class QCheckBox;
class QComboBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QPushButton;

namespace viscera::studio {

class Document;
class Viewport;

/// The rest tip "Set scope view from here" sets (the rule above); nullopt with `why` set when the
/// camera looks at the port.
std::optional<sim::Vec3> scopeTipFromView(const sim::PortDesc& port, const sim::Vec3& eye, const sim::Vec3& target,
                                          QString& why);

class ScopeTaskPanel : public QWidget {
    Q_OBJECT
public:
    /// `viewport`: the studio's viewport now (non-owning; null or no function: none), whose camera
    /// "Set scope view from here" reads (the main window makes a new one when its host changes).
    ScopeTaskPanel(Document* doc, std::function<const Viewport*()> viewport, QWidget* parent = nullptr);

    /// The number fields, by key: port_x, port_y, port_z, insertion_min, insertion_max,
    /// max_angle_deg, shaft_length, fov_deg, motion_scale, tip_x, tip_y, tip_z (object names too).
    QLineEdit* field(const QString& key) const;
    QCheckBox* presentBox() const { return m_present; }
    QComboBox* opticBox() const { return m_optic; }
    QComboBox* handBox() const { return m_hand; }
    QPushButton* setViewButton() const { return m_setView; }
    QLineEdit* titleField() const { return m_title; }
    QLineEdit* instructionsField() const { return m_instructions; }
    QListWidget* stepsList() const { return m_steps; }
    QPushButton* addStepButton() const { return m_addStep; }
    QPushButton* removeStepButton() const { return m_removeStep; }
    QPushButton* stepUpButton() const { return m_stepUp; }
    QPushButton* stepDownButton() const { return m_stepDown; }
    QLabel* errorLabel() const { return m_error; }

    /// The camera's pose into the scope's rest tip (the rule above), one undo step. Returns the
    /// error shown, empty when done.
    QString setScopeViewFromCamera();

private:
    void buildScope();
    void buildTask();
    /// The model's laparoscope and task into the fields.
    void fill();
    /// A number field the user finished: that value into a copy of the scope, then the edit.
    void numberTyped(const QString& key);
    void presentToggled(bool on);
    /// The scope with its optic and hand from the combos.
    void choiceChanged();
    void editScope(const sim::LaparoscopeDesc& next, const QString& what);
    /// The title, the instructions and the list's steps (empty items dropped) as one edit.
    void taskTyped();
    void moveStep(int by);
    /// Shows `why` (empty: accepted); a refusal puts the model's values back in the fields.
    void apply(const QString& why);

    Document* m_doc;
    std::function<const Viewport*()> m_viewport;
    const Viewport* viewport() const { return m_viewport ? m_viewport() : nullptr; }
    QCheckBox* m_present = nullptr;
    QComboBox* m_optic = nullptr;
    QComboBox* m_hand = nullptr;
    QPushButton* m_setView = nullptr;
    QWidget* m_scopeFields = nullptr;
    QLineEdit* m_title = nullptr;
    QLineEdit* m_instructions = nullptr;
    QListWidget* m_steps = nullptr;
    QPushButton *m_addStep = nullptr, *m_removeStep = nullptr, *m_stepUp = nullptr, *m_stepDown = nullptr;
    QLabel* m_error = nullptr;
    bool m_filling = false;
};

} // namespace viscera::studio
