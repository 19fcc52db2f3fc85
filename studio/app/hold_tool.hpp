#pragma once
/// Holding tissue where it is attached [issue 57 item 4]: a body's "fixed" boxes drawn on the
/// anatomy instead of typed. "Hold tissue" (checkable; the paint, port and target tools go off
/// when it goes on): a left click on a body holds the nodes within margin() of the point hit, a
/// drag along it those within margin() of the stroke (the stroke's bounding box grown by the
/// margin, one box); the release adds the box to that body's fixed list as one undo step through
/// Document::edit (the project reader's rules: each box must hold a node at export, at most
/// kMaxHoldBoxes). A click on a layer (fascia) holds the body under it; on anything else (a
/// surrounding) it is refused with the reason. "Release holds" removes a body's boxes as one undo step. While the tool
/// is on, every body's boxes are drawn in the viewport (cyan wire boxes). Esc ends the tool.
#include "sim/mesh/tet_mesh.hpp"

#include <QObject>
#include <QString>
#include <vector>

class QAction;

namespace viscera::studio {

class Document;
class Viewport;

class HoldTool : public QObject {
    Q_OBJECT
public:
    static constexpr double kDefaultMargin = 0.005; ///< m
    explicit HoldTool(Document* doc, QObject* parent = nullptr);
    /// The checkable "Hold tissue" action.
    QAction* action() { return m_action; }
    void connectViewport(Viewport* v);
    /// m: how far around the clicked point or the stroke nodes are held; (0, 0.1].
    double margin() const { return m_margin; }
    /// Refuses (returns the rule) a margin outside (0, 0.1] m or not finite; empty when taken.
    QString setMargin(double metres);

    // The edits, each one undo step; each returns the refusal (one line naming the field and the
    // rule), empty when taken.
    /// Holds the nodes of body `body` (by name) within margin() of the points (rest positions).
    QString hold(const QString& body, const std::vector<sim::Vec3>& points);
    /// Removes every held box of body `body` (index).
    QString release(int body);

signals:
    void refused(const QString& why);
    /// The tool went on or off (the paint, port and target tools go off when it goes on).
    void activeChanged(bool on);

private:
    void setActive(bool on);
    void redraw();

    Document* m_doc;
    Viewport* m_viewport = nullptr;
    QAction* m_action = nullptr;
    double m_margin = kDefaultMargin;
    bool m_drawn = false, m_dragging = false;
    QString m_body;
    std::vector<sim::Vec3> m_stroke;
};

} // namespace viscera::studio
