#pragma once
/// The studio's two paint tools and their docks: stiffness paint (a body's node weights through
/// its curve skeleton, or a fascia's vertices by polygon) and light samples (a body's area-light
/// sample classes). Owns the painters, the checkable tool actions (one tool at a time), the
/// docks tabbed beside the properties, and the viewport's paint overlays; the painters paint
/// what the one Selection names.
#include "app/document.hpp"
#include "app/paint_overlays.hpp"
#include "app/preview.hpp"
#include "app/sample_compare.hpp"
#include "app/sample_painter.hpp"
#include "app/selection.hpp"
#include "app/stiffness_painter.hpp"

#include <QObject>

#include <functional>
#include <optional>

class QAction;
class QCheckBox;
class QComboBox;
class QDockWidget;
class QLabel;
class QMainWindow;
class QMenu;
class QSlider;

namespace viscera::studio {

class Viewport;

class PaintTools : public QObject {
    Q_OBJECT
public:
    /// Makes the actions (added to `menu`) and the docks of `window`.
    PaintTools(QMainWindow* window, Document* doc, Preview* preview, Selection* selection, QMenu* menu);

    QAction* stiffnessAction() { return m_paintAction; }
    QAction* samplesAction() { return m_samplesAction; }
    StiffnessPainter* painter() { return &m_painter; }
    SamplePainter* samplePainter() { return &m_samplePainter; }
    bool painting() const;
    bool paintingSamples() const;
    /// Turns the paint tool of `action` (stiffness or light samples) on or off; the other goes off.
    void setPaintTool(QAction* action, bool on);
    /// The viewport the tools paint in (null while it is being replaced): its paint signals are
    /// connected and the overlays drawn there.
    void connectViewport(Viewport* v);
    /// The painters follow the selection and the preview's meshes.
    void retarget();
    /// The active tool's overlay (weights or classes) on the painted body (none when off).
    void showOverlay();
    /// Opens the side-by-side render of uniform 1× and the painted map for the current scene.
    SampleCompareDialog* openSampleCompare();

signals:
    /// A paint tool went on or off (`any`: one is on).
    void toolChanged(bool any);
    void logMessage(const QString& line);

private:
    QAction* makeTool(QMenu* menu, const QString& text, const char* name, Qt::Key key, const QString& tip);
    void buildPaintDock();
    void buildSampleDock();
    /// `host` in a scrolling dock tabbed beside the properties, hidden until its tool starts.
    QDockWidget* addToolDock(QWidget* host, const QString& title, const char* name);
    void showSampleClasses();
    /// The authoring meshes (skeleton, section) and the brush outline where the cursor is.
    void pushAuthoring();
    /// The brush outline where the cursor is (hidden off the surface and for a fill).
    render::RenderMesh brushRing();
    /// The cursor moved: the outline alone is updated.
    void moveRing();
    /// The painted body at rest, alone, with `rgbaOfNode` colouring its render meshes (null: the
    /// paint view is off and every mesh is shown as it is).
    void showPaintedBody(render::RenderMesh::Source source, int index,
                         const std::function<Eigen::Vector4f(int32_t node)>& rgbaOfNode,
                         const std::optional<CutPlane>& cut, bool translucent = false);

    QMainWindow* m_window;
    Document* m_doc;
    Preview* m_preview;
    Selection* m_sel;
    Viewport* m_viewport = nullptr;
    StiffnessPainter m_painter;
    SamplePainter m_samplePainter;
    QAction *m_paintAction = nullptr, *m_samplesAction = nullptr;
    bool m_adjustStarted = false;
    double m_adjustRadius = 0, m_adjustStrength = 0;
    QLabel* m_paintStatus = nullptr;
    QCheckBox *m_paintSkeleton = nullptr, *m_paintCut = nullptr;
    QComboBox* m_paintCutAxis = nullptr;
    QSlider* m_paintCutAt = nullptr;
    QLabel *m_sampleStatus = nullptr, *m_sampleLegend = nullptr;
    SampleCompareDialog* m_compare = nullptr;
    std::vector<render::RenderMesh> m_extra; ///< skeleton and section meshes
    std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>
        m_hover; ///< the surface point under the cursor and its normal
    std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> m_lastHover; ///< where the hidden ring stays
};

} // namespace viscera::studio
