#include "app/main_window.hpp"

#include "app/anatomy_steps.hpp"
#include "app/assessment_panel.hpp"
#include "app/error_banner.hpp"
#include "app/export_runner.hpp"
#include "app/fit_dialog.hpp"
#include "app/hold_tool.hpp"
#include "app/instrument_panel.hpp"
#include "app/material_panel.hpp"
#include "app/number_text.hpp"
#include "app/port_tool.hpp"
#include "app/project_tree_panel.hpp"
#include "app/properties_panel.hpp"
#include "app/rehearsal.hpp"
#include "app/rehearse_panel.hpp"
#include "app/scope_task_panel.hpp"
#include "app/start_page.hpp"
#include "app/surroundings_panel.hpp"
#include "app/target_tool.hpp"
#include "app/tet_import.hpp"
#include "app/texture_panel.hpp"
#include "app/wheel_guard.hpp"
#include "project/publishing.hpp"

#include <QAction>
#include <QCloseEvent>
#include <QDateTime>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QProgressDialog>
#include <QPushButton>
#include <QRegularExpression>
#include <QScrollArea>
#include <QSettings>
#include <QStackedWidget>
#include <QStatusBar>
#include <QTimer>
#include <QToolBar>
#include <QVBoxLayout>

namespace viscera::studio {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), m_export(std::make_unique<ExportRunner>()) {
    setObjectName("studioMainWindow");
    WheelGuard::install(); // the wheel scrolls docks; it never edits an unfocused field
    setDockNestingEnabled(true);
    buildDocks();
    buildActions();
    // the centre: the start page until a project is open, then the viewport
    auto* centre = new QWidget(this);
    auto* column = new QVBoxLayout(centre);
    column->setContentsMargins(0, 0, 0, 0);
    column->setSpacing(2);
    m_banner = new ErrorBanner(centre); // an action's error, where the user looks
    column->addWidget(m_banner);
    m_centre = new QStackedWidget(centre);
    m_start = new StartPage(m_centre);
    m_centre->addWidget(m_start);
    column->addWidget(m_centre, 1);
    setCentralWidget(centre);
    connect(m_start, &StartPage::newRequested, this, &MainWindow::askNewProject);
    connect(m_start, &StartPage::openRequested, this, &MainWindow::askOpenProject);
    connect(m_start, &StartPage::openRecent, this, [this](const QString& f) { openProject(f); });
    setViewportHost(viewportHostFromText(QSettings().value("viewport/host").toString()).value_or(ViewportHost::Window));
    statusBar()->showMessage(tr("Open or create a project (File menu)"));
    connect(&m_doc, &Document::changed, this, &MainWindow::onDocumentChanged);
    connect(&m_doc, &Document::logMessage, this, &MainWindow::logLine);
    connect(&m_sel, &Selection::changed, this, &MainWindow::onSelectionChanged);
    connect(&m_preview, &Preview::logMessage, this, &MainWindow::logLine, Qt::QueuedConnection);
    connect(m_doc.undoStack(), &QUndoStack::cleanChanged, this, &MainWindow::updateTitle);
    connect(m_properties, &PropertiesPanel::logMessage, this, &MainWindow::logLine);
    connect(m_paint, &PaintTools::logMessage, this, &MainWindow::logLine);
    connect(m_paint, &PaintTools::toolChanged, this, [this](bool any) {
        // in paint mode F and Shift+F size the brush (the viewport's own keys); Home still frames
        m_frameAction->setShortcut(any ? QKeySequence(Qt::Key_Home) : QKeySequence(Qt::Key_F));
    });
    connect(m_previewPanel, &PreviewPanel::modeChanged, this, [this] { submitPreview(); });
    connect(m_material, &MaterialPanel::fitRequested, this, [this](int body) {
        FitDialog dlg(&m_doc, body, this);
        dlg.exec();
    });
    connectExport();
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
    if (m_rehearse) m_rehearse->disconnect(this); // a session ending now reports to no one
    // the docks hide as the children go: nothing may follow them into tools already deleted
    for (QDockWidget* d : findChildren<QDockWidget*>())
        d->disconnect();
}

QWidget* MainWindow::centreWidget() const {
    return m_centre->currentWidget();
}

void MainWindow::connectExport() {
    connect(m_export.get(), &ExportRunner::progress, this, [this](int done, int total, const QString& stage) {
        if (!m_progress) return;
        m_progress->setMaximum(total);
        m_progress->setValue(done);
        m_progress->setLabelText(tr("Exporting: %1").arg(stage));
    });
    connect(m_export.get(), &ExportRunner::finished, this, [this](bool ok, const QString& message) {
        if (ok || message == tr("cancelled")) {
            logLine(message);
            statusBar()->showMessage(message);
            const std::vector<std::string>& warnings = ok ? m_export->result().warnings : std::vector<std::string>{};
            for (const std::string& w : warnings)
                logLine(tr("warning: %1").arg(QString::fromStdString(w)));
            // a port that cannot reach its targets is worth more than a log line: the strip shows the first
            if (!warnings.empty())
                m_banner->showError(tr("%1 — %n warning(s), the first: %2", "", int(warnings.size()))
                                        .arg(message, QString::fromStdString(warnings.front())));
        } else {
            showError(message);
        }
        if (m_progress) {
            m_progress->reset();
            m_progress->hide();
        }
    });
}

void MainWindow::followPortDocks() {
    // The current port is the one of the dock in view: the selected instrument, or the
    // laparoscope; neither dock in view (another tab in front) and no port being placed: none, no
    // workspace drawn. A tabbed dock behind another stays isVisible(): its visibilityChanged says.
    connect(m_instruments, &InstrumentPanel::selectedChanged, this, [this](int i) {
        if (m_instrumentInView) m_portTool->setCurrent(i < 0 ? PortTool::kNoPort : i);
    });
    connect(m_instrumentDock, &QDockWidget::visibilityChanged, this, [this](bool on) {
        m_instrumentInView = on;
        if (on) m_portTool->setCurrent(m_instruments->selected() < 0 ? PortTool::kNoPort : m_instruments->selected());
    });
    connect(m_scopeTaskDock, &QDockWidget::visibilityChanged, this, [this](bool on) {
        m_scopeInView = on;
        if (on) m_portTool->setCurrent(PortTool::kScopePort);
    });
    // a laparoscope added (or removed) while its dock is in view: its port is (no longer) current
    connect(&m_doc, &Document::changed, this, [this](const Change& what) {
        if (!m_scopeInView || !what.touches(Change::Scene) || !m_doc.hasProject()) return;
        const bool scope = m_doc.project().scene.laparoscope.has_value();
        if (scope != (m_portTool->current() == PortTool::kScopePort))
            m_portTool->setCurrent(scope ? PortTool::kScopePort : PortTool::kNoPort);
    });
    for (QDockWidget* d : {m_instrumentDock, m_scopeTaskDock})
        connect(d, &QDockWidget::visibilityChanged, this, [this](bool on) {
            if (!on && !m_instrumentInView && !m_scopeInView && !m_portTool->action()->isChecked())
                m_portTool->setCurrent(PortTool::kNoPort);
        });
}

void MainWindow::viewportToolOn(QObject* tool) {
    // one tool at a time takes the viewport's clicks: the others go off
    if (tool != m_paint) {
        m_paint->setPaintTool(m_paint->stiffnessAction(), false);
        m_paint->setPaintTool(m_paint->samplesAction(), false);
    }
    if (tool != m_portTool) m_portTool->action()->setChecked(false);
    if (tool != m_holdTool) m_holdTool->action()->setChecked(false);
    if (tool != m_targetTool && m_targetTool->pick() != TargetTool::Pick::None)
        m_targetTool->action(m_targetTool->pick())->setChecked(false);
    // a tool going off sets the paint mode off: the one that came on (the paint tools set it
    // before they say so) takes the clicks again
    if (m_viewport) m_viewport->setPaintMode(true);
}

void MainWindow::buildDocks() {
    auto dock = [this](const QString& name, const QString& title, QWidget* w, Qt::DockWidgetArea area) {
        auto* d = new QDockWidget(title, this);
        d->setObjectName(name);
        d->setWidget(w);
        addDockWidget(area, d);
        return d;
    };
    m_tree = new ProjectTreePanel(&m_doc, &m_sel, this);
    connect(m_tree, &ProjectTreePanel::refused, this, &MainWindow::showError); // rename / delete body
    dock("projectDock", tr("Project"), m_tree, Qt::LeftDockWidgetArea);
    m_material = new MaterialPanel(&m_doc, this);
    m_material->setObjectName("materialPanel");
    m_properties = new PropertiesPanel(&m_doc, &m_sel, m_material, this);
    m_holdTool = new HoldTool(&m_doc, this); // [issue 57 item 4] a body's holds, drawn on it
    m_properties->setHoldTool(m_holdTool);
    dock("propertiesDock", tr("Properties"), m_properties, Qt::LeftDockWidgetArea);
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

    m_previewPanel = new PreviewPanel(&m_preview, this);
    QDockWidget* plotsDock = dock("plotsDock", tr("Preview and plots"), m_previewPanel, Qt::RightDockWidgetArea);
    // a tab beside the plots, which stay in front: the panel needs the column's height
    tabifyDockWidget(plotsDock, dock("textureDock", tr("Material maps"), textureScroll, Qt::RightDockWidgetArea));
    m_targetTool = new TargetTool(&m_doc, this); // [issue 57 item 2] the targets drawn on the anatomy
    m_assessment = new AssessmentPanel(&m_doc, m_targetTool, this);
    m_assessment->setObjectName("assessmentPanel");
    QDockWidget* assessmentDock = dock("assessmentDock", tr("Assessment"), m_assessment, Qt::RightDockWidgetArea);
    tabifyDockWidget(plotsDock, assessmentDock);
    connect(assessmentDock, &QDockWidget::visibilityChanged, m_targetTool, &TargetTool::setShown);
    auto* scopeTask = new ScopeTaskPanel(
        &m_doc, [this] { return m_viewport; }, this); // [issue 57]: the scope and the task
    scopeTask->setObjectName("scopeTaskPanel");
    auto* scopeTaskScroll = new QScrollArea(this); // a short dock scrolls instead of clipping the fields
    scopeTaskScroll->setWidget(scopeTask);
    scopeTaskScroll->setWidgetResizable(true);
    m_scopeTaskDock = dock("scopeTaskDock", tr("Laparoscope and task"), scopeTaskScroll, Qt::RightDockWidgetArea);
    tabifyDockWidget(plotsDock, m_scopeTaskDock);
    auto* surroundings = new SurroundingsPanel(&m_doc, this); // [issue 57]: the static anatomy around
    surroundings->setObjectName("surroundingsPanel");
    auto* surroundingsScroll = new QScrollArea(this);
    surroundingsScroll->setWidget(surroundings);
    surroundingsScroll->setWidgetResizable(true);
    tabifyDockWidget(plotsDock,
                     dock("surroundingsDock", tr("Surroundings"), surroundingsScroll, Qt::RightDockWidgetArea));
    // a surrounding's maps are the Material maps dock's, as a body's are
    connect(surroundings, &SurroundingsPanel::selectedChanged, this, [this](int k) {
        if (k >= 0) m_texture->setTarget(TexturePanel::Target::Scenery, k);
    });
    connect(surroundings, &SurroundingsPanel::mapsRequested, this, [this](int k) {
        m_texture->setTarget(TexturePanel::Target::Scenery, k);
        if (auto* d = findChild<QDockWidget*>("textureDock")) d->raise();
    });
    auto* instruments = new InstrumentPanel(&m_doc, this); // [issue 57]: the scene's instruments
    instruments->setObjectName("instrumentPanel");
    auto* instrumentScroll = new QScrollArea(this); // a short dock scrolls instead of clipping the fields
    instrumentScroll->setWidget(instruments);
    instrumentScroll->setWidgetResizable(true);
    m_instruments = instruments;
    m_instrumentDock = dock("instrumentDock", tr("Instruments"), instrumentScroll, Qt::RightDockWidgetArea);
    tabifyDockWidget(plotsDock, m_instrumentDock);
    m_rehearse = new RehearsePanel(&m_doc, this); // [issue 57 item 3] the case run as the player runs it
    m_rehearse->setObjectName("rehearsePanel");
    auto* rehearseScroll = new QScrollArea(this); // a short dock scrolls instead of clipping the verdict
    rehearseScroll->setWidget(m_rehearse);
    rehearseScroll->setWidgetResizable(true);
    tabifyDockWidget(plotsDock, dock("rehearseDock", tr("Rehearse"), rehearseScroll, Qt::RightDockWidgetArea));
    connect(m_rehearse, &RehearsePanel::refused, this, &MainWindow::showError);
    connect(m_rehearse, &RehearsePanel::activeChanged, this, &MainWindow::onRehearsing);
    plotsDock->raise();
}

void MainWindow::buildActions() {
    auto* toolbar = addToolBar(tr("Main"));
    toolbar->setObjectName("mainToolBar");
    m_anatomy = new AnatomySteps(&m_doc, &m_sel, this);
    connect(m_anatomy, &AnatomySteps::logMessage, this, &MainWindow::logLine);
    connect(m_anatomy, &AnatomySteps::failed, this, [this](const QString& line) {
        m_banner->showError(line); // the log has it already
        statusBar()->showMessage(line);
    });
    m_tetImport = new TetImport(&m_doc, &m_sel, this); // [issue 57 item 7] .msh / .vtu as tet bodies
    connect(m_tetImport, &TetImport::logMessage, this, &MainWindow::logLine);
    connect(m_tetImport, &TetImport::failed, this, &MainWindow::showError);
    buildFileMenu(menuBar()->addMenu(tr("&File")), toolbar);
    m_anatomy->buildMenu(menuBar()->addMenu(tr("&Mesh")));
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
    buildViewMenu(menuBar()->addMenu(tr("&View")), toolbar);
}

void MainWindow::buildFileMenu(QMenu* file, QToolBar* toolbar) {
    auto add = [&](const QString& text, QKeySequence key, auto fn, bool onToolbar) {
        QAction* a = file->addAction(text);
        a->setShortcut(key);
        QString name = "action"; // "&Export case…" → "actionExportCase"
        for (const QString& word : QString(text).remove('&').remove(QChar(0x2026)).split(' ', Qt::SkipEmptyParts))
            name += word.left(1).toUpper() + word.mid(1);
        a->setObjectName(name);
        connect(a, &QAction::triggered, this, fn);
        if (onToolbar) toolbar->addAction(a);
    };
    add(
        tr("&New project…"), QKeySequence::New, [this] { askNewProject(); }, true);
    add(
        tr("&Open project…"), QKeySequence::Open, [this] { askOpenProject(); }, true);
    m_recentMenu = file->addMenu(tr("Open &recent"));
    add(
        tr("&Save"), QKeySequence::Save, [this] { saveProject(); }, true);
    add(
        tr("Save &as…"), QKeySequence::SaveAs,
        [this] {
            const QString dir = QFileDialog::getExistingDirectory(this, tr("Save the project into folder"));
            if (!dir.isEmpty()) saveProjectAs(dir);
        },
        false);
    file->addSeparator();
    file->addAction(m_anatomy->importAction());
    file->addAction(m_tetImport->action());
    add(
        tr("&Export case…"), QKeySequence(tr("Ctrl+E")),
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
    add(
        tr("&Quit"), QKeySequence::Quit, [this] { close(); }, false);
}

void MainWindow::buildViewMenu(QMenu* view, QToolBar* toolbar) {
    m_frameAction = view->addAction(tr("&Frame all"));
    m_frameAction->setShortcut(QKeySequence(Qt::Key_F));
    connect(m_frameAction, &QAction::triggered, this, [this] { m_viewport->frameAll(); });
    m_lookAction = view->addAction(tr("&Trainee's look (the case's render settings)"));
    m_lookAction->setObjectName("actionTraineeLook");
    m_lookAction->setCheckable(true);
    m_lookAction->setShortcut(QKeySequence(Qt::Key_T));
    m_lookAction->setToolTip(tr("Off: the authoring look (flat light, no post effects, a grid and the selection's "
                                "outline). On: the scene as the player shows it"));
    connect(m_lookAction, &QAction::toggled, this,
            [this](bool on) { m_viewport->setLook(on ? Viewport::Look::Trainee : Viewport::Look::Authoring); });
    // the paint tools: checkable, one at a time, each with its dock
    m_paint = new PaintTools(this, &m_doc, &m_preview, &m_sel, view);
    toolbar->addSeparator();
    toolbar->addAction(m_paint->stiffnessAction());
    toolbar->addAction(m_paint->samplesAction());
    // [issue 57] the port tool: clicks put the current port (Instruments / Laparoscope dock) on a surface
    m_portTool = new PortTool(&m_doc, this);
    view->addAction(m_portTool->action());
    toolbar->addAction(m_portTool->action());
    view->addAction(m_holdTool->action());
    toolbar->addAction(m_holdTool->action());
    view->addSeparator();
    for (auto pick : {TargetTool::Pick::CutLine, TargetTool::Pick::ClipSite, TargetTool::Pick::SuturePlane,
                      TargetTool::Pick::Vessel})
        view->addAction(m_targetTool->action(pick)); // also the Assessment dock's buttons
    connect(m_portTool, &PortTool::activeChanged, this, [this](bool on) {
        if (on) viewportToolOn(m_portTool);
    });
    connect(m_holdTool, &HoldTool::activeChanged, this, [this](bool on) {
        if (on) viewportToolOn(m_holdTool);
    });
    connect(m_holdTool, &HoldTool::refused, this, &MainWindow::showError);
    connect(m_targetTool, &TargetTool::activeChanged, this, [this](bool on) {
        if (on) viewportToolOn(m_targetTool);
    });
    connect(m_paint, &PaintTools::toolChanged, this, [this](bool any) {
        if (any) viewportToolOn(m_paint);
    });
    connect(m_portTool, &PortTool::refused, this, &MainWindow::showError);
    connect(m_targetTool, &TargetTool::refused, this, &MainWindow::showError);
    followPortDocks();
    m_widgetHostAction = view->addAction(tr("Compatibility viewport (QOpenGLWidget, slower)"));
    m_widgetHostAction->setObjectName("actionWidgetViewport");
    m_widgetHostAction->setCheckable(true);
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
        Viewport* old = m_viewport;
        m_viewport = nullptr;
        m_paint->connectViewport(nullptr);
        m_portTool->connectViewport(nullptr);
        m_holdTool->connectViewport(nullptr);
        m_targetTool->connectViewport(nullptr);
        m_rehearse->connectViewport(nullptr);
        m_centre->removeWidget(old);
        delete old;
    }
    auto* v = new Viewport(host, this);
    v->setObjectName("viewport");
    connect(v, &Viewport::bodyClicked, this, [this](const QString& name) {
        if (!m_doc.hasProject()) return;
        const auto& bodies = m_doc.project().bodies;
        for (size_t i = 0; i < bodies.size(); ++i)
            if (QString::fromStdString(bodies[i].scene.name) == name) selectBody(static_cast<int>(i));
    });
    connect(v, &Viewport::rendererFailed, this, &MainWindow::showError);
    m_paint->connectViewport(v);
    m_portTool->connectViewport(v);
    m_holdTool->connectViewport(v);
    m_targetTool->connectViewport(v);
    m_rehearse->connectViewport(v);
    m_centre->addWidget(v);
    if (m_doc.hasProject()) m_centre->setCurrentWidget(v);
    m_viewport = v;
    // the new host shows what the old one did
    if (m_doc.hasProject()) v->setCaseRender(m_doc.project().scene.render);
    if (auto view = m_preview.sceneView()) {
        v->setScene(*view);
        const Preview::Snapshot s = m_preview.snapshot();
        v->setPositions(s.bodies, s.surfaces);
    }
    v->setSelectedName(selected);
    if (m_lookAction) v->setLook(m_lookAction->isChecked() ? Viewport::Look::Trainee : Viewport::Look::Authoring);
    v->setPaintMode(painting() || paintingSamples() || m_portTool->action()->isChecked() ||
                    m_holdTool->action()->isChecked() || m_targetTool->pick() != TargetTool::Pick::None);
    m_paint->showOverlay();
    QSettings().setValue("viewport/host", viewportHostText(host));
    if (m_widgetHostAction) m_widgetHostAction->setChecked(host == ViewportHost::Widget);
}

void MainWindow::askNewProject() {
    const QString dir = QFileDialog::getExistingDirectory(this, tr("Folder of the new project"));
    if (!dir.isEmpty()) newProject(dir);
}

void MainWindow::askOpenProject() {
    const QString dir = QFileDialog::getExistingDirectory(this, tr("Project folder (with project.json)"));
    if (!dir.isEmpty()) openProject(dir);
}

QStringList MainWindow::recentProjects() const {
    return StartPage::recentProjects();
}

void MainWindow::addRecent(const QString& folder) {
    StartPage::addRecent(folder, kMaxRecent);
    rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
    m_recentMenu->clear();
    const QStringList list = recentProjects();
    m_start->setRecent(list);
    for (const QString& f : list) {
        QAction* a = m_recentMenu->addAction(f);
        connect(a, &QAction::triggered, this, [this, f] { openProject(f); });
    }
    m_recentMenu->setEnabled(!list.isEmpty());
}

void MainWindow::logLine(const QString& line) {
    m_log->appendPlainText(QDateTime::currentDateTime().toString("hh:mm:ss  ") + line);
}

void MainWindow::showError(const QString& line) {
    logLine(line);
    statusBar()->showMessage(line);
    m_banner->showError(line);
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
        showError(QString::fromStdString(e.what()));
        return false;
    }
    addRecent(m_doc.folder());
    m_viewport->frameNextScene(); // the new project's scene is shown whole
    m_sel.clear();
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
        showError(QString::fromStdString(e.what()));
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
        showError(QString::fromStdString(e.what()));
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
        showError(QString::fromStdString(e.what()));
        return false;
    }
    addRecent(m_doc.folder());
    return true;
}

bool MainWindow::startExport(const QString& out, Signing signing) {
    if (!m_doc.hasProject()) return false;
    ExportSigning how; // unsigned unless the publisher key signs
    if (signing == Signing::PublisherKey) {
        const std::optional<std::filesystem::path> key = defaultPublisherKey();
        if (!key) {
            askUnsignedExport(out, QString::fromStdString(defaultPublisherKeyPath().string()));
            return false;
        }
        try { // a key the export would refuse (unreadable, inside the project) is refused before the work
            loadPublisherKey(*key, m_doc.project().dir);
        } catch (const std::exception& e) {
            showError(QString::fromStdString(e.what()));
            return false;
        }
        how = {QString::fromStdString(key->string()), QString::fromStdString(defaultSignerName(std::nullopt))};
    }
    const RealTimeEstimate& rt = realTime();
    if (rt.slower()) { // said before the work: the trainee's session would fall behind
        const QString warning =
            tr("warning: the case runs at ×%1 of real time in the preview (%2 ms per %3 ms frame over the last %4 "
               "frames, one solver thread): a trainee's session would fall behind; fewer substeps or a coarser "
               "mesh would help")
                .arg(rt.factor, 0, 'f', 2)
                .arg(numberText(rt.meanMs))
                .arg(numberText(rt.budgetMs))
                .arg(rt.frames);
        logLine(warning);
        statusBar()->showMessage(warning);
    }
    QString why;
    if (!m_export->start(m_doc.project(), out, how, &why)) {
        showError(why);
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
    logLine(how.isUnsigned() ? tr("exporting to %1, unsigned (chosen)").arg(out)
                             : tr("exporting to %1, signed with %2").arg(out, how.keyFile));
    return true;
}

void MainWindow::askUnsignedExport(const QString& out, const QString& keyFile) {
    const QString why = QString::fromStdString(unsignedCaseWarning(keyFile.toStdString()));
    logLine(tr("Export case: %1").arg(why));
    statusBar()->showMessage(why);
    if (m_unsignedBox) m_unsignedBox->close();
    auto* box = new QMessageBox(
        QMessageBox::Warning, tr("Export case: no publisher key"),
        tr("The case cannot be signed: there is no publisher key at %1.\n\nPlayers refuse an unsigned case unless it "
           "is run with --allow-unsigned. A publisher makes one key (as `viscera-studio keygen` does), keeps it "
           "outside every project folder and gives its public half (%2) to the stations that run the cases.\n\n"
           "Make the key now and sign with it, or export this case unsigned.")
            .arg(keyFile, QString::fromStdString(publicKeyPathFor(keyFile.toStdString()).string())),
        QMessageBox::Cancel, this);
    box->setObjectName("unsignedExportBox");
    QPushButton* make = box->addButton(tr("Make a key and sign"), QMessageBox::AcceptRole);
    make->setObjectName("makeKeyAndSign");
    QPushButton* plain = box->addButton(tr("Export unsigned"), QMessageBox::DestructiveRole);
    plain->setObjectName("exportUnsigned");
    box->setDefaultButton(make);
    box->setAttribute(Qt::WA_DeleteOnClose);
    connect(box, &QMessageBox::buttonClicked, this, [this, make, plain, out](QAbstractButton* b) {
        if (b == make)
            makeKeyAndExport(out);
        else if (b == plain)
            startExport(out, Signing::Unsigned);
    });
    m_unsignedBox = box;
    box->open();
}

void MainWindow::makeKeyAndExport(const QString& out) {
    try {
        const NewPublisherKey k = makePublisherKey(defaultPublisherKeyPath());
        logLine(tr("publisher key %1 made: private %2 (mode 600: keep it outside every project folder), public %3 "
                   "(players trust it: --trust, or a copy in /etc/viscera/trusted-publishers)")
                    .arg(QString::fromStdString(k.keyId), QString::fromStdString(k.privateFile.string()),
                         QString::fromStdString(k.publicFile.string())));
    } catch (const std::exception& e) {
        showError(QString::fromStdString(e.what()));
        return;
    }
    startExport(out, Signing::PublisherKey);
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

void MainWindow::onDocumentChanged(const Change& what) {
    if (!m_doc.hasProject()) return;
    if (m_centre->currentWidget() != m_viewport) m_centre->setCurrentWidget(m_viewport); // the project's view
    // a selection the edit took away (undo of an added body) goes
    const Project& p = m_doc.project();
    if ((m_sel.body() >= static_cast<int>(p.bodies.size())) || (m_sel.surface() >= static_cast<int>(p.surfaces.size())))
        m_sel.clear();
    if (what.touches(Change::Structure)) m_viewport->setCaseRender(p.scene.render);
    m_rehearse->refreshDevices(); // a new project has other replays
    updateTitle();
    submitPreview(what);
}

void MainWindow::onSelectionChanged() {
    const int body = m_sel.body(), surface = m_sel.surface();
    m_material->setBody(body);
    m_texture->setTarget(body >= 0      ? TexturePanel::Target::Body
                         : surface >= 0 ? TexturePanel::Target::Surface
                                        : TexturePanel::Target::None,
                         body >= 0 ? body : surface);
    QString name;
    if (m_doc.hasProject() && body >= 0) name = QString::fromStdString(m_doc.project().bodies[body].scene.name);
    if (m_doc.hasProject() && surface >= 0) name = QString::fromStdString(m_doc.project().surfaces[surface].scene.name);
    m_viewport->setSelectedName(name);
    if (m_previewPanel->mode() == Preview::Mode::Specimen) submitPreview();
}

void MainWindow::submitPreview(Change what) {
    if (!m_doc.hasProject()) return;
    uint64_t frames = 0;
    const uint64_t serial =
        m_preview.submit(m_doc.project(), m_previewPanel->mode(), std::max(0, m_sel.body()), &frames, what);
    m_lastSubmit = {serial, frames};
}

void MainWindow::selectBody(int index) {
    const bool ok = m_doc.hasProject() && index >= 0 && index < static_cast<int>(m_doc.project().bodies.size());
    m_sel.set(Selection::Kind::Body, ok ? index : -1);
}

void MainWindow::selectSurface(int index) {
    const bool ok = m_doc.hasProject() && index >= 0 && index < static_cast<int>(m_doc.project().surfaces.size());
    m_sel.set(Selection::Kind::Surface, ok ? index : -1);
}

QString MainWindow::setProperty(const QString& field, const QString& text) {
    return m_properties->setProperty(field, text);
}

void MainWindow::onRehearsing(bool on) {
    if (on == m_rehearsing) return;
    m_rehearsing = on;
    if (on) {
        // the viewport shows the session; the preview rests meanwhile (the CPU is the session's)
        m_previewWasPaused = m_preview.paused();
        m_preview.setPaused(true);
        return;
    }
    m_preview.setPaused(m_previewWasPaused);
    m_shownScene = 0; // the preview's scene comes back on the next poll
    m_shownRevision = ~uint64_t(0);
    pollPreview();
}

void MainWindow::pollPreview() {
    if (m_rehearsing) return; // the viewport is the rehearsal's
    if (!m_doc.hasProject() || m_preview.revision() == m_shownRevision) return;
    m_shownRevision = m_preview.revision();
    const Preview::Snapshot s = m_preview.snapshot();
    // Only what changed is redrawn: an edit alone changes the verdict, not the positions, and a
    // repaint of the viewport or a plot is what costs on the UI thread.
    const bool newScene = s.scene != m_shownScene;
    if (newScene) {
        if (auto view = m_preview.sceneView()) m_viewport->setScene(*view);
        m_paint->retarget(); // the same mesh keeps its skeleton; a new one is mapped again
        m_paint->showOverlay();
        m_targetTool->refresh(); // the vessel's box follows the new meshes
        m_shownScene = s.scene;
    }
    const bool newFrames = newScene || s.frames != m_shownFrames;
    if (newFrames) {
        m_shownFrames = s.frames;
        m_viewport->setPositions(s.bodies, s.surfaces);
    }
    m_previewPanel->show(s, m_doc.project().scene.xpbd.dt, newFrames);
}

} // namespace viscera::studio
