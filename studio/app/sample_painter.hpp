#pragma once
/// Light-sample painting of one tet body's surface [A §6.3.2, Fig. 6.15], the logic behind the
/// studio's Light samples tool. The body's surface at rest (render::bodySurfaceMesh of the mesh
/// the preview built) carries a class per vertex — unpainted, 1×, 4× or 8× area-light samples:
///   - the project's operations (project.json light_samples) give the classes the export writes
///     into the case's .vsamples (the same render::applySamplePaint, the same order);
///   - a brush stroke in progress is a sequence of dabs a quarter of the radius apart along the
///     cursor's path; a fill starts at the face under the cursor and spreads until a sharp edge
///     (or a UV border); end() commits the stroke or fill as one operation, one undo step, and
///     cancel() drops it.
/// Dabs and seeds are rest positions, so a map is carried over by position when the body is
/// meshed again.
#include "app/document.hpp"
#include "render/sample_map.hpp"

#include <QObject>
#include <QString>

#include <array>
#include <memory>
#include <optional>
#include <vector>

namespace viscera::studio {

class SamplePainter : public QObject {
    Q_OBJECT
public:
    struct Brush {
        render::SamplePaintOp::Tool tool = render::SamplePaintOp::Tool::Brush;
        int samples = 8;         ///< 0 erases, else 1, 4 or 8
        double radius = 0.01;    ///< brush, m
        double maxAngleDeg = 30; ///< fill: the sharp-edge angle
    };

    explicit SamplePainter(Document* doc, QObject* parent = nullptr);

    /// Paints body `body` of the document on `mesh` (its built rest mesh). Null or -1: no target.
    void setTarget(int body, std::shared_ptr<const sim::TetMesh> mesh);
    int body() const { return m_body; }
    bool ready() const { return m_ready; }
    /// One line: what the painter is doing or why it cannot paint.
    const QString& status() const { return m_status; }

    Brush brush;
    /// The operation the brush starts at `restPoint` (a stroke of one dab, or a fill).
    render::SamplePaintOp opAt(const sim::Vec3& restPoint) const;

    /// Starts a stroke or fill; `invert` (Ctrl held) erases instead (class 0).
    void begin(const sim::Vec3& restPoint, bool invert = false);
    void move(const sim::Vec3& restPoint);
    /// Commits the stroke or fill in progress as one undo step; returns the document's error
    /// (empty: ok).
    QString end();
    void cancel();
    bool stroking() const { return m_pending.has_value(); }

    /// Classes shown (the project's operations plus the one in progress): per surface vertex and
    /// per body node (0 off the surface).
    const render::RenderMesh& surface() const { return m_live; }
    const std::vector<uint8_t>& nodeClasses() const { return m_nodes; }
    /// Surface area (m², rest) per class of what is shown: unpainted, 1×, 4×, 8×.
    std::array<double, 4> areas() const { return render::sampleClassAreas(m_live); }

signals:
    void classesChanged();
    void statusChanged(const QString& status);

private:
    void recompute();
    void publish();
    void setStatus(const QString& s);

    Document* m_doc;
    int m_body = -1;
    std::shared_ptr<const sim::TetMesh> m_mesh;
    bool m_ready = false;
    QString m_status;
    render::RenderMesh m_committed, m_live;
    std::vector<uint8_t> m_nodes;
    std::vector<render::SamplePaintOp> m_applied; ///< the project's operations m_committed was made from
    std::optional<render::SamplePaintOp> m_pending;
};

/// The colour of a class in the studio's overlay and legend (RGBA): unpainted faint grey, 1× blue,
/// 4× amber, 8× red.
std::array<float, 4> sampleClassColour(int samples);

} // namespace viscera::studio
