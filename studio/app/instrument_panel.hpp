#pragma once
/// The "Instruments" panel [issue 57 item 1]: the scene's instruments (name, kind, master hand),
/// Add (a grasper, an energy hook or a clip applier: Document::addInstrument, a grasper on the
/// left master, the others on the right), Remove, and the selected instrument's fields: its name;
/// the hook's temperature; the clip applier's target (a tet body); radius and jaw length; the
/// master that drives it (hand, motion scale, force scale, maximum force, damage threshold: empty
/// for none, the assessment's threshold then applies); its trocar port (position, insertion range,
/// angle limit, shaft length, laparoscopic or robotic mode). Every typed value is one undo step
/// through Document::editInstrument, checked by the scene reader's rules; a refused value shows
/// the rule under the fields and the field shows the model's value again.
#include "sim/scene/interaction.hpp"

#include <QString>
#include <QWidget>

#include <functional>

class QComboBox;
class QFormLayout;
class QLabel;
class QLineEdit;
class QListWidget;
class QPushButton;

namespace viscera::studio {

class Document;

/// "grasper", "energy hook", "clip applier", "scissors", "needle driver": how the studio names a
/// kind (the panel, the project tree).
QString instrumentKindLabel(sim::InstrumentDesc::Kind kind);

class InstrumentPanel : public QWidget {
    Q_OBJECT
public:
    explicit InstrumentPanel(Document* doc, QWidget* parent = nullptr);

    /// The text fields, by key: name, temperature_c, radius, jaw_length, motion_scale,
    /// force_scale, max_force_n, damage_force_n, port_x, port_y, port_z, insertion_min,
    /// insertion_max, max_angle_deg, shaft_length (object name "instrument_<key>"). Null for
    /// another key.
    QLineEdit* field(const QString& key) const;
    QListWidget* list() const { return m_list; }
    QComboBox* addKindBox() const { return m_addKind; }
    QPushButton* addButton() const { return m_add; }
    QPushButton* removeButton() const { return m_remove; }
    QComboBox* targetBox() const { return m_target; }
    QComboBox* handBox() const { return m_hand; }
    QComboBox* modeBox() const { return m_mode; }
    QLabel* errorLabel() const { return m_error; }
    /// The instrument whose fields are shown (-1: none).
    int selected() const { return m_selected; }

signals:
    /// The instrument shown changed (the port tool follows it; -1: none).
    void selectedChanged(int index);

private:
    void buildFields(QFormLayout* form);
    QLineEdit* addField(QFormLayout* form, const QString& key, const QString& label, const QString& tip);
    /// The model's instruments into the list, the selected one's values into the fields.
    void fill();
    void fillFields();
    void addClicked();
    void removeClicked();
    /// A text field the user finished: its value into a copy of the instrument, then the edit.
    void fieldTyped(const QString& key);
    /// The target, hand or mode chosen in its combo.
    void choiceMade();
    void editSelected(const sim::InstrumentDesc& next, const QString& what);
    /// Shows `why` (empty: accepted); a refusal puts the model's values back in the fields.
    void apply(const QString& why);

    Document* m_doc;
    QListWidget* m_list = nullptr;
    QComboBox* m_addKind = nullptr;
    QPushButton* m_add = nullptr;
    QPushButton* m_remove = nullptr;
    QWidget* m_fields = nullptr;
    QFormLayout* m_form = nullptr;
    QComboBox* m_target = nullptr;
    QComboBox* m_hand = nullptr;
    QComboBox* m_mode = nullptr;
    QLabel* m_error = nullptr;
    int m_selected = -1;
    bool m_filling = false;
};

} // namespace viscera::studio
