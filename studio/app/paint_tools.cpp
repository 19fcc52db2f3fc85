#include "app/paint_tools.hpp"

#include "app/viewport.hpp"
#include "render/case_settings.hpp"

#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QMainWindow>
#include <QMenu>
#include <QPushButton>
#include <QScrollArea>
#include <QSlider>
#include <QToolButton>

#include <algorithm>
#include <cmath>

namespace viscera::studio {
namespace {

/// The form of a paint tool's dock, starting with the tool's own button.
QFormLayout* toolForm(QWidget* host, QAction* action) {
    auto* form = new QFormLayout(host);
    auto* tool = new QToolButton(host);
    tool->setDefaultAction(action);
    tool->setToolButtonStyle(Qt::ToolButtonTextOnly);
    form->addRow(tool);
    return form;
}

} // namespace

PaintTools::PaintTools(QMainWindow* window, Document* doc, Preview* preview, Selection* selection, QMenu* menu)
    : QObject(window), m_window(window), m_doc(doc), m_preview(preview), m_sel(selection), m_painter(doc),
      m_samplePainter(doc) {
    m_paintAction = makeTool(menu, tr("&Paint stiffness"), "actionPaintStiffness", Qt::Key_P,
                             tr("Paint the selected body's stiffness weights through its curve skeleton "
                                "(left drag paints, Ctrl inverts, Esc cancels a stroke, right drag orbits)"));
    m_samplesAction = makeTool(menu, tr("Paint &light samples"), "actionPaintSamples", Qt::Key_L,
                               tr("Paint the selected body's area-light sample classes 1×, 4×, 8× (left drag "
                                  "paints or fills, Ctrl erases, Esc cancels, right drag orbits)"));
    buildPaintDock();
    buildSampleDock();
    connect(m_sel, &Selection::changed, this, &PaintTools::retarget);
}

QAction* PaintTools::makeTool(QMenu* menu, const QString& text, const char* name, Qt::Key key, const QString& tip) {
    auto* a = new QAction(text, m_window);
    a->setObjectName(name);
    a->setCheckable(true);
    a->setShortcut(QKeySequence(key));
    a->setToolTip(tip);
    connect(a, &QAction::toggled, this, [this, a](bool on) { setPaintTool(a, on); });
    menu->addAction(a);
    return a;
}

bool PaintTools::painting() const {
    return m_paintAction && m_paintAction->isChecked();
}

bool PaintTools::paintingSamples() const {
    return m_samplesAction && m_samplesAction->isChecked();
}

void PaintTools::setPaintTool(QAction* action, bool on) {
    if (action && action->isChecked() != on) {
        action->setChecked(on); // toggled() comes back here
        return;
    }
    QAction* other = action == m_paintAction ? m_samplesAction : m_paintAction;
    if (on && other && other->isChecked()) other->setChecked(false); // one paint tool at a time
    const bool any = painting() || paintingSamples();
    if (m_viewport) m_viewport->setPaintMode(any);
    emit toolChanged(any);
    if (on) {
        if (auto* d = m_window->findChild<QDockWidget*>(action == m_paintAction ? "paintDock" : "sampleDock")) {
            d->show();
            d->raise();
        }
    }
    retarget(); // on: the painters take the selection; off: the dock says what it would paint
    showOverlay();
}

void PaintTools::retarget() {
    const int body = m_sel->body();
    const auto mesh = body >= 0 && (painting() || paintingSamples()) ? m_preview->bodyMesh(body) : nullptr;
    if (painting() && m_sel->surface() >= 0)
        m_painter.setSurfaceTarget(m_sel->surface(), m_preview->surfaceMesh(m_sel->surface())); // polygon paint
    else if (painting())
        m_painter.setTarget(body, mesh);
    if (paintingSamples()) m_samplePainter.setTarget(body, mesh);
    // a dock whose tool is off says what it would paint now (never the previous project's body)
    QString name;
    if (m_doc->hasProject() && body >= 0 && body < static_cast<int>(m_doc->project().bodies.size()))
        name = QString::fromStdString(m_doc->project().bodies[body].scene.name);
    if (m_doc->hasProject() && m_sel->surface() >= 0 &&
        m_sel->surface() < static_cast<int>(m_doc->project().surfaces.size()))
        name = QString::fromStdString(m_doc->project().surfaces[m_sel->surface()].scene.name);
    if (!painting() && m_paintStatus)
        m_paintStatus->setText(name.isEmpty() ? tr("Select a tet body or a fascia surface to paint its stiffness.")
                                              : tr("'%1' selected: Paint stiffness (P) paints its weights.").arg(name));
    if (!paintingSamples() && m_sampleStatus)
        m_sampleStatus->setText(
            body < 0 ? tr("Select a tet body to paint its light samples.")
                     : tr("'%1' selected: Paint light samples (L) paints its sample classes.").arg(name));
}

render::RenderMesh PaintTools::brushRing() {
    // While a tool is on the ring is always there, hidden off the surface: the same meshes keep
    // their buffers (a mesh coming and going would make the viewport's renderer anew).
    if (m_hover) m_lastHover = m_hover;
    const bool fill = paintingSamples() && m_samplePainter.brush.tool == render::SamplePaintOp::Tool::Fill;
    const double radius = paintingSamples() ? m_samplePainter.brush.radius : m_painter.brush.radius;
    const auto at =
        m_lastHover.value_or(std::make_pair(Eigen::Vector3d::Zero().eval(), Eigen::Vector3d::UnitZ().eval()));
    render::RenderMesh ring = brushRingMesh(at.first, at.second, radius, 0);
    ring.visible = m_hover.has_value() && !fill;
    return ring;
}

void PaintTools::pushAuthoring() {
    if (!m_viewport) return;
    std::vector<render::RenderMesh> meshes = m_extra;
    if (painting() || paintingSamples()) meshes.push_back(brushRing());
    m_viewport->setAuthoringMeshes(std::move(meshes));
}

void PaintTools::moveRing() {
    if (!m_viewport) return;
    // the cursor moved: only the ring changes (the skeleton and section meshes stay as they are)
    if ((painting() || paintingSamples()) && m_viewport->authoringMeshCount() == m_extra.size() + 1)
        m_viewport->setAuthoringMesh(m_extra.size(), brushRing());
    else
        pushAuthoring();
}

void PaintTools::connectViewport(Viewport* v) {
    m_viewport = v;
    m_hover.reset();
    if (!v) return;
    // the brush's outline on the surface under the cursor, at the brush's radius
    connect(v, &Viewport::brushHovered, this, [this](const Viewport::SurfaceHit& hit) {
        m_hover = std::make_pair(hit.world.cast<double>(), hit.normal.cast<double>());
        moveRing();
    });
    connect(v, &Viewport::brushLeft, this, [this] {
        if (!m_hover) return;
        m_hover.reset();
        moveRing();
    });
    // a dab only on the painted body's own surface
    auto onBody = [this](const Viewport::SurfaceHit& hit) {
        const auto& meshes = m_viewport->view().meshes();
        const bool surface = !paintingSamples() && m_painter.surface() >= 0;
        const int index = paintingSamples() ? m_samplePainter.body() : surface ? m_painter.surface() : m_painter.body();
        return hit.mesh >= 0 && hit.mesh < static_cast<int>(meshes.size()) &&
               meshes[hit.mesh].source ==
                   (surface ? render::RenderMesh::Source::Surface : render::RenderMesh::Source::Body) &&
               static_cast<int>(meshes[hit.mesh].sourceIndex) == index;
    };
    connect(v, &Viewport::paintPressed, this, [this, onBody](const Viewport::SurfaceHit& hit) {
        if (!onBody(hit)) return;
        if (paintingSamples())
            m_samplePainter.begin(hit.rest.cast<double>(), hit.invert);
        else
            m_painter.begin(hit.rest.cast<double>(), hit.invert);
    });
    connect(v, &Viewport::paintMoved, this, [this, onBody](const Viewport::SurfaceHit& hit) {
        if (!onBody(hit)) return;
        if (paintingSamples())
            m_samplePainter.move(hit.rest.cast<double>());
        else
            m_painter.move(hit.rest.cast<double>());
    });
    connect(v, &Viewport::paintReleased, this, [this] {
        const QString why = paintingSamples() ? m_samplePainter.end() : m_painter.end();
        if (!why.isEmpty()) emit logMessage(why);
    });
    connect(v, &Viewport::paintCancelled, this, [this] {
        m_painter.cancel();
        m_samplePainter.cancel();
    });
    connect(v, &Viewport::brushAdjusted, this, [this](bool strength, double dx, bool done) {
        // a drag to the right grows the brush: ×2 per 200 px for the radius, +1 (or +0.2 for a
        // blend) per 100 px for the strength; Esc restores (done with dx 0)
        const bool samples = paintingSamples(); // its Shift+F sets the fill's edge angle
        auto* radius = m_window->findChild<QDoubleSpinBox*>(samples ? "sampleRadius" : "paintRadius");
        auto* amount = m_window->findChild<QDoubleSpinBox*>(samples ? "sampleAngle" : "paintStrength");
        if (!m_adjustStarted) {
            m_adjustRadius = radius->value();
            m_adjustStrength = amount->value();
            m_adjustStarted = true;
        }
        if (strength && samples) {
            amount->setValue(m_adjustStrength + dx / 100.0 * 15.0); // 15° per 100 px
        } else if (strength) {
            const bool blend =
                m_painter.brush.mode == sim::BrushMode::Mix || m_painter.brush.mode == sim::BrushMode::Smooth;
            amount->setValue(m_adjustStrength + dx / 100.0 * (blend ? 0.2 : 1.0));
        } else {
            radius->setValue(m_adjustRadius * std::pow(2.0, dx / 200.0));
        }
        if (done) m_adjustStarted = false;
    });
}

void PaintTools::showPaintedBody(render::RenderMesh::Source source, int index,
                                 const std::function<Eigen::Vector4f(int32_t node)>& rgbaOfNode,
                                 const std::optional<CutPlane>& cut, bool translucent) {
    const bool show = index >= 0 && rgbaOfNode;
    // the painted mesh at rest: the brush, the skeleton and the section share its frame
    m_viewport->setRestPose(show ? index : -1, source);
    const auto& meshes = m_viewport->view().meshes();
    for (size_t k = 0; k < meshes.size(); ++k) {
        const render::RenderMesh& m = meshes[k];
        const bool painted = show && m.source == source && static_cast<int>(m.sourceIndex) == index;
        // while painting, the painted body alone is drawn (a fascia on it or a neighbour would
        // hide its colours and take the brush's hits)
        m_viewport->setMeshVisible(static_cast<int>(k), painted || !show);
        m_viewport->setMeshTranslucent(static_cast<int>(k), painted && translucent);
        m_viewport->setFaceMask(static_cast<int>(k), painted && cut ? cutAwayMask(m, *cut) : std::vector<uint8_t>{});
        if (!painted) {
            if (!m.overlay.empty()) m_viewport->setOverlay(static_cast<int>(k), {});
            continue;
        }
        std::vector<float> rgba(4 * m.vertexCount());
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const Eigen::Vector4f c = rgbaOfNode(m.sourceVertex[v]);
            std::copy(c.data(), c.data() + 4, rgba.begin() + 4 * v);
        }
        m_viewport->setOverlay(static_cast<int>(k), rgba);
    }
}

void PaintTools::showOverlay() {
    if (!m_viewport) return;
    if (paintingSamples()) {
        showSampleClasses();
        return;
    }
    const std::vector<double>& w = m_painter.weights();
    const bool show = painting() && m_painter.ready() && !w.empty();
    const double base = m_painter.params().baseWeight;
    std::optional<CutPlane> cut;
    const bool surface = m_painter.surface() >= 0; // a fascia: its vertices alone, nothing inside
    const auto mesh = show && !surface ? m_preview->bodyMesh(m_painter.body()) : nullptr;
    if (show && mesh && m_paintCut && m_paintCut->isChecked()) {
        // the normal: towards the camera (the section faces the viewer), or an axis
        const int axis = m_paintCutAxis->currentIndex() - 1;
        const render::Camera& cam = m_viewport->camera();
        const Eigen::Vector3d n = axis < 0 ? Eigen::Vector3d((cam.position - cam.target).cast<double>().normalized())
                                           : Eigen::Vector3d::Unit(axis);
        double lo = INFINITY, hi = -INFINITY;
        for (const sim::Vec3& p : mesh->positions()) {
            lo = std::min(lo, n.dot(p));
            hi = std::max(hi, n.dot(p));
        }
        cut = CutPlane{n, lo + (hi - lo) * m_paintCutAt->value() / 100.0};
    }
    auto colour = [&w, base](int32_t node) {
        return weightColour(node >= 0 && static_cast<size_t>(node) < w.size() ? w[node] : base, base);
    };
    // with the skeleton shown and no section, the body is drawn translucent around it
    const bool skeleton =
        show && m_paintSkeleton && m_paintSkeleton->isChecked() && !m_painter.skeleton().nodes.empty();
    showPaintedBody(surface ? render::RenderMesh::Source::Surface : render::RenderMesh::Source::Body,
                    show ? (surface ? m_painter.surface() : m_painter.body()) : -1,
                    show ? std::function<Eigen::Vector4f(int32_t)>(colour) : nullptr, cut, skeleton && !cut);
    std::vector<render::RenderMesh> extra;
    if (skeleton) extra.push_back(skeletonMesh(m_painter.skeleton(), 0.0006f, 0));
    if (cut && mesh) extra.push_back(sliceMesh(*mesh, w, base, *cut, 0));
    m_extra = std::move(extra);
    pushAuthoring();
}

QDockWidget* PaintTools::addToolDock(QWidget* host, const QString& title, const char* name) {
    auto* d = new QDockWidget(title, m_window);
    d->setObjectName(name);
    auto* scroll = new QScrollArea(d); // a short dock scrolls instead of clipping the legend
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setWidget(host);
    d->setWidget(scroll);
    m_window->addDockWidget(Qt::LeftDockWidgetArea, d);
    // a tab beside the properties: stacked under them it made the left column taller than a
    // 1200-pixel screen
    if (auto* props = m_window->findChild<QDockWidget*>("propertiesDock")) m_window->tabifyDockWidget(props, d);
    d->hide(); // shown when the tool starts
    return d;
}

void PaintTools::buildPaintDock() {
    auto* host = new QWidget(m_window);
    QFormLayout* form = toolForm(host, m_paintAction);
    auto* mode = new QComboBox(host);
    mode->setObjectName("paintMode");
    mode->addItems({tr("Add"), tr("Subtract"), tr("Mix (towards target)"), tr("Smooth")});
    form->addRow(tr("Mode"), mode);
    auto spin = [&](const char* name, double lo, double hi, double value, int decimals, const QString& suffix) {
        auto* s = new QDoubleSpinBox(host);
        s->setObjectName(name);
        s->setRange(lo, hi);
        s->setDecimals(decimals);
        s->setValue(value);
        s->setSuffix(suffix);
        return s;
    };
    auto* radius = spin("paintRadius", 0.5, 200, m_painter.brush.radius * 1000, 1, tr(" mm"));
    auto* strength = spin("paintStrength", 0, 100, m_painter.brush.strength, 3, {});
    auto* target = spin("paintTarget", 0.001, 1e6, m_painter.brush.target, 3, {});
    radius->setToolTip(tr("The poly6 kernel's support h [A eq. 4.28]"));
    strength->setToolTip(tr("Add / Subtract: weight added at the brush centre. Mix / Smooth: blend in [0, 1]"));
    target->setToolTip(tr("Mix: the weight the stroke moves towards"));
    form->addRow(tr("Radius"), radius);
    form->addRow(tr("Strength"), strength);
    form->addRow(tr("Target weight"), target);
    auto sync = [this, mode, radius, strength, target] {
        m_painter.brush.mode = static_cast<sim::BrushMode>(mode->currentIndex());
        m_painter.brush.radius = radius->value() / 1000.0;
        m_painter.brush.strength = strength->value();
        m_painter.brush.target = target->value();
        target->setEnabled(m_painter.brush.mode == sim::BrushMode::Mix);
        if (m_painter.brush.mode == sim::BrushMode::Mix || m_painter.brush.mode == sim::BrushMode::Smooth)
            strength->setMaximum(1.0);
        else
            strength->setMaximum(100.0);
        moveRing(); // the outline takes the new radius
    };
    connect(mode, &QComboBox::currentIndexChanged, this, sync);
    for (QDoubleSpinBox* s : {radius, strength, target})
        connect(s, &QDoubleSpinBox::valueChanged, this, sync);
    sync();
    auto* skeletonOnly = new QCheckBox(tr("Reach only through the skeleton (eq. 4.26)"), host);
    skeletonOnly->setObjectName("paintSkeletonOnly");
    skeletonOnly->setToolTip(tr("Off: the brush changes the nodes it touches and the cross-sections of the skeleton "
                                "nodes inside it. On: only the latter (a surface far from the skeleton stays)"));
    connect(skeletonOnly, &QCheckBox::toggled, this,
            [this](bool on) { m_painter.brush.reach = on ? sim::BrushReach::Skeleton : sim::BrushReach::Sphere; });
    form->addRow(skeletonOnly);
    m_paintSkeleton = new QCheckBox(tr("Show the curve skeleton"), host);
    m_paintSkeleton->setObjectName("paintSkeleton");
    m_paintSkeleton->setChecked(true);
    form->addRow(m_paintSkeleton);
    m_paintCut = new QCheckBox(tr("Cut away (interior nodes on the section)"), host);
    m_paintCut->setObjectName("paintCut");
    m_paintCutAxis = new QComboBox(host);
    m_paintCutAxis->setObjectName("paintCutAxis");
    m_paintCutAxis->addItems({tr("facing the camera"), tr("x"), tr("y"), tr("z")});
    m_paintCutAt = new QSlider(Qt::Horizontal, host);
    m_paintCutAt->setObjectName("paintCutAt");
    m_paintCutAt->setRange(0, 100);
    m_paintCutAt->setValue(50);
    auto* cutRow = new QHBoxLayout;
    cutRow->addWidget(m_paintCutAxis);
    cutRow->addWidget(m_paintCutAt, 1);
    form->addRow(m_paintCut);
    form->addRow(tr("Section"), cutRow);
    connect(m_paintSkeleton, &QCheckBox::toggled, this, &PaintTools::showOverlay);
    connect(m_paintCut, &QCheckBox::toggled, this, &PaintTools::showOverlay);
    connect(m_paintCutAxis, &QComboBox::currentIndexChanged, this, &PaintTools::showOverlay);
    connect(m_paintCutAt, &QSlider::valueChanged, this, &PaintTools::showOverlay);
    auto* legend = new QLabel(tr("<span style='color:#1a4df2'>■</span> softer (¼× base) · "
                                 "<span style='color:#8c8c8c'>■</span> base (faint: unpainted) · "
                                 "<span style='color:#e61a0d'>■</span> stiffer (4× base)"),
                              host);
    legend->setObjectName("paintLegend");
    legend->setWordWrap(true);
    form->addRow(legend);
    m_paintStatus = new QLabel(tr("Select a tet body to paint its stiffness."), host);
    m_paintStatus->setObjectName("paintStatus");
    m_paintStatus->setWordWrap(true);
    form->addRow(m_paintStatus);
    addToolDock(host, tr("Stiffness paint"), "paintDock");
    connect(&m_painter, &StiffnessPainter::statusChanged, m_paintStatus, &QLabel::setText);
    connect(&m_painter, &StiffnessPainter::weightsChanged, this, &PaintTools::showOverlay);
    connect(&m_painter, &StiffnessPainter::readyChanged, this, &PaintTools::showOverlay);
}

void PaintTools::showSampleClasses() {
    if (!m_viewport) return;
    const std::vector<uint8_t>& classes = m_samplePainter.nodeClasses();
    const bool show = paintingSamples() && m_samplePainter.ready() && !classes.empty();
    auto colour = [&classes](int32_t node) {
        const std::array<float, 4> c =
            sampleClassColour(node >= 0 && static_cast<size_t>(node) < classes.size() ? classes[node] : 0);
        return Eigen::Vector4f(c[0], c[1], c[2], c[3]);
    };
    showPaintedBody(render::RenderMesh::Source::Body, show ? m_samplePainter.body() : -1,
                    show ? std::function<Eigen::Vector4f(int32_t)>(colour) : nullptr, std::nullopt);
    m_extra.clear();
    pushAuthoring();
    if (!m_sampleLegend) return;
    // the legend: the three classes' colours and their share of the body's surface
    const std::array<double, 4> a = show ? m_samplePainter.areas() : std::array<double, 4>{0, 0, 0, 0};
    const double all = a[0] + a[1] + a[2] + a[3];
    auto share = [&](int i) { return all > 0 ? 100.0 * a[i] / all : 0.0; };
    auto swatch = [](int samples) {
        const std::array<float, 4> c = sampleClassColour(samples);
        return QColor::fromRgbF(c[0], c[1], c[2]).name();
    };
    QString text;
    const int classesShown[] = {1, 4, 8};
    for (int i = 0; i < 3; ++i)
        text += tr("<span style='color:%1'>■</span> %2×: %3 %<br>")
                    .arg(swatch(classesShown[i]))
                    .arg(classesShown[i])
                    .arg(share(i + 1), 0, 'f', 1);
    text += tr("<span style='color:#8c8c8c'>■</span> unpainted (the case's uniform count): %1 %<br>"
               "surface %2 cm²")
                .arg(share(0), 0, 'f', 1)
                .arg(all * 1e4, 0, 'f', 1);
    m_sampleLegend->setText(text);
}

void PaintTools::buildSampleDock() {
    auto* host = new QWidget(m_window);
    QFormLayout* form = toolForm(host, m_samplesAction);
    auto* kind = new QComboBox(host);
    kind->setObjectName("sampleTool");
    kind->addItems({tr("Brush"), tr("Fill (up to sharp edges)")});
    form->addRow(tr("Tool"), kind);
    auto* cls = new QComboBox(host);
    cls->setObjectName("sampleClass");
    cls->addItems({tr("8× samples"), tr("4× samples"), tr("1× sample"), tr("Erase (unpainted)")});
    form->addRow(tr("Class"), cls);
    m_sampleLegend = new QLabel(host); // near the top: a short dock still shows it
    m_sampleLegend->setObjectName("sampleLegend");
    m_sampleLegend->setTextFormat(Qt::RichText);
    form->addRow(m_sampleLegend);
    auto* radius = new QDoubleSpinBox(host);
    radius->setObjectName("sampleRadius");
    radius->setRange(0.5, 200);
    radius->setDecimals(1);
    radius->setSuffix(tr(" mm"));
    radius->setValue(m_samplePainter.brush.radius * 1000);
    auto* angle = new QDoubleSpinBox(host);
    angle->setObjectName("sampleAngle");
    angle->setRange(0, 180);
    angle->setDecimals(1);
    angle->setSuffix(tr("°"));
    angle->setValue(m_samplePainter.brush.maxAngleDeg);
    angle->setToolTip(tr("Fill: an edge whose two faces turn by more than this stops it"));
    form->addRow(tr("Radius (F)"), radius);
    form->addRow(tr("Edge angle (Shift+F)"), angle);
    auto sync = [this, kind, cls, radius, angle] {
        static const int kClasses[] = {8, 4, 1, 0};
        m_samplePainter.brush.tool =
            kind->currentIndex() == 1 ? render::SamplePaintOp::Tool::Fill : render::SamplePaintOp::Tool::Brush;
        m_samplePainter.brush.samples = kClasses[std::clamp(cls->currentIndex(), 0, 3)];
        m_samplePainter.brush.radius = radius->value() / 1000.0;
        m_samplePainter.brush.maxAngleDeg = angle->value();
        radius->setEnabled(kind->currentIndex() == 0);
        angle->setEnabled(kind->currentIndex() == 1);
        moveRing(); // the outline takes the new radius (none for a fill)
    };
    connect(kind, &QComboBox::currentIndexChanged, this, sync);
    connect(cls, &QComboBox::currentIndexChanged, this, sync);
    for (QDoubleSpinBox* sp : {radius, angle})
        connect(sp, &QDoubleSpinBox::valueChanged, this, sync);
    sync();
    auto* compare = new QPushButton(tr("Compare uniform 1× | painted…"), host);
    compare->setObjectName("sampleCompare");
    compare->setToolTip(tr("Render the scene as the player would, uniform 1× beside the painted map, with the "
                           "error against the many-sample reference near the light and the frame time"));
    connect(compare, &QPushButton::clicked, this, [this] { openSampleCompare(); });
    form->addRow(compare);
    m_sampleStatus = new QLabel(tr("Select a tet body to paint its light samples."), host);
    m_sampleStatus->setObjectName("sampleStatus");
    m_sampleStatus->setWordWrap(true);
    form->addRow(m_sampleStatus);
    addToolDock(host, tr("Light samples"), "sampleDock");
    connect(&m_samplePainter, &SamplePainter::statusChanged, m_sampleStatus, &QLabel::setText);
    connect(&m_samplePainter, &SamplePainter::classesChanged, this, &PaintTools::showOverlay);
    showSampleClasses();
}

SampleCompareDialog* PaintTools::openSampleCompare() {
    if (!m_doc->hasProject()) return nullptr;
    auto source = m_preview->sceneView();
    if (!source) {
        emit logMessage(tr("Light samples: the preview has not built the scene yet"));
        return nullptr;
    }
    // the scene at rest with the painted classes, as the exported case would show it
    render::SceneView view = *source;
    const auto& bodies = m_doc->project().bodies;
    std::vector<sim::SurfaceDesc> layers;
    for (const SurfaceProject& sp : m_doc->project().surfaces)
        layers.push_back(sp.scene);
    for (size_t b = 0; b < bodies.size(); ++b) {
        const auto mesh = m_preview->bodyMesh(static_cast<int>(b));
        if (!mesh) continue;
        render::RenderMesh surface = render::bodySurfaceMesh(*mesh, bodies[b].scene.name, b);
        render::applySamplePaint(surface, bodies[b].lightSamples);
        render::applyBodySampleMap(view, b, bodies[b].scene.name,
                                   render::nodeSampleClasses(surface, mesh->vertexCount()), layers);
    }
    for (render::RenderMesh& m : view.meshes()) { // at rest, every face, no authoring colours
        m.positions = m.rest;
        m.faceMask.clear();
        m.overlay.clear();
        m.visible = true;
    }
    for (size_t k = 0; k < view.meshes().size(); ++k)
        view.recomputeNormals(k);
    render::RenderSettings settings = render::defaultSettingsFor(view, 480, 360);
    try {
        render::applyCaseRender(settings, m_doc->project().scene.render, "project.json");
    } catch (const std::exception& e) {
        emit logMessage(QString::fromStdString(e.what()));
    }
    if (!m_compare) m_compare = new SampleCompareDialog(m_window);
    m_compare->show();
    m_compare->raise();
    m_compare->start(view, settings);
    return m_compare;
}

} // namespace viscera::studio
