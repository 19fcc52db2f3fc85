#include "app/port_tool.hpp"

#include "app/document.hpp"
#include "app/port_overlays.hpp"
#include "app/viewport.hpp"
#include "sim/scene/port_reach.hpp"

#include <QAction>

#include <algorithm>
#include <cmath>

namespace viscera::studio {

PortTool::PortTool(Document* doc, QObject* parent) : QObject(parent), m_doc(doc) {
    m_action = new QAction(tr("Place port"), this);
    m_action->setObjectName("placePortAction");
    m_action->setCheckable(true);
    m_action->setEnabled(false);
    m_action->setToolTip(tr("Click a surface to put the current port there; drag to slide it; Esc ends"));
    connect(m_action, &QAction::toggled, this, &PortTool::setActive);
    connect(doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Scene | Change::Assessment | Change::Structure)) setCurrent(m_current);
    });
}

PortTool::~PortTool() {
    if (m_viewport) m_viewport->setHandleGrabber(nullptr);
}

void PortTool::connectViewport(Viewport* v) {
    m_viewport = v;
    m_drawn = false;
    if (!v) return;
    connect(v, &Viewport::paintPressed, this, [this](const Viewport::SurfaceHit& hit) {
        if (!m_action->isChecked()) return;
        m_dragKey = m_doc->newMergeKey();
        const QString why = placeAt(hit.world.cast<double>(), m_dragKey);
        if (!why.isEmpty()) emit refused(why);
    });
    connect(v, &Viewport::paintMoved, this, [this](const Viewport::SurfaceHit& hit) {
        if (!m_action->isChecked() || m_dragKey == 0) return;
        // a refused position mid-drag leaves the port at the last one taken; say why once
        const QString why = placeAt(hit.world.cast<double>(), m_dragKey);
        if (!why.isEmpty()) emit refused(why);
    });
    connect(v, &Viewport::paintReleased, this, [this] { m_dragKey = 0; });
    connect(v, &Viewport::paintCancelled, this, [this] {
        m_dragKey = 0;
        m_action->setChecked(false);
    });
    connect(v, &Viewport::paintEscaped, this, [this] { m_action->setChecked(false); });
    v->setHandleGrabber(this);
    redraw();
}

int PortTool::handleAt(QPoint pos) const {
    const std::optional<sim::PortFrame> frame = currentFrame();
    if (!m_viewport || !m_action->isChecked() || !frame) return -1;
    const sim::Vec3& at = frame->desc.position;
    const auto a = m_viewport->toScreen(at.cast<float>());
    if (!a) return -1;
    int best = -1;
    double nearest = kGrabPixels;
    for (int k = 0; k < 3; ++k) {
        const auto b = m_viewport->toScreen((at + kGizmoLength * sim::Vec3::Unit(k)).cast<float>());
        if (!b) continue;
        const QPointF ab = *b - *a, ap = QPointF(pos) - *a;
        const double len2 = QPointF::dotProduct(ab, ab);
        const double t = len2 > 0 ? std::clamp(QPointF::dotProduct(ap, ab) / len2, 0.0, 1.0) : 0.0;
        const QPointF off = QPointF(pos) - (*a + t * ab);
        const double d = std::hypot(off.x(), off.y());
        if (d <= nearest) {
            nearest = d;
            best = k;
        }
    }
    return best;
}

std::optional<double> PortTool::alongHandle(QPoint pos) const {
    if (!m_viewport || m_axis < 0) return std::nullopt;
    Eigen::Vector3f o, d;
    m_viewport->ray(pos, o, d);
    // the axis line p(s) = from + s e and the ray q(t) = o + t d: their closest points
    const sim::Vec3 e = sim::Vec3::Unit(m_axis), dd = d.cast<double>(), w = m_grabFrom - o.cast<double>();
    const double b = e.dot(dd), denom = 1 - b * b; // both unit
    if (!(denom > 1e-6)) return std::nullopt;      // looking along the axis: no drag
    const double s = (b * w.dot(dd) - w.dot(e)) / denom;
    if (!std::isfinite(s)) return std::nullopt;
    return s;
}

bool PortTool::grab(QPoint pos) {
    m_axis = handleAt(pos);
    if (m_axis < 0) return false;
    m_grabFrom = currentFrame()->desc.position;
    const std::optional<double> s = alongHandle(pos);
    if (!s) {
        m_axis = -1;
        return false;
    }
    m_grabAt = *s;
    m_dragKey = m_doc->newMergeKey();
    return true;
}

void PortTool::drag(QPoint pos) {
    const std::optional<double> s = alongHandle(pos);
    if (!s || m_dragKey == 0) return;
    // a refused position mid-drag leaves the port at the last one taken; say why
    const QString why = placeAt(m_grabFrom + (*s - m_grabAt) * sim::Vec3::Unit(m_axis), m_dragKey);
    if (!why.isEmpty()) emit refused(why);
}

void PortTool::release() {
    m_axis = -1;
    m_dragKey = 0;
}

void PortTool::setCurrent(int port) {
    const Project* p = m_doc->hasProject() ? &m_doc->project() : nullptr;
    const int instruments = p && p->scene.interaction ? static_cast<int>(p->scene.interaction->instruments.size()) : 0;
    const bool valid = (port >= 0 && port < instruments) || (port == kScopePort && p && p->scene.laparoscope);
    m_current = valid ? port : kNoPort;
    m_action->setEnabled(m_current != kNoPort);
    if (m_current == kNoPort && m_action->isChecked()) m_action->setChecked(false);
    redraw();
}

void PortTool::setActive(bool on) {
    m_dragKey = 0;
    m_axis = -1;
    emit activeChanged(on); // the paint tools go off first: they would set the paint mode off
    if (m_viewport) m_viewport->setPaintMode(on);
    redraw(); // the gizmo: drawn while the tool is on
}

QString PortTool::placeAt(const sim::Vec3& point, int mergeKey) {
    if (!m_doc->hasProject() || m_current == kNoPort)
        return tr("no port is chosen: pick an instrument or the laparoscope");
    if (!point.allFinite()) return tr("the point under the cursor is not finite");
    const Project& p = m_doc->project();
    if (m_current == kScopePort) {
        sim::LaparoscopeDesc scope = *p.scene.laparoscope;
        scope.port.position = point;
        scope.port.declared = true;
        return m_doc->editLaparoscope(tr("Move the laparoscope's port"), scope, mergeKey);
    }
    sim::InstrumentDesc in = p.scene.interaction->instruments[static_cast<size_t>(m_current)];
    in.port.position = point;
    in.port.declared = true;
    return m_doc->editInstrument(tr("Move the port of %1").arg(QString::fromStdString(in.name)), m_current, in,
                                 mergeKey);
}

std::optional<sim::PortFrame> PortTool::currentFrame() const {
    if (!m_doc->hasProject() || m_current == kNoPort) return std::nullopt;
    const Project& p = m_doc->project();
    if (m_current == kScopePort) {
        const sim::LaparoscopeDesc& s = *p.scene.laparoscope;
        return sim::makePortFrame(s.port, s.tip, s.motionScale);
    }
    return sim::instrumentPortFrame(p.scene.interaction->instruments[static_cast<size_t>(m_current)]);
}

std::pair<int, int> PortTool::reachCounts() const {
    const std::optional<sim::PortFrame> frame = currentFrame();
    const Project* p = m_doc->hasProject() ? &m_doc->project() : nullptr;
    if (!frame || m_current < 0 || !p->scene.assessment) return {0, 0};
    int reached = 0, total = 0;
    const auto& in = p->scene.interaction->instruments[static_cast<size_t>(m_current)];
    for (const sim::ReachTarget& t : sim::targetsToReach(in, *p->scene.assessment))
        for (const sim::Vec3& x : t.points) {
            ++total;
            reached += sim::reachRule(*frame, x).empty() ? 1 : 0;
        }
    return {reached, total};
}

void PortTool::redraw() {
    if (!m_viewport) return;
    const std::optional<sim::PortFrame> frame = currentFrame();
    if (!frame) {
        if (m_drawn) m_viewport->setAuthoringLayer(Viewport::Layer::Port, {});
        m_drawn = false;
        return;
    }
    std::vector<render::RenderMesh> meshes{portWorkspaceMesh(*frame, 0)};
    if (m_action->isChecked())
        for (render::RenderMesh& handle : portGizmoMeshes(frame->desc.position, kGizmoLength, 0))
            meshes.push_back(std::move(handle));
    const Project& p = m_doc->project();
    if (m_current >= 0 && p.scene.assessment) {
        std::vector<ReachMarker> markers;
        const auto& in = p.scene.interaction->instruments[static_cast<size_t>(m_current)];
        for (const sim::ReachTarget& t : sim::targetsToReach(in, *p.scene.assessment))
            for (const sim::Vec3& x : t.points)
                markers.push_back({x, sim::reachRule(*frame, x).empty()});
        if (!markers.empty()) meshes.push_back(reachMarkersMesh(markers, 0.0015, 0));
    }
    m_viewport->setAuthoringLayer(Viewport::Layer::Port, std::move(meshes));
    m_drawn = true;
}

} // namespace viscera::studio
