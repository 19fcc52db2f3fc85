#pragma once
/// The studio's main window: a thin shell that assembles the panels around the 3D viewport — the
/// project tree, properties, the curve-based material editor, material maps, the paint tools, log
/// and the preview's plots — and owns the one model (Document), the one Selection and the live
/// Preview. Every dock and toolbar has an object name, so the layout is saved and restored
/// (QSettings "Viscera/Studio"); up to kMaxRecent recent projects; New / Open / Save / Save As of
/// a project folder (atomic writes); the title marks unsaved changes from the undo stack's clean
/// state; File → Export case… runs the export with progress and Cancel.
#include "app/document.hpp"
#include "app/paint_tools.hpp"
#include "app/preview.hpp"
#include "app/preview_panel.hpp"
#include "app/project_tree_panel.hpp"
#include "app/properties_panel.hpp"
#include "app/selection.hpp"
#include "app/viewport.hpp"

#include <QMainWindow>
#include <QMessageBox>
#include <QPointer>
#include <QStringList>

#include <memory>

class QComboBox;
class QLabel;
class QMenu;
class QPlainTextEdit;
class QProgressDialog;
class QStackedWidget;
class QTimer;
class QTreeWidget;

class QDockWidget;
namespace viscera::studio {

class AnatomySteps;
class PortTool;
class TargetTool;
class HoldTool;
class TetImport;
class InstrumentPanel;
class ErrorBanner;
class ExportRunner;
class MaterialPanel;
class PlotWidget;
class StartPage;
class TexturePanel;
class AssessmentPanel;
class RehearsePanel;

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    static constexpr int kMaxRecent = 5;

    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    /// Opens a project folder; on failure the message (file, field, rule) is shown (showError)
    /// and false is returned (the open project stays).
    bool openProject(const QString& folder);
    bool saveProject();
    bool saveProjectAs(const QString& folder);
    bool newProject(const QString& folder);
    /// How File → Export case… signs: with the publisher key (the one `viscera-studio export`
    /// uses by default, studio::defaultPublisherKey), or unsigned because the user chose so.
    enum class Signing { PublisherKey, Unsigned };
    /// Starts File → Export case… to `out` (no file dialog). False with the reason shown. With
    /// Signing::PublisherKey and no key, nothing starts: unsignedExportBox() says why and offers
    /// to make a key (as `viscera-studio keygen`) and sign, or to export unsigned.
    bool startExport(const QString& out, Signing signing = Signing::PublisherKey);
    /// The open "no publisher key" question (null when none).
    QMessageBox* unsignedExportBox() const { return m_unsignedBox; }

    /// An error of an action: the log, the status bar and the banner over the viewport.
    void showError(const QString& line);
    ErrorBanner* errorBanner() { return m_banner; }

    /// Selects the body (tree, material editor, viewport highlight). -1: none.
    void selectBody(int index);
    /// Selects fascia surface `index` (-1: none), as a click on it in the project tree; the
    /// stiffness paint tool then paints its vertices.
    void selectSurface(int index);
    int selectedBody() const { return m_sel.body(); }
    Selection* selection() { return &m_sel; }
    /// Sets a property field of the selection as if typed (PropertiesPanel::setProperty).
    QString setProperty(const QString& field, const QString& text);

    Document* document() { return &m_doc; }
    Preview* preview() { return &m_preview; }
    Viewport* viewport() { return m_viewport; }
    /// Replaces the viewport by one on `host` showing the same scene, selection and look (View
    /// menu; saved in the settings as "viewport/host").
    void setViewportHost(ViewportHost host);
    MaterialPanel* materialPanel() { return m_material; }
    /// The "Material maps" dock's panel: the selection's texture block, thumbnails, palette picker.
    TexturePanel* texturePanel() { return m_texture; }
    AssessmentPanel* assessmentPanel() { return m_assessment; }
    PropertiesPanel* propertiesPanel() { return m_properties; }
    ProjectTreePanel* projectTree() { return m_tree; }
    /// Shown instead of the viewport while no project is open.
    StartPage* startPage() { return m_start; }
    /// The start page or the viewport, whichever is shown.
    QWidget* centreWidget() const;
    PaintTools* paintTools() { return m_paint; }
    /// Placing trocar ports in the viewport (port_tool.hpp).
    PortTool* portTool() { return m_portTool; }
    TargetTool* targetTool() { return m_targetTool; }
    HoldTool* holdTool() { return m_holdTool; }
    RehearsePanel* rehearsePanel() { return m_rehearse; }
    TetImport* tetImport() { return m_tetImport; }
    AnatomySteps* anatomySteps() { return m_anatomy; }
    StiffnessPainter* painter() { return m_paint->painter(); }
    /// Paint stiffness mode (the toolbar's Paint action): the viewport's left drag paints the
    /// selected body's node weights, shown as a colour ramp.
    void setPainting(bool on) { m_paint->setPaintTool(m_paint->stiffnessAction(), on); }
    bool painting() const { return m_paint->painting(); }
    SamplePainter* samplePainter() { return m_paint->samplePainter(); }
    /// Light samples mode (the toolbar's Light samples action, L): the viewport's left drag paints
    /// the selected body's light-sample classes (or fills a region), shown in the class colours.
    void setPaintingSamples(bool on) { m_paint->setPaintTool(m_paint->samplesAction(), on); }
    bool paintingSamples() const { return m_paint->paintingSamples(); }
    /// Opens the side-by-side render of uniform 1× and the painted map for the current scene.
    SampleCompareDialog* openSampleCompare() { return m_paint->openSampleCompare(); }
    QTreeWidget* tree() { return m_tree; }
    PlotWidget* errorPlot() { return m_previewPanel->errorPlot(); }
    PlotWidget* costPlot() { return m_previewPanel->costPlot(); }
    const RealTimeEstimate& realTime() const { return m_previewPanel->realTime(); }
    QLabel* verdictLabel() { return m_previewPanel->verdictLabel(); }
    QLabel* propertyError() { return m_properties->errorLabel(); }
    QPlainTextEdit* log() { return m_log; }
    ExportRunner* exportRunner() { return m_export.get(); }
    QProgressDialog* exportProgress() { return m_progress; }
    QComboBox* previewMode() { return m_previewPanel->modeBox(); }
    QStringList recentProjects() const;
    /// Ask before discarding unsaved changes (off in tests).
    void setConfirmDiscard(bool on) { m_confirm = on; }
    /// The last model handed to the preview: its serial and the frames completed then.
    std::pair<uint64_t, uint64_t> lastPreviewSubmit() const { return m_lastSubmit; }
    /// Applies the preview's latest frame to the viewport and the plots (a 60 Hz timer calls it).
    void pollPreview();
    /// A rehearsal took the viewport (on) or gave it back.
    void onRehearsing(bool on);

protected:
    void closeEvent(QCloseEvent*) override;

private:
    void buildActions();
    void buildDocks();
    /// The port tool's current port follows the Instruments dock's selection and the Laparoscope dock.
    /// `tool` (the paint tools, the port tool or the target tool) took the viewport's clicks: the others go off.
    void viewportToolOn(QObject* tool);
    void followPortDocks();
    void buildFileMenu(QMenu* file, QToolBar* toolbar);
    void buildViewMenu(QMenu* view, QToolBar* toolbar);
    void onDocumentChanged(const Change& what);
    void onSelectionChanged();
    void updateTitle();
    void addRecent(const QString& folder);
    void askNewProject();  ///< asks for a folder, then newProject()
    void askOpenProject(); ///< asks for a folder, then openProject()
    void rebuildRecentMenu();
    bool maybeDiscard();
    void logLine(const QString& line);
    void submitPreview(Change what = Change::everything());
    void connectExport();
    void askUnsignedExport(const QString& out, const QString& keyFile);
    void makeKeyAndExport(const QString& out);

    Document m_doc;
    Selection m_sel;
    Preview m_preview;
    std::unique_ptr<ExportRunner> m_export;
    AnatomySteps* m_anatomy = nullptr;
    Viewport* m_viewport = nullptr;
    QAction* m_widgetHostAction = nullptr;
    QAction* m_frameAction = nullptr;
    QAction* m_lookAction = nullptr;
    QStackedWidget* m_centre = nullptr; ///< the start page, or the viewport once a project is open
    StartPage* m_start = nullptr;
    PaintTools* m_paint = nullptr;
    PortTool* m_portTool = nullptr;
    TetImport* m_tetImport = nullptr;
    HoldTool* m_holdTool = nullptr;      ///< [issue 57 item 4] where a body is held, drawn
    TargetTool* m_targetTool = nullptr;  ///< [issue 57 item 2] the assessment's targets, drawn
    RehearsePanel* m_rehearse = nullptr; ///< [issue 57 item 3] the case run in the viewport
    bool m_rehearsing = false, m_previewWasPaused = false;
    InstrumentPanel* m_instruments = nullptr;
    QDockWidget* m_instrumentDock = nullptr;
    QDockWidget* m_scopeTaskDock = nullptr;
    bool m_instrumentInView = false, m_scopeInView = false; ///< their tabs in front (followPortDocks)
    MaterialPanel* m_material = nullptr;
    TexturePanel* m_texture = nullptr;
    AssessmentPanel* m_assessment = nullptr;
    ProjectTreePanel* m_tree = nullptr;
    PropertiesPanel* m_properties = nullptr;
    PreviewPanel* m_previewPanel = nullptr;
    QPlainTextEdit* m_log = nullptr;
    QMenu* m_recentMenu = nullptr;
    QProgressDialog* m_progress = nullptr;
    ErrorBanner* m_banner = nullptr;
    QPointer<QMessageBox> m_unsignedBox;
    QTimer* m_poll = nullptr;
    uint64_t m_shownScene = 0, m_shownFrames = 0, m_shownRevision = ~uint64_t(0);
    std::pair<uint64_t, uint64_t> m_lastSubmit{0, 0};
    bool m_confirm = true;
};

} // namespace viscera::studio
