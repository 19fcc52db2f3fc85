#pragma once
/// Drawing the assessment's targets on the anatomy [issue 57 item 2]. Four checkable actions
/// (one at a time; the paint and port tools go off when one goes on), each a way of picking in
/// the viewport, each taken as one undo step through Document::editAssessment (the scene reader's
/// rules for the assessment; a refusal leaves the model unchanged and is reported by refused()):
///   Draw cut line     a left drag along a surface paints a polyline snapped to it (a point every
///                     2 mm of the drag, at most 256); the release adds it as targets.cut[i]
///   Pick clip site    a click on a surface adds targets.clip[i] at the point hit
///   Pick suture plane a click on each edge of the wound: the plane lies halfway between the two
///                     points, its normal from the first to the second (targets.suture; bites,
///                     depth and spacing kept when there was one)
///   Pick vessel       a click on a body (or on a layer on its boundary) makes it the vessel to
///                     protect (targets.vessel)
/// New targets take the sizes in defaults() (the dock's fields). Points are the surface's rest
/// positions (the scene frame the player measures in). Esc ends the tool and drops what was not
/// taken. While shown (the Assessment dock open) the targets are drawn in the viewport's Targets
/// layer (target_overlays.hpp) and the vessel's bounds as a red box.
#include "sim/scene/assessment.hpp"

#include <QObject>
#include <QString>
#include <array>
#include <optional>
#include <vector>

class QAction;

namespace viscera::studio {

class Document;
class Viewport;

class TargetTool : public QObject {
    Q_OBJECT
public:
    enum class Pick { None = 0, CutLine, ClipSite, SuturePlane, Vessel };
    /// Sizes new targets take (m; a count).
    struct Defaults {
        double cutRadius = 0.005, cutCoverage = 0.8;
        double clipTolerance = 0.008;
        int clipCount = 2;
        double vesselMargin = 0.0015;
    };
    static constexpr double kStrokeStep = 0.002;  ///< m between a cut line's points
    static constexpr size_t kMaxLinePoints = 256; ///< the reader's limit

    explicit TargetTool(Document* doc, QObject* parent = nullptr);
    /// The checkable action of `pick` (not None).
    QAction* action(Pick pick) { return m_actions[static_cast<size_t>(pick) - 1]; }
    Pick pick() const { return m_pick; }
    void connectViewport(Viewport* v);
    /// Draws the targets (the Assessment dock in view) or not.
    void setShown(bool on);
    bool shown() const { return m_shown; }
    Defaults& defaults() { return m_defaults; }
    /// Draws the targets again (a new scene arrived: the vessel's bounds are its meshes').
    void refresh() { redraw(); }

    // The edits, each one undo step; each returns the refusal (one line naming the field and the
    // rule), empty when taken.
    QString addCutLine(const std::vector<sim::Vec3>& points);
    QString addClipSite(const sim::Vec3& at);
    QString setSuturePlane(const sim::Vec3& first, const sim::Vec3& second);
    QString setVessel(const QString& body);

    /// The cut line being drawn and the first point of a suture plane not yet taken.
    const std::vector<sim::Vec3>& stroke() const { return m_stroke; }
    const std::optional<sim::Vec3>& firstPlanePoint() const { return m_first; }

signals:
    void refused(const QString& why);
    /// A pick went on or off (the paint and port tools go off when one goes on).
    void activeChanged(bool on);

private:
    void setPick(Pick pick, bool on);
    void pressed(const sim::Vec3& at, const QString& name);
    void moved(const sim::Vec3& at);
    void released();
    void report(const QString& why);
    void redraw();
    /// The model's assessment, or an empty one.
    sim::AssessmentDesc current() const;

    Document* m_doc;
    Viewport* m_viewport = nullptr;
    std::array<QAction*, 4> m_actions{};
    Pick m_pick = Pick::None;
    bool m_shown = false, m_drawn = false, m_dragging = false;
    Defaults m_defaults;
    std::vector<sim::Vec3> m_stroke;
    std::optional<sim::Vec3> m_first;
};

} // namespace viscera::studio
