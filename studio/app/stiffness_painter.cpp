#include "app/stiffness_painter.hpp"

#include "bake/skeleton.hpp"

#include <QtConcurrent/QtConcurrent>

#include <algorithm>

namespace viscera::studio {

struct StiffnessPainter::Prepared {
    uint64_t generation = 0;
    sim::Skeleton skeleton;
    sim::SkeletonNodeMap map;
    sim::NodeNeighbours neighbours;
    QString error;
};

StiffnessPainter::StiffnessPainter(Document* doc, QObject* parent) : QObject(parent), m_doc(doc) {
    connect(m_doc, &Document::changed, this, [this](const Change& what) {
        // undo, redo, another edit of the strokes (a material edit leaves the weights)
        if (m_ready && !m_stroking && what.touches(Change::Paint | Change::Structure)) recompute();
    });
}

StiffnessPainter::~StiffnessPainter() {
    if (m_watcher) m_watcher->waitForFinished();
}

void StiffnessPainter::setStatus(const QString& s) {
    if (s == m_status) return;
    m_status = s;
    emit statusChanged(s);
}

void StiffnessPainter::setTarget(int body, std::shared_ptr<const sim::TetMesh> mesh) {
    const bool same =
        body == m_body && mesh && m_mesh && mesh->positions() == m_mesh->positions() && mesh->tets() == m_mesh->tets();
    if (same) { // the preview built the same mesh again: a stroke in progress goes on
        m_mesh = std::move(mesh);
        if (m_ready && !m_stroking) recompute();
        return;
    }
    clearTarget();
    m_body = body;
    m_mesh = std::move(mesh);
    emit readyChanged();
    emit weightsChanged();
    if (body < 0 || !m_mesh || !m_doc->hasProject() || body >= static_cast<int>(m_doc->project().bodies.size())) {
        setStatus(body < 0 ? tr("Select a tet body to paint its stiffness.")
                           : tr("Waiting for the preview to build the body's mesh."));
        return;
    }
    const BodyProject& b = m_doc->project().bodies[body];
    bake::SkeletonParams params = b.paint ? b.paint->skeleton : bake::SkeletonParams{};
    params.label = "skeleton of '" + b.scene.name + "'";
    setStatus(tr("Extracting the curve skeleton of '%1'…").arg(QString::fromStdString(b.scene.name)));
    const uint64_t generation = ++m_generation;
    if (!m_watcher) {
        m_watcher = new QFutureWatcher<std::shared_ptr<Prepared>>(this);
        connect(m_watcher, &QFutureWatcher<std::shared_ptr<Prepared>>::finished, this, [this] {
            const std::shared_ptr<Prepared> p = m_watcher->result();
            if (!p || p->generation != m_generation) return; // a newer target is on its way
            if (!p->error.isEmpty()) {
                setStatus(p->error);
                return;
            }
            m_skeleton = std::move(p->skeleton);
            m_map = std::move(p->map);
            m_neighbours = std::move(p->neighbours);
            m_ready = true;
            recompute();
            setStatus(tr("Painting '%1': %2 skeleton nodes, %3 mesh nodes mapped")
                          .arg(QString::fromStdString(m_doc->project().bodies[m_body].scene.name))
                          .arg(m_skeleton.nodes.size())
                          .arg(m_map.meshNodeCount));
            emit readyChanged();
        });
    }
    std::shared_ptr<const sim::TetMesh> source = m_mesh;
    m_watcher->setFuture(QtConcurrent::run([source, params, generation] {
        auto p = std::make_shared<Prepared>();
        p->generation = generation;
        try {
            std::unique_ptr<sim::TetMesh> mesh = source->clone(); // the skeleton builds adjacency levels
            bake::SkeletonResult sk = bake::extractSkeleton(*mesh, params);
            p->map = sim::mapNodesToSkeleton(*mesh, sk.skeleton, params.label);
            p->neighbours = sim::nodeNeighbours(*mesh);
            p->skeleton = std::move(sk.skeleton);
        } catch (const std::exception& e) {
            p->error = QString::fromStdString(e.what());
        }
        return p;
    }));
}

void StiffnessPainter::clearTarget() {
    if (m_stroking) cancel();
    ++m_generation; // a skeleton still on its way is for another target
    m_body = m_surface = -1;
    m_mesh.reset();
    m_triMesh.reset();
    m_ready = false;
    m_committed.clear();
    m_applied.clear();
    m_live.clear();
    m_skeleton = {};
    m_neighbours = {};
}

void StiffnessPainter::setSurfaceTarget(int surface, std::shared_ptr<const sim::TriMesh> mesh) {
    const bool same = surface == m_surface && mesh && m_triMesh && mesh->positions() == m_triMesh->positions() &&
                      mesh->triangles() == m_triMesh->triangles();
    if (same) {
        m_triMesh = std::move(mesh);
        if (m_ready && !m_stroking) recompute();
        return;
    }
    clearTarget();
    if (surface < 0 || !mesh || !m_doc->hasProject() || surface >= static_cast<int>(m_doc->project().surfaces.size())) {
        emit readyChanged();
        emit weightsChanged();
        setStatus(surface < 0 ? tr("Select a tet body or a fascia to paint its stiffness.")
                              : tr("Waiting for the preview to cut the fascia's surface."));
        return;
    }
    m_surface = surface;
    m_triMesh = std::move(mesh);
    m_neighbours = sim::nodeNeighbours(*m_triMesh);
    m_ready = true; // polygon paint: no skeleton to wait for
    recompute();
    setStatus(
        tr("Painting fascia '%1' on its %2 vertices (polygon paint)").arg(targetName()).arg(m_triMesh->vertexCount()));
    emit readyChanged();
}

const std::optional<StiffnessPaintProject>* StiffnessPainter::paintOf(const Project& p) const {
    if (m_surface >= 0 && m_surface < static_cast<int>(p.surfaces.size())) return &p.surfaces[m_surface].paint;
    if (m_body >= 0 && m_body < static_cast<int>(p.bodies.size())) return &p.bodies[m_body].paint;
    return nullptr;
}

QString StiffnessPainter::targetName() const {
    if (!m_doc->hasProject()) return {};
    const Project& p = m_doc->project();
    if (m_surface >= 0 && m_surface < static_cast<int>(p.surfaces.size()))
        return QString::fromStdString(p.surfaces[m_surface].scene.name);
    if (m_body >= 0 && m_body < static_cast<int>(p.bodies.size()))
        return QString::fromStdString(p.bodies[m_body].scene.name);
    return {};
}

void StiffnessPainter::applyStroke(const sim::BrushStroke& s, std::vector<double>& w) const {
    if (m_triMesh)
        sim::applySurfaceBrushStroke(m_triMesh->positions(), s, m_params, w, nullptr, &m_neighbours);
    else
        sim::applyBrushStroke(m_mesh->positions(), m_skeleton, m_map, s, m_params, w, nullptr, &m_neighbours);
}

void StiffnessPainter::waitUntilReady() {
    if (m_watcher) m_watcher->waitForFinished();
    QCoreApplication::processEvents(); // delivers finished()
}

void StiffnessPainter::recompute() {
    if (!m_ready || !m_doc->hasProject()) return;
    const std::optional<StiffnessPaintProject>* paint = paintOf(m_doc->project());
    if (!paint) return;
    // an edit of anything else (a material drag) leaves the weights as they are
    const std::vector<sim::BrushStroke> strokes = *paint ? (*paint)->strokes : std::vector<sim::BrushStroke>{};
    const sim::PaintParams params = *paint ? (*paint)->params : sim::PaintParams{};
    auto sameStroke = [](const sim::BrushStroke& x, const sim::BrushStroke& y) {
        return x.center == y.center && x.radius == y.radius && x.amplitude == y.amplitude && x.scale == y.scale &&
               x.mode == y.mode && x.target == y.target;
    };
    if (!m_committed.empty() && m_dabs.empty() && params.baseWeight == m_params.baseWeight &&
        params.minWeight == m_params.minWeight && params.maxWeight == m_params.maxWeight &&
        std::equal(strokes.begin(), strokes.end(), m_applied.begin(), m_applied.end(), sameStroke)) {
        if (m_live != m_committed) { // a refused stroke: the weights shown go back
            m_live = m_committed;
            emit weightsChanged();
        }
        return;
    }
    m_applied = strokes;
    m_params = params;
    m_committed.assign(m_triMesh ? m_triMesh->vertexCount() : m_mesh->vertexCount(), m_params.baseWeight);
    for (const sim::BrushStroke& s : strokes)
        applyStroke(s, m_committed);
    m_live = m_committed;
    for (const sim::BrushStroke& s : m_dabs)
        applyStroke(s, m_live);
    emit weightsChanged();
}

sim::BrushStroke StiffnessPainter::dabAt(const sim::Vec3& center) const {
    sim::BrushStroke s;
    s.center = center;
    s.radius = brush.radius;
    s.mode = brush.mode;
    s.amplitude = brush.strength;
    s.target = brush.target;
    if (m_surface < 0) s.reach = brush.reach; // a fascia's polygon paint selects by sphere anyway
    if (m_invert && m_stroking) {             // Ctrl: the inverse of the brush
        if (s.mode == sim::BrushMode::Add)
            s.mode = sim::BrushMode::Subtract;
        else if (s.mode == sim::BrushMode::Subtract)
            s.mode = sim::BrushMode::Add;
        else if (s.mode == sim::BrushMode::Mix)
            s.target = m_params.baseWeight;
    }
    s.scale = sim::BrushScale::Peak;
    return s;
}

void StiffnessPainter::addDab(const sim::Vec3& center) {
    const sim::BrushStroke s = dabAt(center);
    try {
        applyStroke(s, m_live);
    } catch (const std::exception& e) {
        setStatus(QString::fromStdString(e.what()));
        return;
    }
    m_dabs.push_back(s);
    m_lastDab = center;
    emit weightsChanged();
}

void StiffnessPainter::begin(const sim::Vec3& restPoint, bool invert) {
    if (!m_ready || !restPoint.allFinite()) return;
    m_dabs.clear();
    m_live = m_committed;
    m_stroking = true;
    m_invert = invert;
    addDab(restPoint);
}

void StiffnessPainter::move(const sim::Vec3& restPoint) {
    if (!m_stroking || !restPoint.allFinite()) return;
    // dabs a quarter radius apart along the path: an even stroke at any cursor speed
    const double spacing = 0.25 * brush.radius;
    const sim::Vec3 d = restPoint - m_lastDab;
    const double len = d.norm();
    const int n = static_cast<int>(std::floor(len / spacing));
    for (int k = 1; k <= std::min(n, 1000); ++k)
        addDab(m_lastDab + d * (spacing / len));
}

QString StiffnessPainter::end() {
    if (!m_stroking) return {};
    m_stroking = false;
    const std::vector<sim::BrushStroke> dabs = std::move(m_dabs);
    m_dabs.clear();
    if (dabs.empty()) return {};
    if (m_live == m_committed) { // nothing to keep: no undo step, and the artist is told why
        const QString why =
            tr("the stroke changed no weight on '%1' (no node within the brush's %2 mm%3); nothing was recorded")
                .arg(targetName())
                .arg(1e3 * dabs.front().radius, 0, 'g', 3)
                .arg(m_surface >= 0 || dabs.front().reach == sim::BrushReach::Sphere
                         ? QString()
                         : tr(", which reaches the body's nodes through its curve skeleton only"));
        setStatus(why);
        return why;
    }
    static const char* const kModes[] = {"add", "subtract", "mix", "smooth"};
    const Project& project = m_doc->project();
    std::optional<StiffnessPaintProject> paint =
        m_surface >= 0 ? project.surfaces.at(m_surface).paint : project.bodies.at(m_body).paint;
    if (!paint) paint = StiffnessPaintProject{};
    paint->strokes.insert(paint->strokes.end(), dabs.begin(), dabs.end());
    const QString why = m_doc->editStiffnessPaint(
        tr("Paint stiffness (%1) on '%2'").arg(kModes[static_cast<int>(dabs.front().mode)], targetName()),
        m_surface >= 0 ? -1 : m_body, m_surface, paint);
    if (!why.isEmpty()) setStatus(why);
    recompute(); // the committed strokes (or, refused, the weights as they were)
    return why;
}

void StiffnessPainter::cancel() {
    if (!m_stroking) return;
    m_stroking = false;
    m_dabs.clear();
    m_live = m_committed;
    emit weightsChanged();
}

} // namespace viscera::studio
