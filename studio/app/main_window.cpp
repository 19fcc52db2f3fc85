#include "app/main_window.hpp"

#include "app/number_text.hpp"

#include "app/export_runner.hpp"
#include "app/fit_dialog.hpp"
#include "app/material_panel.hpp"
#include "app/paint_overlays.hpp"
#include "app/plot_widget.hpp"
#include "app/texture_panel.hpp"
#include "app/viewport.hpp"
#include "app/wheel_guard.hpp"
#include "render/case_settings.hpp"
#include "sim/material/material.hpp"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QProgressDialog>
#include <QPushButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QSettings>
#include <QSlider>
#include <QStatusBar>
#include <QTimer>
#include <QToolBar>
#include <QToolButton>
#include <QTreeWidget>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace viscera::studio {
namespace {

enum ItemKind { kGroup = 0, kBody, kSurface, kMaterial, kInstrument, kRender, kSolver };
constexpr int kKindRole = Qt::UserRole, kIndexRole = Qt::UserRole + 1;

const char* const kBodyFields[] = {"youngs_modulus", "poisson_ratio", "density"};
const char* const kSolverFields[] = {"dt", "substeps", "iterations", "damping"};

} // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), m_export(std::make_unique<ExportRunner>()) {
    setObjectName("studioMainWindow");
    WheelGuard::install(); // the wheel scrolls docks; it never edits an unfocused field
    setDockNestingEnabled(true);
    setViewportHost(viewportHostFromText(QSettings().value("viewport/host").toString()).value_or(ViewportHost::Window));
    buildDocks();
    buildActions();
    statusBar()->showMessage(tr("Open or create a project (File menu)"));
    connect(&m_doc, &Document::changed, this, &MainWindow::onDocumentChanged);
    connect(&m_doc, &Document::logMessage, this, &MainWindow::logLine);
    connect(&m_preview, &Preview::logMessage, this, &MainWindow::logLine, Qt::QueuedConnection);
    connect(m_doc.undoStack(), &QUndoStack::cleanChanged, this, &MainWindow::updateTitle);
    connect(m_material, &MaterialPanel::fitRequested, this, [this](int body) {
        FitDialog dlg(&m_doc, body, this);
        dlg.exec();
    });
    connect(m_export.get(), &ExportRunner::progress, this, [this](int done, int total, const QString& stage) {
        if (!m_progress) return;
        m_progress->setMaximum(total);
        m_progress->setValue(done);
        m_progress->setLabelText(tr("Exporting: %1").arg(stage));
    });
    connect(m_export.get(), &ExportRunner::finished, this, [this](bool ok, const QString& message) {
        logLine(message);
        statusBar()->showMessage(message);
        if (m_progress) {
            m_progress->reset();
            m_progress->hide();
        }
        Q_UNUSED(ok);
    });
    m_poll = new QTimer(this);
    m_poll->setInterval(16);
    connect(m_poll, &QTimer::timeout, this, &MainWindow::pollPreview);
    m_poll->start();
    QSettings settings;
    restoreGeometry(settings.value("window/geometry").toByteArray());
    restoreState(settings.value("window/state").toByteArray());
    rebuildRecentMenu();
    updateTitle();
}

MainWindow::~MainWindow() {
    m_preview.stop();
}

void MainWindow::buildDocks() {
    auto dock = [this](const QString& name, const QString& title, QWidget* w, Qt::DockWidgetArea area) {
        auto* d = new QDockWidget(title, this);
        d->setObjectName(name);
        d->setWidget(w);
        addDockWidget(area, d);
        return d;
    };
    m_tree = new QTreeWidget(this);
    m_tree->setObjectName("projectTree");
    m_tree->setHeaderLabels({tr("Project"), tr("")});
    m_tree->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
    connect(m_tree, &QTreeWidget::currentItemChanged, this, [this](QTreeWidgetItem* item) {
        if (m_rebuilding || !item) return;
        const int kind = item->data(0, kKindRole).toInt(), index = item->data(0, kIndexRole).toInt();
        if (kind == kBody || kind == kMaterial) {
            selectBody(index);
            return;
        }
        if (kind == kSurface) {
            selectSurface(index);
            return;
        }
        m_body = -1;
        m_selKind = kind;
        m_selIndex = index;
        m_material->setBody(-1);
        m_texture->setTarget(TexturePanel::Target::None, -1);
        m_viewport->setSelectedName(QString());
        retargetPainter();
        scheduleRefresh(false);
    });
    dock("projectDock", tr("Project"), m_tree, Qt::LeftDockWidgetArea);

    m_propertiesHost = new QWidget(this);
    auto* pv = new QVBoxLayout(m_propertiesHost);
    m_properties = new QFormLayout;
    pv->addLayout(m_properties);
    m_propertyError = new QLabel(m_propertiesHost);
    m_propertyError->setObjectName("propertyError");
    m_propertyError->setWordWrap(true);
    m_propertyError->setStyleSheet("color: #b00020");
    pv->addWidget(m_propertyError);
    pv->addStretch();
    dock("propertiesDock", tr("Properties"), m_propertiesHost, Qt::LeftDockWidgetArea);

    m_material = new MaterialPanel(&m_doc, this);
    m_material->setObjectName("materialPanel");
    dock("materialDock", tr("Material curves"), m_material, Qt::BottomDockWidgetArea);

    m_texture = new TexturePanel(&m_doc, this);
    m_texture->setObjectName("texturePanel");
    auto* textureScroll = new QScrollArea(this); // a short dock scrolls instead of clipping the swatches
    textureScroll->setWidget(m_texture);
    textureScroll->setWidgetResizable(true);

    m_log = new QPlainTextEdit(this);
    m_log->setObjectName("log");
    m_log->setReadOnly(true);
    m_log->setMaximumBlockCount(2000);
    dock("logDock", tr("Log"), m_log, Qt::BottomDockWidgetArea);

    auto* plots = new QWidget(this);
    auto* pl = new QVBoxLayout(plots);
    auto* modeRow = new QHBoxLayout;
    m_previewMode = new QComboBox(plots);
    m_previewMode->setObjectName("previewMode");
    m_previewMode->addItems({tr("Preview: the scene"), tr("Preview: uniaxial specimen of the selected material")});
    connect(m_previewMode, &QComboBox::currentIndexChanged, this, [this](int) { submitPreview(); });
    modeRow->addWidget(m_previewMode, 1);
    auto* pause = new QCheckBox(tr("Pause"), plots);
    pause->setObjectName("previewPause");
    connect(pause, &QCheckBox::toggled, this, [this](bool on) { m_preview.setPaused(on); });
    modeRow->addWidget(pause);
    pl->addLayout(modeRow);
    m_verdict = new QLabel(plots);
    m_verdict->setObjectName("stabilityVerdict");
    m_verdict->setWordWrap(true);
    pl->addWidget(m_verdict);
    m_errorPlot = new PlotWidget(plots);
    m_errorPlot->setObjectName("errorPlot");
    m_errorPlot->setTitle(tr("Relative error vs Newton [A eq. 4.45]"));
    m_errorPlot->setAxes(tr("wall time [ms]"), tr("relative error"));
    m_errorPlot->setLogY(true);
    m_errorPlot->setLogX(true);
    pl->addWidget(m_errorPlot, 1);
    m_costPlot = new PlotWidget(plots);
    m_costPlot->setObjectName("costPlot");
    m_costPlot->setTitle(tr("Physics cost per frame"));
    m_costPlot->setAxes(tr("frame"), tr("ms"));
    pl->addWidget(m_costPlot, 1);
    QDockWidget* plotsDock = dock("plotsDock", tr("Preview and plots"), plots, Qt::RightDockWidgetArea);
    // a tab beside the plots, which stay in front: the panel needs the column's height
    tabifyDockWidget(plotsDock, dock("textureDock", tr("Material maps"), textureScroll, Qt::RightDockWidgetArea));
    plotsDock->raise();
}

void MainWindow::buildActions() {
    auto* toolbar = addToolBar(tr("Main"));
    toolbar->setObjectName("mainToolBar");
    QMenu* file = menuBar()->addMenu(tr("&File"));
    auto add = [&](QMenu* menu, const QString& text, QKeySequence key, auto fn, bool onToolbar = false) {
        QAction* a = menu->addAction(text);
        a->setShortcut(key);
        connect(a, &QAction::triggered, this, fn);
        if (onToolbar) toolbar->addAction(a);
        return a;
    };
    add(
        file, tr("&New project…"), QKeySequence::New,
        [this] {
            const QString dir = QFileDialog::getExistingDirectory(this, tr("Folder of the new project"));
            if (!dir.isEmpty()) newProject(dir);
        },
        true);
    add(
        file, tr("&Open project…"), QKeySequence::Open,
        [this] {
            const QString dir = QFileDialog::getExistingDirectory(this, tr("Project folder (with project.json)"));
            if (!dir.isEmpty()) openProject(dir);
        },
        true);
    m_recentMenu = file->addMenu(tr("Open &recent"));
    add(
        file, tr("&Save"), QKeySequence::Save, [this] { saveProject(); }, true);
    add(file, tr("Save &as…"), QKeySequence::SaveAs, [this] {
        const QString dir = QFileDialog::getExistingDirectory(this, tr("Save the project into folder"));
        if (!dir.isEmpty()) saveProjectAs(dir);
    });
    file->addSeparator();
    add(
        file, tr("&Export case…"), QKeySequence(tr("Ctrl+E")),
        [this] {
            if (!m_doc.hasProject()) return;
            const QString out = QFileDialog::getSaveFileName(
                this, tr("Export case package"),
                m_doc.folder() + "/" + QString::fromStdString(m_doc.project().caseId) + ".vcase",
                tr("Case packages (*.vcase)"));
            if (!out.isEmpty()) startExport(out);
        },
        true);
    file->addSeparator();
    add(file, tr("&Quit"), QKeySequence::Quit, [this] { close(); });

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    QAction* undo = m_doc.undoStack()->createUndoAction(this, tr("&Undo"));
    undo->setShortcut(QKeySequence::Undo);
    QAction* redo = m_doc.undoStack()->createRedoAction(this, tr("&Redo"));
    redo->setShortcut(QKeySequence::Redo);
    edit->addAction(undo);
    edit->addAction(redo);
    toolbar->addSeparator();
    toolbar->addAction(undo);
    toolbar->addAction(redo);

    QMenu* view = menuBar()->addMenu(tr("&View"));
    m_frameAction = add(view, tr("&Frame all"), QKeySequence(Qt::Key_F), [this] { m_viewport->frameAll(); });
    // the paint tools: checkable, one at a time (setPaintTool)
    auto tool = [this, view](const QString& text, const char* name, Qt::Key key, const QString& tip) {
        auto* a = new QAction(text, this);
        a->setObjectName(name);
        a->setCheckable(true);
        a->setShortcut(QKeySequence(key));
        a->setToolTip(tip);
        connect(a, &QAction::toggled, this, [this, a](bool on) { setPaintTool(a, on); });
        view->addAction(a);
        return a;
    };
    m_paintAction = tool(tr("&Paint stiffness"), "actionPaintStiffness", Qt::Key_P,
                         tr("Paint the selected body's stiffness weights through its curve skeleton "
                            "(left drag paints, Ctrl inverts, Esc cancels a stroke, Alt + left drag orbits)"));
    m_samplesAction = tool(tr("Paint &light samples"), "actionPaintSamples", Qt::Key_L,
                           tr("Paint the selected body's area-light sample classes 1×, 4×, 8× (left drag "
                              "paints or fills, Ctrl erases, Esc cancels, Alt + left drag orbits)"));
    toolbar->addSeparator();
    toolbar->addAction(m_paintAction);
    toolbar->addAction(m_samplesAction);
    buildPaintDock();
    buildSampleDock();
    m_widgetHostAction = view->addAction(tr("Compatibility viewport (QOpenGLWidget, slower)"));
    m_widgetHostAction->setObjectName("actionWidgetViewport");
    m_widgetHostAction->setCheckable(true);
    m_widgetHostAction->setChecked(m_viewport->host() == ViewportHost::Widget);
    m_widgetHostAction->setToolTip(tr("Draw the viewport in a QOpenGLWidget instead of an embedded window: for "
                                      "displays where the embedded window misbehaves; every repaint of the "
                                      "main window then composes through OpenGL"));
    connect(m_widgetHostAction, &QAction::toggled, this,
            [this](bool on) { setViewportHost(on ? ViewportHost::Widget : ViewportHost::Window); });
    view->addSeparator();
    for (QDockWidget* d : findChildren<QDockWidget*>())
        view->addAction(d->toggleViewAction());
    view->addAction(toolbar->toggleViewAction());
}

void MainWindow::setViewportHost(ViewportHost host) {
    if (m_viewport && m_viewport->host() == host) return;
    const QString selected = m_viewport ? m_viewport->selectedName() : QString();
    // The old viewport goes first: a QOpenGLWidget added to the window makes Qt recreate the
    // top-level native window, which would take an embedded window still in it along.
    if (m_viewport) {
        m_viewport = nullptr;
        delete takeCentralWidget();
    }
    auto* v = new Viewport(host, this);
    v->setObjectName("viewport");
    connect(v, &Viewport::bodyClicked, this, [this](const QString& name) {
        if (!m_doc.hasProject()) return;
        const auto& bodies = m_doc.project().bodies;
        for (size_t i = 0; i < bodies.size(); ++i)
            if (QString::fromStdString(bodies[i].scene.name) == name) selectBody(static_cast<int>(i));
    });
    connect(v, &Viewport::rendererFailed, this, &MainWindow::logLine);
    connectPainting(v);
    setCentralWidget(v);
    m_viewport = v;
    // the new host shows what the old one did
    if (m_doc.hasProject()) v->setCaseRender(m_doc.project().scene.render);
    if (auto view = m_preview.sceneView()) {
        v->setScene(*view);
        const Preview::Snapshot s = m_preview.snapshot();
        v->setPositions(s.bodies, s.surfaces);
    }
    v->setSelectedName(selected);
    v->setPaintMode(painting());
    showPaintWeights();
    QSettings().setValue("viewport/host", viewportHostText(host));
    if (m_widgetHostAction) m_widgetHostAction->setChecked(host == ViewportHost::Widget);
}

bool MainWindow::painting() const {
    return m_paintAction && m_paintAction->isChecked();
}

void MainWindow::setPainting(bool on) {
    setPaintTool(m_paintAction, on);
}

bool MainWindow::paintingSamples() const {
    return m_samplesAction && m_samplesAction->isChecked();
}

void MainWindow::setPaintingSamples(bool on) {
    setPaintTool(m_samplesAction, on);
}

void MainWindow::setPaintTool(QAction* action, bool on) {
    if (action && action->isChecked() != on) {
        action->setChecked(on); // toggled() comes back here
        return;
    }
    QAction* other = action == m_paintAction ? m_samplesAction : m_paintAction;
    if (on && other && other->isChecked()) other->setChecked(false); // one paint tool at a time
    const bool any = painting() || paintingSamples();
    m_viewport->setPaintMode(any);
    // in paint mode F and Shift+F size the brush (the viewport's own keys); Home still frames
    m_frameAction->setShortcut(any ? QKeySequence(Qt::Key_Home) : QKeySequence(Qt::Key_F));
    if (on) {
        if (auto* d = findChild<QDockWidget*>(action == m_paintAction ? "paintDock" : "sampleDock")) {
            d->show();
            d->raise();
        }
        retargetPainter();
    }
    showPaintWeights();
}

void MainWindow::retargetPainter() {
    const auto mesh = m_body >= 0 && (painting() || paintingSamples()) ? m_preview.bodyMesh(m_body) : nullptr;
    if (painting() && m_selKind == kSurface)
        m_painter.setSurfaceTarget(m_selIndex, m_preview.surfaceMesh(m_selIndex)); // polygon paint
    else if (painting())
        m_painter.setTarget(m_body, mesh);
    if (paintingSamples()) m_samplePainter.setTarget(m_body, mesh);
}

void MainWindow::connectPainting(Viewport* v) {
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
        if (!why.isEmpty()) logLine(why);
    });
    connect(v, &Viewport::paintCancelled, this, [this] {
        m_painter.cancel();
        m_samplePainter.cancel();
    });
    connect(v, &Viewport::brushAdjusted, this, [this](bool strength, double dx, bool done) {
        // a drag to the right grows the brush: ×2 per 200 px for the radius, +1 (or +0.2 for a
        // blend) per 100 px for the strength; Esc restores (done with dx 0)
        const bool samples = paintingSamples(); // its Shift+F sets the fill's edge angle
        auto* radius = findChild<QDoubleSpinBox*>(samples ? "sampleRadius" : "paintRadius");
        auto* amount = findChild<QDoubleSpinBox*>(samples ? "sampleAngle" : "paintStrength");
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

void MainWindow::showPaintedBody(render::RenderMesh::Source source, int index,
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

void MainWindow::showPaintWeights() {
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
    const auto mesh = show && !surface ? m_preview.bodyMesh(m_painter.body()) : nullptr;
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
    m_viewport->setAuthoringMeshes(std::move(extra));
}

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

QDockWidget* MainWindow::addToolDock(QWidget* host, const QString& title, const char* name) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(name);
    auto* scroll = new QScrollArea(d); // a short dock scrolls instead of clipping the legend
    scroll->setWidgetResizable(true);
    scroll->setFrameShape(QFrame::NoFrame);
    scroll->setWidget(host);
    d->setWidget(scroll);
    addDockWidget(Qt::LeftDockWidgetArea, d);
    // a tab beside the properties: stacked under them it made the left column taller than a
    // 1200-pixel screen
    if (auto* props = findChild<QDockWidget*>("propertiesDock")) tabifyDockWidget(props, d);
    d->hide(); // shown when the tool starts
    return d;
}

void MainWindow::buildPaintDock() {
    auto* host = new QWidget(this);
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
    };
    connect(mode, &QComboBox::currentIndexChanged, this, sync);
    for (QDoubleSpinBox* s : {radius, strength, target})
        connect(s, &QDoubleSpinBox::valueChanged, this, sync);
    sync();
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
    connect(m_paintSkeleton, &QCheckBox::toggled, this, &MainWindow::showPaintWeights);
    connect(m_paintCut, &QCheckBox::toggled, this, &MainWindow::showPaintWeights);
    connect(m_paintCutAxis, &QComboBox::currentIndexChanged, this, &MainWindow::showPaintWeights);
    connect(m_paintCutAt, &QSlider::valueChanged, this, &MainWindow::showPaintWeights);
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
    connect(&m_painter, &StiffnessPainter::weightsChanged, this, &MainWindow::showPaintWeights);
    connect(&m_painter, &StiffnessPainter::readyChanged, this, &MainWindow::showPaintWeights);
}

void MainWindow::showSampleClasses() {
    const std::vector<uint8_t>& classes = m_samplePainter.nodeClasses();
    const bool show = paintingSamples() && m_samplePainter.ready() && !classes.empty();
    auto colour = [&classes](int32_t node) {
        const std::array<float, 4> c =
            sampleClassColour(node >= 0 && static_cast<size_t>(node) < classes.size() ? classes[node] : 0);
        return Eigen::Vector4f(c[0], c[1], c[2], c[3]);
    };
    showPaintedBody(render::RenderMesh::Source::Body, show ? m_samplePainter.body() : -1,
                    show ? std::function<Eigen::Vector4f(int32_t)>(colour) : nullptr, std::nullopt);
    m_viewport->setAuthoringMeshes({});
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

void MainWindow::buildSampleDock() {
    auto* host = new QWidget(this);
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
    connect(&m_samplePainter, &SamplePainter::classesChanged, this, &MainWindow::showPaintWeights);
    showSampleClasses();
}

SampleCompareDialog* MainWindow::openSampleCompare() {
    if (!m_doc.hasProject()) return nullptr;
    auto source = m_preview.sceneView();
    if (!source) {
        logLine(tr("Light samples: the preview has not built the scene yet"));
        return nullptr;
    }
    // the scene at rest with the painted classes, as the exported case would show it
    render::SceneView view = *source;
    const auto& bodies = m_doc.project().bodies;
    std::vector<sim::SurfaceDesc> layers;
    for (const SurfaceProject& sp : m_doc.project().surfaces)
        layers.push_back(sp.scene);
    for (size_t b = 0; b < bodies.size(); ++b) {
        const auto mesh = m_preview.bodyMesh(static_cast<int>(b));
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
        render::applyCaseRender(settings, m_doc.project().scene.render, "project.json");
    } catch (const std::exception& e) {
        logLine(QString::fromStdString(e.what()));
    }
    if (!m_compare) m_compare = new SampleCompareDialog(this);
    m_compare->show();
    m_compare->raise();
    m_compare->start(view, settings);
    return m_compare;
}

QStringList MainWindow::recentProjects() const {
    return QSettings().value("recentProjects").toStringList();
}

void MainWindow::addRecent(const QString& folder) {
    QStringList list = recentProjects();
    list.removeAll(folder);
    list.prepend(folder);
    while (list.size() > kMaxRecent)
        list.removeLast();
    QSettings().setValue("recentProjects", list);
    rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
    m_recentMenu->clear();
    const QStringList list = recentProjects();
    for (const QString& f : list) {
        QAction* a = m_recentMenu->addAction(f);
        connect(a, &QAction::triggered, this, [this, f] { openProject(f); });
    }
    m_recentMenu->setEnabled(!list.isEmpty());
}

void MainWindow::logLine(const QString& line) {
    m_log->appendPlainText(QDateTime::currentDateTime().toString("hh:mm:ss  ") + line);
}

bool MainWindow::maybeDiscard() {
    if (!m_confirm || !m_doc.hasProject() || m_doc.undoStack()->isClean()) return true;
    const auto r = QMessageBox::question(this, tr("Unsaved changes"), tr("Save the changes to the project first?"),
                                         QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (r == QMessageBox::Cancel) return false;
    if (r == QMessageBox::Save) return saveProject();
    return true;
}

bool MainWindow::openProject(const QString& folder) {
    if (!maybeDiscard()) return false;
    try {
        m_doc.open(folder);
    } catch (const std::exception& e) {
        const QString why = QString::fromStdString(e.what());
        logLine(why);
        statusBar()->showMessage(why);
        return false;
    }
    addRecent(m_doc.folder());
    m_body = -1;
    selectBody(m_doc.project().bodies.empty() ? -1 : 0);
    statusBar()->showMessage(tr("Opened %1").arg(m_doc.folder()));
    return true;
}

bool MainWindow::newProject(const QString& folder) {
    if (!maybeDiscard()) return false;
    try {
        const QString id = QFileInfo(folder).fileName().toLower().replace(QRegularExpression("[^a-z0-9-]"), "-");
        m_doc.createNew(folder, id.isEmpty() ? QStringLiteral("new-case") : id);
    } catch (const std::exception& e) {
        logLine(QString::fromStdString(e.what()));
        return false;
    }
    addRecent(m_doc.folder());
    selectBody(0);
    return true;
}

bool MainWindow::saveProject() {
    if (!m_doc.hasProject()) return false;
    try {
        m_doc.save();
    } catch (const std::exception& e) {
        const QString why = QString::fromStdString(e.what());
        logLine(why);
        statusBar()->showMessage(why);
        return false;
    }
    statusBar()->showMessage(tr("Saved"));
    return true;
}

bool MainWindow::saveProjectAs(const QString& folder) {
    if (!m_doc.hasProject()) return false;
    try {
        m_doc.saveAs(folder);
    } catch (const std::exception& e) {
        logLine(QString::fromStdString(e.what()));
        return false;
    }
    addRecent(m_doc.folder());
    return true;
}

bool MainWindow::startExport(const QString& out) {
    if (!m_doc.hasProject()) return false;
    if (m_realTime.slower()) { // said before the work: the trainee's session would fall behind
        const QString warning =
            tr("warning: the case runs at ×%1 of real time in the preview (%2 ms per %3 ms frame over the last %4 "
               "frames, one solver thread): a trainee's session would fall behind; fewer substeps or a coarser "
               "mesh would help")
                .arg(m_realTime.factor, 0, 'f', 2)
                .arg(numberText(m_realTime.meanMs))
                .arg(numberText(m_realTime.budgetMs))
                .arg(m_realTime.frames);
        logLine(warning);
        statusBar()->showMessage(warning);
    }
    QString why;
    if (!m_export->start(m_doc.project(), out, &why)) {
        logLine(why);
        statusBar()->showMessage(why);
        return false;
    }
    if (!m_progress) {
        m_progress = new QProgressDialog(this);
        m_progress->setObjectName("exportProgress");
        m_progress->setWindowTitle(tr("Export case"));
        m_progress->setMinimumDuration(0);
        m_progress->setAutoReset(false);
        m_progress->setAutoClose(false);
        connect(m_progress, &QProgressDialog::canceled, m_export.get(), &ExportRunner::cancel);
    }
    m_progress->setMaximum(m_export->stageCount());
    m_progress->setValue(0);
    m_progress->setLabelText(tr("Exporting %1").arg(out));
    m_progress->show();
    logLine(tr("exporting to %1").arg(out));
    return true;
}

void MainWindow::closeEvent(QCloseEvent* e) {
    if (!maybeDiscard()) {
        e->ignore();
        return;
    }
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/state", saveState());
    m_preview.stop();
    e->accept();
}

void MainWindow::updateTitle() {
    QString title = tr("Viscera Studio");
    if (m_doc.hasProject())
        title = QStringLiteral("%1 [*] — %2 — %3")
                    .arg(QString::fromStdString(m_doc.project().caseId), m_doc.folder(), tr("Viscera Studio"));
    setWindowTitle(title);
    setWindowModified(m_doc.hasProject() && !m_doc.undoStack()->isClean());
}

void MainWindow::onDocumentChanged() {
    if (m_doc.hasProject() && m_body >= static_cast<int>(m_doc.project().bodies.size())) m_body = -1;
    if (m_doc.hasProject()) m_viewport->setCaseRender(m_doc.project().scene.render);
    updateTitle();
    submitPreview();
    scheduleRefresh();
}

void MainWindow::scheduleRefresh(bool tree) {
    m_treePending = m_treePending || tree;
    // The tree and the property fields are rebuilt on the next pass of the event loop: an edit
    // often comes from one of those fields' own signals, which must not delete it, and a drag's
    // many edits then cost one rebuild per pass.
    if (m_refreshPending) return;
    m_refreshPending = true;
    QTimer::singleShot(0, this, [this] {
        m_refreshPending = false;
        // Rebuilt only when what they show changed: a curve drag changes neither, and building
        // widgets is what costs in a pass of the event loop.
        const QString tree = treeKey(), props = propertiesKey();
        if ((m_treePending || m_forceRefresh) && tree != m_treeKey) rebuildTree();
        if (props != m_propertiesKey || m_forceRefresh) rebuildProperties();
        m_treeKey = tree;
        m_propertiesKey = props;
        m_treePending = m_forceRefresh = false;
    });
}

void MainWindow::submitPreview() {
    if (!m_doc.hasProject()) return;
    uint64_t frames = 0;
    const uint64_t serial = m_preview.submit(
        m_doc.project(), m_previewMode->currentIndex() == 1 ? Preview::Mode::Specimen : Preview::Mode::Scene,
        std::max(0, m_body), &frames);
    m_lastSubmit = {serial, frames};
}

void MainWindow::selectBody(int index) {
    m_body = index;
    m_selKind = index >= 0 ? kBody : kGroup;
    m_selIndex = index;
    m_material->setBody(index);
    m_texture->setTarget(TexturePanel::Target::Body, index);
    retargetPainter();
    const bool ok = m_doc.hasProject() && index >= 0 && index < static_cast<int>(m_doc.project().bodies.size());
    m_viewport->setSelectedName(ok ? QString::fromStdString(m_doc.project().bodies[index].scene.name) : QString());
    followInTree(kBody, index);
    scheduleRefresh(false);
    if (m_previewMode->currentIndex() == 1) submitPreview();
}

void MainWindow::followInTree(int kind, int index) {
    m_rebuilding = true; // the tree follows without selecting again
    for (QTreeWidgetItemIterator it(m_tree); *it; ++it)
        if ((*it)->data(0, kKindRole).toInt() == kind && (*it)->data(0, kIndexRole).toInt() == index) {
            m_tree->setCurrentItem(*it);
            break;
        }
    m_rebuilding = false;
}

void MainWindow::selectSurface(int index) {
    const bool ok = m_doc.hasProject() && index >= 0 && index < static_cast<int>(m_doc.project().surfaces.size());
    m_body = -1;
    m_selKind = ok ? kSurface : kGroup;
    m_selIndex = ok ? index : -1;
    m_material->setBody(-1);
    m_texture->setTarget(ok ? TexturePanel::Target::Surface : TexturePanel::Target::None, ok ? index : -1);
    retargetPainter();
    m_viewport->setSelectedName(ok ? QString::fromStdString(m_doc.project().surfaces[index].scene.name) : QString());
    followInTree(kSurface, index);
    scheduleRefresh(false);
}

QString MainWindow::treeKey() const {
    if (!m_doc.hasProject()) return {};
    const Project& p = m_doc.project();
    QString k =
        QString::fromStdString(p.scene.solverType) + QString::number(m_selKind) + ":" + QString::number(m_selIndex);
    for (const BodyProject& b : p.bodies)
        k += "|" + QString::fromStdString(b.scene.name + ":" + sim::materialModelName(b.scene.material.model));
    for (const SurfaceProject& sp : p.surfaces)
        k += "|s" + QString::fromStdString(sp.scene.name + ":" + sp.scene.attachTo);
    if (p.scene.interaction)
        for (const auto& in : p.scene.interaction->instruments)
            k += "|i" + QString::fromStdString(in.name);
    return k + (p.scene.suture ? "|needle" : "");
}

QString MainWindow::propertiesKey() const {
    if (!m_doc.hasProject()) return {};
    const Project& p = m_doc.project();
    QString k = QString::number(m_selKind) + ":" + QString::number(m_selIndex) + ":" + QString::number(m_body);
    if (m_body >= 0 && m_body < static_cast<int>(p.bodies.size())) {
        const sim::Material& m = p.bodies[m_body].scene.material;
        k += QString::fromStdString(sim::materialModelName(m.model)) + numberText(m.youngsModulus) + "," +
             numberText(m.poissonRatio) + "," + numberText(m.density);
    }
    const auto& x = p.scene.xpbd;
    k += "|" + numberText(x.dt) + "," + QString::number(x.substeps) + "," + QString::number(x.iterations) + "," +
         numberText(x.damping);
    return k + "|" + QString::fromStdString(p.scene.render);
}

void MainWindow::rebuildTree() {
    m_rebuilding = true;
    m_tree->clear();
    if (m_doc.hasProject()) {
        const Project& p = m_doc.project();
        auto group = [&](const QString& name, int kind) {
            auto* g = new QTreeWidgetItem(m_tree, {name});
            g->setData(0, kKindRole, kind == kSolver || kind == kRender ? kind : kGroup);
            g->setData(0, kIndexRole, -1);
            if (kind == m_selKind && (kind == kSolver || kind == kRender)) m_tree->setCurrentItem(g);
            return g;
        };
        auto leaf = [&](QTreeWidgetItem* g, const QString& name, const QString& info, int kind, int index) {
            auto* it = new QTreeWidgetItem(g, {name, info});
            it->setData(0, kKindRole, kind);
            it->setData(0, kIndexRole, index);
            if (kind == m_selKind && index == m_selIndex) m_tree->setCurrentItem(it);
        };
        QTreeWidgetItem* bodies = group(tr("Bodies"), kGroup);
        QTreeWidgetItem* materials = group(tr("Materials"), kGroup);
        for (size_t i = 0; i < p.bodies.size(); ++i) {
            const auto& b = p.bodies[i].scene;
            leaf(bodies, QString::fromStdString(b.name), tr("tet body"), kBody, static_cast<int>(i));
            leaf(materials, QString::fromStdString(b.name) + tr(" material"),
                 QString::fromStdString(sim::materialModelName(b.material.model)), kMaterial, static_cast<int>(i));
        }
        QTreeWidgetItem* surfaces = group(tr("Surfaces"), kGroup);
        for (size_t s = 0; s < p.surfaces.size(); ++s)
            leaf(surfaces, QString::fromStdString(p.surfaces[s].scene.name),
                 tr("on %1").arg(QString::fromStdString(p.surfaces[s].scene.attachTo)), kSurface, static_cast<int>(s));
        QTreeWidgetItem* instruments = group(tr("Instruments"), kGroup);
        if (p.scene.interaction)
            for (size_t t = 0; t < p.scene.interaction->instruments.size(); ++t)
                leaf(instruments, QString::fromStdString(p.scene.interaction->instruments[t].name), tr("scripted"),
                     kInstrument, static_cast<int>(t));
        if (p.scene.suture) leaf(instruments, tr("needle"), tr("suture trajectory"), kInstrument, -1);
        group(tr("Render settings"), kRender);
        group(tr("Solver (%1)").arg(QString::fromStdString(p.scene.solverType)), kSolver);
        m_tree->expandAll();
    }
    m_rebuilding = false;
}

void MainWindow::rebuildProperties() {
    while (m_properties->rowCount() > 0)
        m_properties->removeRow(0);
    if (!m_doc.hasProject()) return;
    const Project& p = m_doc.project();
    auto field = [&](const QString& name, const QString& label, const QString& value) {
        auto* e = new QLineEdit(value, m_propertiesHost);
        e->setObjectName(name);
        connect(e, &QLineEdit::editingFinished, this, [this, e, name] {
            if (e->isModified()) {
                e->setModified(false);
                setProperty(name, e->text());
            }
        });
        m_properties->addRow(label, e);
    };
    const int kind = m_selKind;
    if (m_body >= 0 && m_body < static_cast<int>(p.bodies.size())) {
        const sim::Material& m = p.bodies[m_body].scene.material;
        m_properties->addRow(tr("Body"), new QLabel(QString::fromStdString(p.bodies[m_body].scene.name)));
        auto* model = new QComboBox(m_propertiesHost);
        model->setObjectName("model");
        for (auto mm :
             {sim::MaterialModel::StableNeoHookean, sim::MaterialModel::NeoHookean, sim::MaterialModel::Linear,
              sim::MaterialModel::StVenantKirchhoff, sim::MaterialModel::Corotated, sim::MaterialModel::ValanisLandel})
            model->addItem(QString::fromStdString(sim::materialModelName(mm)));
        model->setCurrentText(QString::fromStdString(sim::materialModelName(m.model)));
        connect(model, &QComboBox::currentTextChanged, this, [this](const QString& t) { setProperty("model", t); });
        m_properties->addRow(tr("Material model"), model);
        field("youngs_modulus", tr("Young's modulus E [Pa]"), numberText(m.youngsModulus));
        field("poisson_ratio", tr("Poisson ratio ν"), numberText(m.poissonRatio));
        field("density", tr("Density [kg/m³]"), numberText(m.density));
    } else if (kind == kSolver && p.scene.solverType == "xpbd") {
        field("dt", tr("Frame step dt [s]"), numberText(p.scene.xpbd.dt));
        field("substeps", tr("Substeps per frame"), QString::number(p.scene.xpbd.substeps));
        field("iterations", tr("Iterations per substep"), QString::number(p.scene.xpbd.iterations));
        field("damping", tr("Damping [1/s]"), numberText(p.scene.xpbd.damping));
    } else if (kind == kRender) {
        auto* l = new QLabel(p.scene.render.empty() ? tr("renderer defaults") : QString::fromStdString(p.scene.render));
        l->setWordWrap(true);
        m_properties->addRow(tr("Render"), l);
    } else if (kind == kSurface && m_selIndex >= 0 && m_selIndex < static_cast<int>(p.surfaces.size())) {
        const auto& s = p.surfaces.at(m_selIndex).scene;
        m_properties->addRow(tr("Surface"), new QLabel(QString::fromStdString(s.name)));
        m_properties->addRow(tr("Stretch stiffness"), new QLabel(numberText(s.stretchStiffness)));
        m_properties->addRow(tr("Areal density"), new QLabel(numberText(s.arealDensity)));
    }
}

QString MainWindow::setProperty(const QString& field, const QString& text) {
    auto show = [&](const QString& w) {
        m_propertyError->setText(w);
        if (!w.isEmpty()) {
            logLine(w);
            m_forceRefresh = true; // the field shows the model's value again
            scheduleRefresh();
        }
        return w;
    };
    if (field == "model") {
        if (m_body < 0) return show(tr("no body selected"));
        const int b = m_body;
        if (text == "valanis_landel") {
            const sim::Material& m = m_doc.project().bodies[b].scene.material;
            if (m.model == sim::MaterialModel::ValanisLandel) return show({});
            return show(m_material->applyPreset("neo_hookean", m.youngsModulus, m.poissonRatio));
        }
        return show(m_doc.edit(tr("Set material model"), [&](Project& p) {
            sim::Material& m = p.bodies.at(b).scene.material;
            m.model = sim::materialModelFromName(text.toStdString());
            m.curvePreset.clear();
            m.fPrime.reset();
            m.gPrime.reset();
            m.hPrime.reset();
        }));
    }
    QString why;
    const std::optional<double> parsed = parseNumberText(text, field, why);
    if (!parsed) return show(why);
    const double v = *parsed;
    const int b = m_body;
    for (const char* f : kBodyFields)
        if (field == f) {
            if (b < 0) return show(tr("no body selected"));
            return show(m_doc.edit(tr("Set %1").arg(field), [&](Project& p) {
                sim::Material& m = p.bodies.at(b).scene.material;
                if (field == "youngs_modulus") m.youngsModulus = v;
                if (field == "poisson_ratio") m.poissonRatio = v;
                if (field == "density") m.density = v;
            }));
        }
    for (const char* f : kSolverFields)
        if (field == f) {
            if ((field == "substeps" || field == "iterations") && v != std::floor(v))
                return show(tr("solver.%1: '%2' must be a whole number").arg(field, text));
            // A whole number past any valid count still reaches the reader's rule, which names the range.
            const int count = static_cast<int>(std::clamp(v, -1e9, 1e9));
            return show(m_doc.edit(tr("Set solver %1").arg(field), [&](Project& p) {
                if (field == "dt") p.scene.xpbd.dt = v;
                if (field == "substeps") p.scene.xpbd.substeps = count;
                if (field == "iterations") p.scene.xpbd.iterations = count;
                if (field == "damping") p.scene.xpbd.damping = v;
            }));
        }
    return show(tr("%1: not a property of the selection").arg(field));
}

void MainWindow::pollPreview() {
    if (!m_doc.hasProject() || m_preview.revision() == m_shownRevision) return;
    m_shownRevision = m_preview.revision();
    const Preview::Snapshot s = m_preview.snapshot();
    // Only what changed is redrawn: an edit alone changes the verdict, not the positions, and a
    // repaint of the viewport or a plot is what costs on the UI thread.
    const bool newScene = s.scene != m_shownScene;
    if (newScene) {
        if (auto view = m_preview.sceneView()) m_viewport->setScene(*view);
        retargetPainter(); // the same mesh keeps its skeleton; a new one is mapped again
        showPaintWeights();
        m_shownScene = s.scene;
    }
    if (newScene || s.frames != m_shownFrames) {
        m_shownFrames = s.frames;
        m_viewport->setPositions(s.bodies, s.surfaces);
        PlotWidget::Series c{tr("physics ms"), {}, {}, QColor(40, 90, 200)};
        const double first = static_cast<double>(s.frames) - static_cast<double>(s.frameMs.size());
        for (size_t i = 0; i < s.frameMs.size(); ++i) {
            c.x.push_back(first + static_cast<double>(i));
            c.y.push_back(s.frameMs[i]);
        }
        // The frame's budget beside the cost, and what it says of real time.
        const double dt = m_doc.hasProject() ? m_doc.project().scene.xpbd.dt : 0;
        m_realTime = estimateRealTime(s.frameMs, dt);
        std::vector<PlotWidget::Series> series{c};
        if (dt > 0 && !c.x.empty())
            series.push_back({tr("%1 ms frame").arg(1e3 * dt, 0, 'f', 1),
                              {c.x.front(), c.x.back()},
                              {1e3 * dt, 1e3 * dt},
                              QColor(120, 120, 120)});
        m_costPlot->setSeries(std::move(series));
        QString note = tr("last %1 ms").arg(s.stepMs, 0, 'f', 1);
        if (m_realTime.frames > 0)
            note += tr(", mean %1 ms: ×%2 real time%3")
                        .arg(m_realTime.meanMs, 0, 'f', 1)
                        .arg(m_realTime.factor, 0, 'f', 2)
                        .arg(m_realTime.slower() ? tr(" — TOO SLOW") : QString());
        m_costPlot->setNote(note);
    }
    QString verdict = s.verdict;
    if (!s.error.isEmpty()) verdict += (verdict.isEmpty() ? "" : "\n") + s.error;
    if (verdict != m_verdict->text()) {
        m_verdict->setText(verdict);
        m_verdict->setStyleSheet(s.verdictOk && s.error.isEmpty() ? "color: #106010" : "color: #b00020");
    }
    const int sampled = s.accuracy ? s.accuracy->frame : -1;
    if (s.accuracy && sampled != m_shownSample) {
        m_shownSample = sampled;
        std::vector<PlotWidget::Series> series{
            {tr("XPBD, current settings"), s.accuracy->timeMs, s.accuracy->relError, QColor(200, 60, 40)}};
        if (s.accuracyNewton)
            series.push_back(
                {tr("Newton (reference)"), s.accuracyNewton->timeMs, s.accuracyNewton->relError, QColor(40, 90, 200)});
        m_errorPlot->setSeries(std::move(series));
        m_errorPlot->setNote(tr("frame %1 of %2: %3 iterations of its first substep, one point each")
                                 .arg(s.accuracy->frame)
                                 .arg(s.accuracyOf)
                                 .arg(s.accuracy->iterations.empty() ? 0 : s.accuracy->iterations.back()));
    }
}

} // namespace viscera::studio
