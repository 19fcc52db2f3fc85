#pragma once
/// The studio's main window: the project tree (bodies, surfaces, materials, instruments, render
/// settings, solver), properties, the curve-based material editor, log and plots around the 3D
/// viewport. Every dock and toolbar has an object name, so the layout is saved and restored
/// (QSettings "Viscera/Studio"); up to kMaxRecent recent projects; New / Open / Save / Save As of
/// a project folder (atomic writes); the title marks unsaved changes from the undo stack's clean
/// state; File → Export case… runs the export with progress and Cancel.
#include "app/document.hpp"
#include "app/paint_overlays.hpp"
#include "app/preview.hpp"
#include "app/sample_compare.hpp"
#include "app/sample_painter.hpp"
#include "app/stiffness_painter.hpp"
#include "app/viewport.hpp"

#include <QMainWindow>
#include <QStringList>

#include <functional>
#include <memory>
#include <optional>

class QCheckBox;
class QComboBox;
class QDockWidget;
class QSlider;
class QLabel;
class QLineEdit;
class QMenu;
class QPlainTextEdit;
class QProgressDialog;
class QTimer;
class QTreeWidget;
class QTreeWidgetItem;
class QFormLayout;

namespace viscera::studio {

class ExportRunner;
class MaterialPanel;
class PlotWidget;
class TexturePanel;

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    static constexpr int kMaxRecent = 5;

    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    /// Opens a project folder; on failure the message (file, field, rule) goes to the log and
    /// the status bar and false is returned (the open project stays).
    bool openProject(const QString& folder);
    bool saveProject();
    bool saveProjectAs(const QString& folder);
    bool newProject(const QString& folder);
    /// Starts File → Export case… to `out` (no file dialog). False with the reason logged.
    bool startExport(const QString& out);

    /// Selects the body (tree, material editor, viewport highlight). -1: none.
    void selectBody(int index);
    /// Selects fascia surface `index` (-1: none), as a click on it in the project tree; the
    /// stiffness paint tool then paints its vertices.
    void selectSurface(int index);
    int selectedBody() const { return m_body; }
    /// Sets a property field of the selection as if typed (name as the field's object name,
    /// e.g. "youngs_modulus"). Returns the error shown, empty when accepted.
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
    StiffnessPainter* painter() { return &m_painter; }
    /// Paint stiffness mode (the toolbar's Paint action): the viewport's left drag paints the
    /// selected body's node weights, shown as a colour ramp.
    void setPainting(bool on);
    bool painting() const;
    SamplePainter* samplePainter() { return &m_samplePainter; }
    /// Light samples mode (the toolbar's Light samples action, L): the viewport's left drag paints
    /// the selected body's light-sample classes (or fills a region), shown in the class colours.
    void setPaintingSamples(bool on);
    bool paintingSamples() const;
    /// Opens the side-by-side render of uniform 1× and the painted map for the current scene.
    SampleCompareDialog* openSampleCompare();
    QTreeWidget* tree() { return m_tree; }
    PlotWidget* errorPlot() { return m_errorPlot; }
    PlotWidget* costPlot() { return m_costPlot; }
    const RealTimeEstimate& realTime() const { return m_realTime; }
    QLabel* verdictLabel() { return m_verdict; }
    QLabel* propertyError() { return m_propertyError; }
    QPlainTextEdit* log() { return m_log; }
    ExportRunner* exportRunner() { return m_export.get(); }
    QProgressDialog* exportProgress() { return m_progress; }
    QComboBox* previewMode() { return m_previewMode; }
    QStringList recentProjects() const;
    /// Ask before discarding unsaved changes (off in tests).
    void setConfirmDiscard(bool on) { m_confirm = on; }
    /// The last model handed to the preview: its serial and the frames completed then.
    std::pair<uint64_t, uint64_t> lastPreviewSubmit() const { return m_lastSubmit; }
    /// Applies the preview's latest frame to the viewport and the plots (a 60 Hz timer calls it).
    void pollPreview();

protected:
    void closeEvent(QCloseEvent*) override;

private:
    void buildActions();
    void buildDocks();
    void rebuildTree();
    void rebuildProperties();
    /// Rebuilds the property fields (and the tree) on the next pass of the event loop.
    void scheduleRefresh(bool tree = true);
    /// What the tree and the property fields show (rebuilt only when it changes).
    QString treeKey() const;
    QString propertiesKey() const;
    void onDocumentChanged();
    void updateTitle();
    void addRecent(const QString& folder);
    void rebuildRecentMenu();
    bool maybeDiscard();
    void logLine(const QString& line);
    void submitPreview();

    Document m_doc;
    Preview m_preview;
    std::unique_ptr<ExportRunner> m_export;
    Viewport* m_viewport = nullptr;
    QAction* m_widgetHostAction = nullptr;
    QAction* m_paintAction = nullptr;
    QAction* m_frameAction = nullptr;
    bool m_adjustStarted = false;
    double m_adjustRadius = 0, m_adjustStrength = 0;
    StiffnessPainter m_painter{&m_doc};
    QLabel* m_paintStatus = nullptr;
    QCheckBox *m_paintSkeleton = nullptr, *m_paintCut = nullptr;
    QComboBox* m_paintCutAxis = nullptr;
    QSlider* m_paintCutAt = nullptr;
    void buildPaintDock();
    void connectPainting(Viewport* v);
    /// The painter's weights as an overlay on the painted body's render meshes (none when off).
    void showPaintWeights();
    void retargetPainter();
    /// Makes tree item (kind, index) current without acting on the change.
    void followInTree(int kind, int index);
    SamplePainter m_samplePainter{&m_doc};
    QAction* m_samplesAction = nullptr;
    QLabel *m_sampleStatus = nullptr, *m_sampleLegend = nullptr;
    SampleCompareDialog* m_compare = nullptr;
    void buildSampleDock();
    /// `host` in a scrolling dock tabbed beside the properties, hidden until its tool starts.
    QDockWidget* addToolDock(QWidget* host, const QString& title, const char* name);
    /// Turns the paint tool of `action` (stiffness or light samples) on or off; the other goes off.
    void setPaintTool(QAction* action, bool on);
    /// The sample painter's classes as an overlay on the painted body (none when off).
    void showSampleClasses();
    /// The painted body at rest, alone, with `rgbaOfNode` colouring its render meshes (null: the
    /// paint view is off and every mesh is shown as it is).
    void showPaintedBody(render::RenderMesh::Source source, int index,
                         const std::function<Eigen::Vector4f(int32_t node)>& rgbaOfNode,
                         const std::optional<CutPlane>& cut, bool translucent = false);
    MaterialPanel* m_material = nullptr;
    TexturePanel* m_texture = nullptr;
    QTreeWidget* m_tree = nullptr;
    QWidget* m_propertiesHost = nullptr;
    QFormLayout* m_properties = nullptr;
    QLabel* m_propertyError = nullptr;
    QPlainTextEdit* m_log = nullptr;
    PlotWidget *m_errorPlot = nullptr, *m_costPlot = nullptr;
    RealTimeEstimate m_realTime; ///< of the preview's last frames (the cost plot's note, the export warning)
    QLabel* m_verdict = nullptr;
    QComboBox* m_previewMode = nullptr;
    QMenu* m_recentMenu = nullptr;
    QProgressDialog* m_progress = nullptr;
    QTimer* m_poll = nullptr;
    int m_body = -1;
    uint64_t m_shownScene = 0, m_shownFrames = 0, m_shownRevision = ~uint64_t(0);
    int m_shownSample = -2; ///< frame of the error sample on the plot
    std::pair<uint64_t, uint64_t> m_lastSubmit{0, 0};
    bool m_confirm = true;
    bool m_rebuilding = false;
    bool m_refreshPending = false, m_treePending = false, m_forceRefresh = false;
    QString m_treeKey, m_propertiesKey;
    int m_selKind = 0, m_selIndex = -1; ///< the tree's selection (ItemKind, index)
};

} // namespace viscera::studio
