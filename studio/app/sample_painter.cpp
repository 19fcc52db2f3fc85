#include "app/sample_painter.hpp"

#include <QCoreApplication>

#include <algorithm>
#include <cmath>

namespace viscera::studio {
namespace {

bool sameOp(const render::SamplePaintOp& a, const render::SamplePaintOp& b) {
    return a.tool == b.tool && a.samples == b.samples && a.points == b.points && a.radius == b.radius &&
           a.maxAngleDeg == b.maxAngleDeg;
}

} // namespace

std::array<float, 4> sampleClassColour(int samples) {
    switch (samples) {
    case 1:
        return {0.16f, 0.42f, 0.95f, 0.85f};
    case 4:
        return {0.98f, 0.70f, 0.08f, 0.85f};
    case 8:
        return {0.90f, 0.10f, 0.12f, 0.85f};
    default:
        return {0.55f, 0.55f, 0.55f, 0.12f};
    }
}

SamplePainter::SamplePainter(Document* doc, QObject* parent) : QObject(parent), m_doc(doc) {
    connect(m_doc, &Document::changed, this, [this](const Change& what) {
        // undo, redo, another edit of the operations (a material edit leaves the classes)
        if (m_ready && !stroking() && what.touches(Change::LightSamples | Change::Structure)) recompute();
    });
}

void SamplePainter::setStatus(const QString& s) {
    if (s == m_status) return;
    m_status = s;
    emit statusChanged(s);
}

void SamplePainter::setTarget(int body, std::shared_ptr<const sim::TetMesh> mesh) {
    const bool same =
        body == m_body && mesh && m_mesh && mesh->positions() == m_mesh->positions() && mesh->tets() == m_mesh->tets();
    if (same) { // the preview built the same mesh again: a stroke in progress goes on
        m_mesh = std::move(mesh);
        if (m_ready && !stroking()) recompute();
        return;
    }
    cancel();
    m_body = body;
    m_mesh = std::move(mesh);
    m_ready = false;
    m_applied.clear();
    m_committed = {};
    m_live = {};
    m_nodes.clear();
    if (body < 0 || !m_mesh || !m_doc->hasProject() || body >= static_cast<int>(m_doc->project().bodies.size())) {
        setStatus(body < 0 ? tr("Select a tet body to paint its light samples.")
                           : tr("Waiting for the preview to build the body's mesh."));
        emit classesChanged();
        return;
    }
    const std::string& name = m_doc->project().bodies[body].scene.name;
    m_committed = render::bodySurfaceMesh(*m_mesh, name, static_cast<size_t>(body));
    m_ready = true;
    recompute();
    const QString mode = usesPaintedSampling(m_doc->project().scene)
                             ? tr("the case renders with painted sampling")
                             : tr("the case's render sampling is not 'painted': the map is kept in the project "
                                  "but not exported until it is");
    setStatus(tr("Painting the light samples of '%1' (%2 surface vertices); %3")
                  .arg(QString::fromStdString(name))
                  .arg(m_committed.vertexCount())
                  .arg(mode));
}

void SamplePainter::recompute() {
    if (!m_ready || !m_doc->hasProject() || m_body >= static_cast<int>(m_doc->project().bodies.size())) return;
    const std::vector<render::SamplePaintOp>& ops = m_doc->project().bodies[m_body].lightSamples;
    const bool unchanged = !m_committed.sampleMap.empty() &&
                           std::equal(ops.begin(), ops.end(), m_applied.begin(), m_applied.end(), sameOp);
    if (!unchanged) {
        try {
            render::applySamplePaint(m_committed, ops);
        } catch (const std::exception& e) { // the document's check keeps bad operations out
            setStatus(QString::fromStdString(e.what()));
            return;
        }
        m_applied = ops;
    }
    m_live = m_committed;
    if (m_pending) {
        if (m_pending->tool == render::SamplePaintOp::Tool::Brush)
            render::paintSampleBrush(m_live, m_pending->points, m_pending->radius, m_pending->samples);
        else
            render::fillSampleClass(m_live, render::nearestFace(m_live, m_pending->points[0]), m_pending->samples,
                                    static_cast<float>(m_pending->maxAngleDeg));
    }
    publish();
}

void SamplePainter::publish() {
    m_nodes = render::nodeSampleClasses(m_live, m_mesh ? m_mesh->vertexCount() : 0);
    emit classesChanged();
}

render::SamplePaintOp SamplePainter::opAt(const sim::Vec3& restPoint) const {
    render::SamplePaintOp op;
    op.tool = brush.tool;
    op.samples = brush.samples;
    op.points = {restPoint};
    op.radius = brush.radius;
    op.maxAngleDeg = brush.maxAngleDeg;
    return op;
}

void SamplePainter::begin(const sim::Vec3& restPoint, bool invert) {
    if (!m_ready || !restPoint.allFinite() || m_live.triangleCount() == 0) return;
    render::SamplePaintOp op = opAt(restPoint);
    if (invert) op.samples = 0;
    try {
        render::validateSamplePaintOp(op, "light samples");
    } catch (const std::exception& e) {
        setStatus(QString::fromStdString(e.what()));
        return;
    }
    m_pending = op;
    recompute();
}

void SamplePainter::move(const sim::Vec3& restPoint) {
    if (!m_pending || m_pending->tool != render::SamplePaintOp::Tool::Brush || !restPoint.allFinite()) return;
    // dabs a quarter radius apart along the path: an even stroke at any cursor speed
    const double spacing = 0.25 * m_pending->radius;
    std::vector<Eigen::Vector3d> added;
    for (int k = 0; k < 1000; ++k) {
        const sim::Vec3 last = m_pending->points.back();
        const sim::Vec3 d = restPoint - last;
        const double len = d.norm();
        if (len < spacing) break;
        m_pending->points.push_back(last + d * (spacing / len));
        added.push_back(m_pending->points.back());
    }
    if (added.empty()) return;
    render::paintSampleBrush(m_live, added, m_pending->radius, m_pending->samples);
    publish();
}

QString SamplePainter::end() {
    if (!m_pending) return {};
    const render::SamplePaintOp op = std::move(*m_pending);
    m_pending.reset();
    const int body = m_body;
    const QString name = QString::fromStdString(m_doc->project().bodies[body].scene.name);
    const QString what = op.samples == 0 ? tr("erase") : tr("%1×").arg(op.samples);
    const QString text = op.tool == render::SamplePaintOp::Tool::Fill ? tr("Fill light samples (%1) on '%2'")
                                                                      : tr("Paint light samples (%1) on '%2'");
    std::vector<render::SamplePaintOp> ops = m_doc->project().bodies[body].lightSamples;
    ops.push_back(op);
    const QString why = m_doc->editLightSamples(text.arg(what, name), body, ops);
    if (!why.isEmpty()) setStatus(why);
    recompute(); // the committed operations (or, refused, the classes as they were)
    return why;
}

void SamplePainter::cancel() {
    if (!m_pending) return;
    m_pending.reset();
    recompute();
}

} // namespace viscera::studio
