#pragma once
/// Skeleton stiffness painting of one tet body [A §4.3.5, eq. 4.26–4.28], the logic behind the
/// studio's paint tool. The body's curve skeleton is extracted (off the UI thread) from the
/// mesh the preview built, every node is mapped to it once, and then:
///   - the project's strokes (project.json stiffness_paint.strokes) give the node weights the
///     export bakes into the case's .vweights (the same sim::applyBrushStroke, the same order);
///   - a stroke in progress is a sequence of dabs (one sim::BrushStroke each, a quarter of the
///     radius apart along the cursor's path on the rest surface), applied to a copy of those
///     weights for display; end() commits every dab as one undo step, cancel() drops them.
/// Dab centres are in the mesh (rest) frame, so strokes are carried over by position when the
/// body is meshed again.
/// A fascia surface is painted on its vertices directly (polygon paint, [A Fig. 4.11]): no
/// skeleton, the same strokes through sim::applySurfaceBrushStroke, stored in the surface's
/// stiffness_paint.
#include "app/document.hpp"
#include "sim/skeleton/stiffness_paint.hpp"

#include <QFutureWatcher>
#include <QObject>
#include <QString>

#include <memory>
#include <vector>

namespace viscera::studio {

class StiffnessPainter : public QObject {
    Q_OBJECT
public:
    struct Brush {
        sim::BrushMode mode = sim::BrushMode::Add;
        double radius = 0.01;  ///< m, the poly6 support h
        double strength = 1.0; ///< Add/Subtract: weight added at the centre; Mix/Smooth: in [0, 1]
        double target = 2.0;   ///< Mix: the weight approached
        /// A body's nodes the brush reaches: the surface it touches and, through the curve
        /// skeleton, the members of the skeleton nodes inside it (Sphere, the default), or only
        /// the latter (Skeleton, eq. 4.26 as printed).
        sim::BrushReach reach = sim::BrushReach::Sphere;
    };

    explicit StiffnessPainter(Document* doc, QObject* parent = nullptr);
    ~StiffnessPainter() override;

    /// Paints body `body` of the document on `mesh` (its built rest mesh). Extracts the skeleton
    /// in the background; ready() once done (readyChanged). Null mesh or -1: no target.
    void setTarget(int body, std::shared_ptr<const sim::TetMesh> mesh);
    /// Paints fascia `surface` of the document on `mesh` (its cut rest surface); ready at once.
    void setSurfaceTarget(int surface, std::shared_ptr<const sim::TriMesh> mesh);
    /// The painted body, or -1 (none, or a surface is painted).
    int body() const { return m_body; }
    /// The painted fascia surface, or -1.
    int surface() const { return m_surface; }
    bool ready() const { return m_ready; }
    /// One line: what the painter is doing or why it cannot paint.
    const QString& status() const { return m_status; }
    /// Waits for the skeleton (tests and scripted use).
    void waitUntilReady();

    Brush brush;
    /// The dab the brush would make at `center` (validated by the project's stroke rule).
    sim::BrushStroke dabAt(const sim::Vec3& center) const;

    /// Starts a stroke; `invert` (Ctrl held) paints the brush's inverse: Add subtracts, Subtract
    /// adds, Mix moves towards the base weight; Smooth is its own inverse.
    void begin(const sim::Vec3& restPoint, bool invert = false);
    void move(const sim::Vec3& restPoint);
    /// Commits the stroke in progress as one undo step; returns the document's error (empty: ok).
    QString end();
    void cancel();
    bool stroking() const { return m_stroking; }
    const std::vector<sim::BrushStroke>& pendingDabs() const { return m_dabs; }

    /// Node weights shown: the project's strokes, plus the stroke in progress.
    const std::vector<double>& weights() const { return m_live; }
    const sim::PaintParams& params() const { return m_params; }
    /// The skeleton's nodes and edges (for drawing it), empty before ready().
    const sim::Skeleton& skeleton() const { return m_skeleton; }

signals:
    void readyChanged();
    void weightsChanged();
    void statusChanged(const QString& status);

private:
    void recompute();
    void addDab(const sim::Vec3& center);
    void clearTarget();
    /// The stroke on `w` through the skeleton (a body) or on the vertices (a surface).
    void applyStroke(const sim::BrushStroke& s, std::vector<double>& w) const;
    /// The target's paint in the document (null: none yet).
    const std::optional<StiffnessPaintProject>* paintOf(const Project& p) const;
    QString targetName() const;
    void setStatus(const QString& s);

    Document* m_doc;
    int m_body = -1, m_surface = -1;
    std::shared_ptr<const sim::TetMesh> m_mesh;
    std::shared_ptr<const sim::TriMesh> m_triMesh;
    bool m_ready = false;
    QString m_status;
    sim::Skeleton m_skeleton;
    sim::SkeletonNodeMap m_map;
    sim::NodeNeighbours m_neighbours;
    sim::PaintParams m_params;
    std::vector<double> m_committed, m_live;
    std::vector<sim::BrushStroke> m_dabs;
    std::vector<sim::BrushStroke> m_applied; ///< the project's strokes m_committed was made from
    sim::Vec3 m_lastDab = sim::Vec3::Zero();
    bool m_stroking = false, m_invert = false;
    struct Prepared;
    QFutureWatcher<std::shared_ptr<Prepared>>* m_watcher = nullptr;
    uint64_t m_generation = 0;
};

} // namespace viscera::studio
