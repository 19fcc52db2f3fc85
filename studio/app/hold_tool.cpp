#include "app/hold_tool.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "app/paint_overlays.hpp"
#include "app/viewport.hpp"

#include <QAction>

#include <cmath>

namespace viscera::studio {
namespace {

constexpr double kMaxMargin = 0.1; ///< m

/// The body named `name`, or the body a layer (fascia) of that name lies on; -1: neither.
int bodyIndex(const Project& p, const QString& name) {
    QString body = name;
    for (const SurfaceProject& s : p.surfaces)
        if (QString::fromStdString(s.scene.name) == name) body = QString::fromStdString(s.scene.attachTo);
    for (size_t i = 0; i < p.bodies.size(); ++i)
        if (QString::fromStdString(p.bodies[i].scene.name) == body) return static_cast<int>(i);
    return -1;
}

} // namespace

HoldTool::HoldTool(Document* doc, QObject* parent) : QObject(parent), m_doc(doc) {
    m_action = new QAction(tr("Hold tissue"), this);
    m_action->setObjectName("holdTissueAction");
    m_action->setCheckable(true);
    m_action->setToolTip(tr("Click or drag along a body where it is attached: the tissue there is held in "
                            "place; Esc ends"));
    connect(m_action, &QAction::toggled, this, &HoldTool::setActive);
    connect(doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Structure)) redraw();
    });
}

void HoldTool::connectViewport(Viewport* v) {
    m_viewport = v;
    m_drawn = false;
    if (!v) return;
    connect(v, &Viewport::paintPressed, this, [this](const Viewport::SurfaceHit& hit) {
        if (!m_action->isChecked()) return;
        m_body = hit.name;
        m_stroke = {hit.rest.cast<double>()};
        m_dragging = true;
    });
    connect(v, &Viewport::paintMoved, this, [this](const Viewport::SurfaceHit& hit) {
        if (!m_action->isChecked() || !m_dragging || hit.name != m_body) return;
        if (hit.rest.allFinite() && m_stroke.size() < 4096) m_stroke.push_back(hit.rest.cast<double>());
    });
    connect(v, &Viewport::paintReleased, this, [this] {
        if (!m_action->isChecked() || !m_dragging) return;
        m_dragging = false;
        const QString why = hold(m_body, m_stroke);
        m_stroke.clear();
        if (!why.isEmpty()) emit refused(why);
    });
    connect(v, &Viewport::paintCancelled, this, [this] { m_action->setChecked(false); });
    connect(v, &Viewport::paintEscaped, this, [this] { m_action->setChecked(false); });
    redraw();
}

QString HoldTool::setMargin(double metres) {
    if (!std::isfinite(metres) || !(metres > 0) || metres > kMaxMargin)
        return tr("hold margin: must be in (0, %1] mm").arg(kMaxMargin * 1000);
    m_margin = metres;
    return {};
}

void HoldTool::setActive(bool on) {
    m_dragging = false;
    m_stroke.clear();
    emit activeChanged(on); // the other viewport tools go off first: they would set the paint mode off
    if (m_viewport) m_viewport->setPaintMode(on);
    redraw();
}

QString HoldTool::hold(const QString& body, const std::vector<sim::Vec3>& points) {
    if (!m_doc->hasProject()) return tr("no project is open");
    const int b = bodyIndex(m_doc->project(), body);
    if (b < 0) return tr("Hold tissue: '%1' is not a body (only bodies can be held)").arg(body);
    if (points.empty()) return tr("Hold tissue: no point on '%1'").arg(body);
    sim::Vec3 lo = sim::Vec3::Constant(1e300), hi = -lo;
    for (const sim::Vec3& p : points) {
        if (!p.allFinite()) return tr("Hold tissue: the point under the cursor is not finite");
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const sim::Vec3 pad = sim::Vec3::Constant(m_margin);
    return m_doc->edit(
        tr("Hold %1 here").arg(QString::fromStdString(m_doc->project().bodies[static_cast<size_t>(b)].scene.name)),
        [&](Project& q) {
            q.bodies[static_cast<size_t>(b)].fixedBoxes.push_back({lo - pad, hi + pad});
        },
        0, Change{Change::Structure});
}

QString HoldTool::release(int body) {
    if (!m_doc->hasProject() || body < 0 || body >= static_cast<int>(m_doc->project().bodies.size()))
        return tr("no body selected");
    if (m_doc->project().bodies[static_cast<size_t>(body)].fixedBoxes.empty())
        return tr("Release holds: '%1' is held nowhere")
            .arg(QString::fromStdString(m_doc->project().bodies[static_cast<size_t>(body)].scene.name));
    return m_doc->edit(
        tr("Release the holds of %1")
            .arg(QString::fromStdString(m_doc->project().bodies[static_cast<size_t>(body)].scene.name)),
        [body](Project& q) { q.bodies[static_cast<size_t>(body)].fixedBoxes.clear(); }, 0, Change{Change::Structure});
}

void HoldTool::redraw() {
    if (!m_viewport) return;
    if (!m_action->isChecked() || !m_doc->hasProject()) {
        if (m_drawn) m_viewport->setAuthoringLayer(Viewport::Layer::Holds, {});
        m_drawn = false;
        return;
    }
    std::vector<render::RenderMesh> meshes;
    for (const BodyProject& b : m_doc->project().bodies)
        for (const auto& box : b.fixedBoxes)
            meshes.push_back(boxOutlineMesh(box[0], box[1], 0, "held", {0.2f, 0.9f, 0.9f, 1.0f}));
    m_viewport->setAuthoringLayer(Viewport::Layer::Holds, std::move(meshes));
    m_drawn = true;
}

} // namespace viscera::studio
