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
    connect(m_doc, &Document::changed, this, [this] {
        if (m_ready && !m_stroking) recompute(); // undo, redo, another edit of the strokes
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
    if (m_stroking) cancel();
    m_body = body;
    m_mesh = std::move(mesh);
    m_ready = false;
    m_committed.clear();
    m_applied.clear();
    m_live.clear();
    m_skeleton = {};
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

void StiffnessPainter::waitUntilReady() {
    if (m_watcher) m_watcher->waitForFinished();
    QCoreApplication::processEvents(); // delivers finished()
}

void StiffnessPainter::recompute() {
    if (!m_ready || !m_doc->hasProject() || m_body >= static_cast<int>(m_doc->project().bodies.size())) return;
    const BodyProject& b = m_doc->project().bodies[m_body];
    // an edit of anything else (a material drag) leaves the weights as they are
    const std::vector<sim::BrushStroke> strokes = b.paint ? b.paint->strokes : std::vector<sim::BrushStroke>{};
    const sim::PaintParams params = b.paint ? b.paint->params : sim::PaintParams{};
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
    m_committed.assign(m_mesh->vertexCount(), m_params.baseWeight);
    if (b.paint)
        for (const sim::BrushStroke& s : b.paint->strokes)
            sim::applyBrushStroke(m_mesh->positions(), m_skeleton, m_map, s, m_params, m_committed, nullptr,
                                  &m_neighbours);
    m_live = m_committed;
    for (const sim::BrushStroke& s : m_dabs)
        sim::applyBrushStroke(m_mesh->positions(), m_skeleton, m_map, s, m_params, m_live, nullptr, &m_neighbours);
    emit weightsChanged();
}

sim::BrushStroke StiffnessPainter::dabAt(const sim::Vec3& center) const {
    sim::BrushStroke s;
    s.center = center;
    s.radius = brush.radius;
    s.mode = brush.mode;
    s.amplitude = brush.strength;
    s.target = brush.target;
    if (m_invert && m_stroking) { // Ctrl: the inverse of the brush
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
        sim::applyBrushStroke(m_mesh->positions(), m_skeleton, m_map, s, m_params, m_live, nullptr, &m_neighbours);
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
    static const char* const kModes[] = {"add", "subtract", "mix", "smooth"};
    const QString name = QString::fromStdString(m_doc->project().bodies[m_body].scene.name);
    const int body = m_body;
    const QString why = m_doc->edit(
        tr("Paint stiffness (%1) on '%2'").arg(kModes[static_cast<int>(dabs.front().mode)], name), [&](Project& p) {
            BodyProject& b = p.bodies[body];
            if (!b.paint) b.paint = StiffnessPaintProject{};
            b.paint->strokes.insert(b.paint->strokes.end(), dabs.begin(), dabs.end());
        });
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
