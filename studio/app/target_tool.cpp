#include "app/target_tool.hpp"

#include "app/document.hpp"
#include "app/paint_overlays.hpp"
#include "app/target_overlays.hpp"
#include "app/viewport.hpp"

#include <QAction>
#include <QSignalBlocker>

namespace viscera::studio {

TargetTool::TargetTool(Document* doc, QObject* parent) : QObject(parent), m_doc(doc) {
    const struct {
        Pick pick;
        const char* name;
        const char* text;
        const char* tip;
    } kinds[] = {
        {Pick::CutLine, "drawCutLineAction", "Draw cut line", "Drag along a surface to mark a line to open"},
        {Pick::ClipSite, "pickClipSiteAction", "Pick clip site", "Click a vessel where clips must go"},
        {Pick::SuturePlane, "pickSuturePlaneAction", "Pick suture plane",
         "Click one edge of the wound, then the other: the plane lies between them"},
        {Pick::Vessel, "pickVesselAction", "Pick vessel", "Click the body the energized hook must not touch"},
    };
    for (const auto& k : kinds) {
        auto* a = new QAction(tr(k.text), this);
        a->setObjectName(k.name);
        a->setCheckable(true);
        a->setToolTip(tr(k.tip) + tr("; Esc ends"));
        const Pick pick = k.pick;
        connect(a, &QAction::toggled, this, [this, pick](bool on) { setPick(pick, on); });
        m_actions[static_cast<size_t>(pick) - 1] = a;
    }
    connect(doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Assessment | Change::Structure | Change::Scene)) redraw();
    });
}

void TargetTool::connectViewport(Viewport* v) {
    m_viewport = v;
    m_drawn = false;
    if (!v) return;
    connect(v, &Viewport::paintPressed, this, [this](const Viewport::SurfaceHit& hit) {
        if (m_pick != Pick::None) pressed(hit.rest.cast<double>(), hit.name);
    });
    connect(v, &Viewport::paintMoved, this, [this](const Viewport::SurfaceHit& hit) {
        if (m_pick != Pick::None) moved(hit.rest.cast<double>());
    });
    connect(v, &Viewport::paintReleased, this, [this] {
        if (m_pick != Pick::None) released();
    });
    connect(v, &Viewport::paintCancelled, this, [this] {
        if (m_pick != Pick::None) action(m_pick)->setChecked(false);
    });
    connect(v, &Viewport::paintEscaped, this, [this] {
        if (m_pick != Pick::None) action(m_pick)->setChecked(false);
    });
    redraw();
}

void TargetTool::setPick(Pick pick, bool on) {
    if (!on && m_pick != pick) return; // another pick took over
    const Pick old = m_pick;
    m_pick = on ? pick : Pick::None;
    m_stroke.clear();
    m_first.reset();
    m_dragging = false;
    if (on && old != Pick::None && old != pick) {
        const QSignalBlocker quiet(action(old));
        action(old)->setChecked(false);
    }
    emit activeChanged(on); // the paint and port tools go off first: they would set the paint mode off
    if (m_viewport) m_viewport->setPaintMode(on);
    redraw();
}

void TargetTool::setShown(bool on) {
    m_shown = on;
    redraw();
}

sim::AssessmentDesc TargetTool::current() const {
    return m_doc->hasProject() ? m_doc->project().scene.assessment.value_or(sim::AssessmentDesc{})
                               : sim::AssessmentDesc{};
}

void TargetTool::pressed(const sim::Vec3& at, const QString& name) {
    if (!m_doc->hasProject()) return;
    if (!at.allFinite()) return report(tr("the point under the cursor is not finite"));
    switch (m_pick) {
    case Pick::CutLine:
        m_stroke = {at};
        m_dragging = true;
        break;
    case Pick::ClipSite:
        report(addClipSite(at));
        break;
    case Pick::SuturePlane:
        if (!m_first) {
            m_first = at;
        } else {
            const sim::Vec3 first = *m_first;
            m_first.reset();
            report(setSuturePlane(first, at));
        }
        break;
    case Pick::Vessel: {
        // a layer on a body's boundary (a fascia) stands for that body: the click meant what lies under it
        QString body = name;
        for (const SurfaceProject& sp : m_doc->project().surfaces)
            if (QString::fromStdString(sp.scene.name) == name && !sp.scene.attachTo.empty())
                body = QString::fromStdString(sp.scene.attachTo);
        report(setVessel(body));
        break;
    }
    case Pick::None:
        break;
    }
    redraw();
}

void TargetTool::moved(const sim::Vec3& at) {
    if (m_pick != Pick::CutLine || !m_dragging || !at.allFinite() || m_stroke.size() >= kMaxLinePoints) return;
    if ((at - m_stroke.back()).norm() < kStrokeStep) return;
    m_stroke.push_back(at);
    redraw();
}

void TargetTool::released() {
    if (m_pick != Pick::CutLine || !m_dragging) return;
    m_dragging = false;
    const std::vector<sim::Vec3> line = std::move(m_stroke);
    m_stroke.clear();
    report(addCutLine(line));
    redraw();
}

void TargetTool::report(const QString& why) {
    if (!why.isEmpty()) emit refused(why);
}

QString TargetTool::addCutLine(const std::vector<sim::Vec3>& points) {
    if (!m_doc->hasProject()) return tr("no project is open");
    if (points.size() < 2)
        return tr("assessment.targets.cut: a cut line needs at least 2 points: drag along the surface");
    sim::AssessmentDesc a = current();
    a.cuts.push_back({points, m_defaults.cutRadius, m_defaults.cutCoverage});
    return m_doc->editAssessment(tr("Draw cut line %1").arg(a.cuts.size()), a);
}

QString TargetTool::addClipSite(const sim::Vec3& at) {
    if (!m_doc->hasProject()) return tr("no project is open");
    sim::AssessmentDesc a = current();
    a.clips.push_back({at, m_defaults.clipTolerance, m_defaults.clipCount});
    return m_doc->editAssessment(tr("Pick clip site %1").arg(a.clips.size()), a);
}

QString TargetTool::setSuturePlane(const sim::Vec3& first, const sim::Vec3& second) {
    if (!m_doc->hasProject()) return tr("no project is open");
    const sim::Vec3 d = second - first;
    if (!d.allFinite() || !(d.norm() > 1e-4))
        return tr("assessment.targets.suture.plane.normal: the two points are less than 0.1 mm apart: pick one on "
                  "each edge of the wound");
    sim::AssessmentDesc a = current();
    sim::SutureTarget s = a.suture.value_or(sim::SutureTarget{});
    s.planePoint = 0.5 * (first + second);
    s.planeNormal = d.normalized();
    a.suture = s;
    return m_doc->editAssessment(tr("Pick suture plane"), a);
}

QString TargetTool::setVessel(const QString& body) {
    if (!m_doc->hasProject()) return tr("no project is open");
    sim::AssessmentDesc a = current();
    a.vessel = sim::VesselTarget{body.toStdString(), a.vessel ? a.vessel->margin : m_defaults.vesselMargin};
    return m_doc->editAssessment(tr("Vessel to protect: %1").arg(body), a);
}

void TargetTool::redraw() {
    if (!m_viewport) return;
    const bool draw = m_shown || m_pick != Pick::None;
    if (!draw || !m_doc->hasProject()) {
        if (m_drawn) m_viewport->setAuthoringLayer(Viewport::Layer::Targets, {});
        m_drawn = false;
        return;
    }
    const sim::AssessmentDesc a = current();
    std::vector<render::RenderMesh> meshes;
    for (render::RenderMesh m : {cutTargetsMesh(a.cuts, 0), clipTargetsMesh(a.clips, 0),
                                 sutureTargetMesh(a.suture.value_or(sim::SutureTarget{}), a.suture ? 0.03 : 0, 0),
                                 pendingTargetMesh(m_stroke, m_first, 0)})
        if (m.vertexCount() > 0) meshes.push_back(std::move(m)); // an empty mesh is no mesh to the renderer
    if (a.vessel)
        for (const render::RenderMesh& m : m_viewport->view().meshes()) {
            if (m.name != a.vessel->body || m.rest.size() < 3) continue;
            Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
            for (size_t k = 0; k + 2 < m.rest.size(); k += 3) {
                const Eigen::Vector3d p(m.rest[k], m.rest[k + 1], m.rest[k + 2]);
                lo = lo.cwiseMin(p);
                hi = hi.cwiseMax(p);
            }
            const Eigen::Vector3d pad = Eigen::Vector3d::Constant(a.vessel->margin);
            meshes.push_back(boxOutlineMesh(lo - pad, hi + pad, 0, "vessel target", {0.95f, 0.2f, 0.15f, 1.0f}));
            break;
        }
    m_viewport->setAuthoringLayer(Viewport::Layer::Targets, std::move(meshes));
    m_drawn = true;
}

} // namespace viscera::studio
