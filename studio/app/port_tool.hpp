#pragma once
/// Placing trocar ports on the anatomy [issue 57 item 1]. The current port is an instrument's
/// (index >= 0) or the laparoscope's (kScopePort), chosen by the Instruments or the Laparoscope
/// dock. While a port is current its reachable workspace is drawn in the viewport (a wire cone:
/// max_angle_deg about the rest axis, rims at the insertion minimum and maximum) with the task
/// targets its instrument must reach (sim::targetsToReach), green where the port reaches them and
/// red where not.
///
/// "Place port" (Scene menu, checkable): a left click on any drawn surface (a body wall, a
/// scenery surface) puts the current port at the point hit, a drag slides it over the surfaces,
/// each press-drag-release one undo step (Document::editInstrument / editLaparoscope with one
/// merge key); a position the reader refuses (the rest tip then out of the insertion range) is
/// not taken and the rule is reported (refused()); Esc ends the tool. The port's rest tip (the
/// track's first key, the scope's tip) stays where it is: the port's axis turns towards it.
/// While it is on, the gizmo's three axis handles are drawn at the port: a drag on a handle
/// (taken before the surface under it) slides the port along that axis alone.
#include "app/viewport.hpp"
#include "sim/scene/port.hpp"

#include <QObject>
#include <QPointer>
#include <QString>
#include <optional>
#include <utility>

class QAction;

namespace viscera::studio {

class Document;
struct Change;

class PortTool : public QObject, public Viewport::HandleGrabber {
    Q_OBJECT
public:
    static constexpr int kNoPort = -1, kScopePort = -2;
    PortTool(Document* doc, QObject* parent = nullptr);
    ~PortTool() override;

    /// The checkable "Place port" action (disabled while no port is current).
    QAction* action() { return m_action; }
    /// The viewport clicks come from and the workspace is drawn in (null: none).
    void connectViewport(Viewport* v);
    /// The port edited and drawn: an instrument index, kScopePort or kNoPort.
    void setCurrent(int port);
    int current() const { return m_current; }
    /// Moves the current port to `point` (m) as an undo step (merging with the same nonzero
    /// `mergeKey`). Returns the refusal (one line naming the field and the rule), empty when done.
    QString placeAt(const sim::Vec3& point, int mergeKey);
    /// The current port's frame as drawn (its rest axis towards the rest tip); none when no port
    /// is current or it has none.
    std::optional<sim::PortFrame> currentFrame() const;
    /// How many of the current instrument's task points its port reaches, and of how many.
    std::pair<int, int> reachCounts() const;

    /// The gizmo (drawn while "Place port" is on): a handle per world axis from the port,
    /// kGizmoLength long; a left drag on one slides the port along that axis only, one undo step
    /// per drag, a position the reader refuses leaving the port at the last one taken.
    static constexpr double kGizmoLength = 0.05; ///< m
    static constexpr double kGrabPixels = 8;     ///< how near a handle's drawn rod a press takes it
    /// The axis (0 x, 1 y, 2 z) whose handle is drawn within kGrabPixels of `pos`; -1: none.
    int handleAt(QPoint pos) const;
    bool grab(QPoint pos) override;
    void drag(QPoint pos) override;
    void release() override;

signals:
    /// A placement the reader refused: the rule, one line.
    void refused(const QString& why);
    /// The tool went on or off (the paint tools go off when it goes on).
    void activeChanged(bool on);

private:
    void setActive(bool on);
    /// The workspace and targets of the current port into the viewport's authoring meshes.
    void redraw();

    Document* m_doc;
    QPointer<Viewport> m_viewport; ///< null once the viewport is gone
    QAction* m_action = nullptr;
    int m_current = kNoPort;
    int m_dragKey = 0;
    int m_axis = -1;                          ///< the handle being dragged
    double m_grabAt = 0;                      ///< where along it the press took it, m
    sim::Vec3 m_grabFrom = sim::Vec3::Zero(); ///< the port's position at the press
    /// Where along the axis `m_axis` through m_grabFrom the eye ray through `pos` passes nearest.
    std::optional<double> alongHandle(QPoint pos) const;
    bool m_drawn = false; ///< the authoring meshes are ours
};

} // namespace viscera::studio
