#pragma once
/// The studio's 3D viewport: the preview's bodies and surfaces drawn with core/render on the
/// viewport's own OpenGL context (render::createRendererForCurrentContext: the deferred PBR
/// renderer of the player, presented into the viewport's framebuffer).
///
/// Two hosts, chosen by the user (View menu, saved in the settings):
///   - Window (default): a QWindow embedded with QWidget::createWindowContainer, drawn by a
///     render thread of its own (its own GL context, as Qt Quick's threaded render loop). The
///     UI thread only hands over a snapshot of what to draw (the scene, shared and immutable,
///     the camera, the look) and never waits for a frame: on a software renderer a frame of
///     the liver costs ~10 ms of rasterization that would otherwise stall every edit. The main
///     window also keeps Qt's raster backing store.
///   - Widget: a QOpenGLWidget painting on the UI thread. Qt then composes the whole top-level
///     window through OpenGL on every repaint of any widget in it (QOpenGLWidget's
///     documentation, "Performance considerations"): measured on the liver with Mesa llvmpipe
///     at 1600×1000, 20 ms per event-loop pass (median) against 1 ms without it
///     (bench_studio_preview). It stays for platforms where native child windows misbehave
///     (stacking under floating docks, some remote displays).
///
/// Left drag orbits about the target, middle drag (or Shift + left) pans, the wheel zooms,
/// F (or frameAll()) frames every mesh; a left click without a drag picks the body under the
/// cursor (a ray against the drawn triangles, on the UI thread's copy of the scene) and emits
/// bodyClicked. The host's input events reach the Viewport's own handlers, so either host
/// behaves the same.
#include "render/renderer.hpp"
#include "render/scene_view.hpp"

#include <QImage>
#include <QPoint>
#include <QString>
#include <QWidget>

#include <array>
#include <memory>
#include <optional>
#include <vector>

class QOpenGLContext;
class QWindow;

namespace viscera::studio {

enum class ViewportHost { Window, Widget };
/// "window" or "widget" (the settings' and command line's spelling); nullopt for anything else.
std::optional<ViewportHost> viewportHostFromText(const QString& text);
QString viewportHostText(ViewportHost host);

/// A host of the viewport's GL drawing (viewport.cpp): the render-thread window or the widget.
class ViewportCanvas;
/// What one frame draws: an immutable snapshot the UI thread hands to the host.
struct ViewportFrame;

class Viewport : public QWidget {
    Q_OBJECT
public:
    explicit Viewport(ViewportHost host = ViewportHost::Window, QWidget* parent = nullptr);
    ~Viewport() override;

    ViewportHost host() const { return m_host; }
    /// The surface the user's mouse and keys land on: the embedded QWindow (Window host) or
    /// the QOpenGLWidget (Widget host). Tests send their synthetic events there.
    QWindow* canvasWindow() const;
    QWidget* canvasWidget() const;
    /// Renders the current view into an offscreen framebuffer of the viewport's size and reads
    /// it back (null when no renderer exists). Waits for the render thread (Window host).
    QImage grabFramebuffer();

    /// The meshes to draw (the preview's SceneView; copied, the viewport then owns its data).
    void setScene(const render::SceneView& view);
    /// New positions per body and surface (m), as the preview publishes them.
    void setPositions(const std::vector<std::vector<Eigen::Vector3d>>& bodies,
                      const std::vector<std::vector<Eigen::Vector3d>>& surfaces);
    /// The case's "render" block (project.json; empty: renderer defaults): the viewport shows the
    /// case's look (SSS, light sampling, post effects), in mono.
    void setCaseRender(const std::string& json);
    /// The look: Authoring (the studio's default: flat light, no post effects or subsurface
    /// scattering, a grey background, a grid under the scene and the selection's outline) or
    /// Trainee (the case's render settings, as the player shows them).
    enum class Look { Authoring, Trainee };
    void setLook(Look look);
    Look look() const { return m_look; }
    /// The authoring look's grid and selection outline (drawn only in that look).
    const std::vector<render::RenderMesh>& guideMeshes() const { return m_guides; }
    /// The camera's target (the point it orbits), world frame.
    Eigen::Vector3f cameraTarget() const { return m_target; }
    /// The next scene set is framed (a project was opened: its scene is shown whole).
    void frameNextScene() { m_framed = false; }
    /// Highlights the body (or surface) named `name` (empty: none).
    void setSelectedName(const QString& name);
    const QString& selectedName() const { return m_selected; }
    void frameAll();

    /// Where the eye ray through `pos` meets a drawn mesh first.
    struct SurfaceHit {
        int mesh = -1;                                   ///< index into the view's meshes
        QString name;                                    ///< the mesh's name
        Eigen::Vector3f world = Eigen::Vector3f::Zero(); ///< on the drawn (deformed) surface
        Eigen::Vector3f rest = Eigen::Vector3f::Zero();  ///< the same surface point at rest
        bool invert = false; ///< paintPressed: Ctrl was held (the stroke does the brush's inverse)
        Eigen::Vector3f normal = Eigen::Vector3f::UnitZ(); ///< unit normal of the drawn triangle hit
    };
    std::optional<SurfaceHit> hitAt(QPoint pos) const;
    /// The meshes drawn (the UI thread's copy).
    const render::SceneView& view() const { return m_view; }
    /// RGBA per vertex over mesh `mesh` (empty: none), as render::SceneView::setOverlay.
    void setOverlay(int mesh, const std::vector<float>& rgba);
    /// Shows or hides mesh `mesh` (a hidden mesh is neither drawn nor hit).
    void setMeshVisible(int mesh, bool visible);
    /// Draws mesh `mesh` translucent (a 50 % screen door, render::RenderMesh::translucent).
    void setMeshTranslucent(int mesh, bool translucent);
    /// Face mask of mesh `mesh` (empty: every face), as render::SceneView::setFaceMask.
    void setFaceMask(int mesh, const std::vector<uint8_t>& mask);
    /// Draws body (or, `source` Surface, fascia) `index` at its rest positions (the preview's
    /// positions are not applied to it); -1: everything as simulated.
    void setRestPose(int index, render::RenderMesh::Source source = render::RenderMesh::Source::Body);
    /// Who draws authoring meshes: each tool replaces its own layer, the layers drawn in this
    /// order (the paint tools' skeleton and brush, a port's workspace, the assessment's targets).
    enum class Layer { Paint = 0, Port, Targets, Holds, Count };
    /// Static meshes of `layer` drawn after the scene's; not hit.
    void setAuthoringLayer(Layer layer, std::vector<render::RenderMesh> meshes);
    /// The paint layer's meshes (the paint tool's skeleton and section).
    void setAuthoringMeshes(std::vector<render::RenderMesh> meshes) {
        setAuthoringLayer(Layer::Paint, std::move(meshes));
    }
    size_t authoringMeshCount() const { return m_authoring.size(); }
    /// Every layer's meshes, in layer order.
    const std::vector<render::RenderMesh>& authoringMeshes() const { return m_authoring; }
    /// The meshes of one layer (a copy).
    std::vector<render::RenderMesh> authoringLayer(Layer layer) const;
    /// Replaces mesh k of the paint layer alone (a brush outline following the cursor): updated
    /// in the buffers it has when its triangles are the same, the others untouched.
    void setAuthoringMesh(size_t k, render::RenderMesh mesh);
    /// Paint mode: a left drag paints (paintPressed/Moved/Released at the surface under the
    /// cursor, Esc: paintCancelled) instead of orbiting; Alt + left drag orbits, middle drag
    /// pans, the wheel zooms.
    void setPaintMode(bool on);
    bool paintMode() const { return m_paintMode; }

    /// A tool's handles drawn in the viewport (the port gizmo): in paint mode a left press the
    /// grabber takes (grab() true) drags the handle (drag() per move, release() at the end)
    /// instead of painting or orbiting.
    class HandleGrabber {
    public:
        virtual ~HandleGrabber() = default;
        virtual bool grab(QPoint pos) = 0;
        virtual void drag(QPoint pos) = 0;
        virtual void release() = 0;
    };
    /// The grabber asked first on a press (null: none; the viewport does not own it).
    void setHandleGrabber(HandleGrabber* grabber);
    /// The eye ray through widget position `pos` (world frame, unit direction).
    void ray(QPoint pos, Eigen::Vector3f& origin, Eigen::Vector3f& dir) const;
    /// Where world point `x` appears in the widget (px); none behind the eye.
    std::optional<QPointF> toScreen(const Eigen::Vector3f& x) const;

    /// The mesh name under widget position `pos` (empty: none): what a click selects.
    QString pick(QPoint pos) const;
    /// One line: "llvmpipe (...)", or why the renderer could not be made (empty before the
    /// first frame).
    QString rendererInfo() const;
    bool rendererReady() const;
    int meshCount() const { return static_cast<int>(m_view.meshes().size()); }
    const render::Camera& camera() const { return m_camera; }
    /// Wall time of the last frame on screen (render + present), ms, and the resolution scale
    /// in use: the viewport renders at a lower resolution (down to kMinScale of the pixels,
    /// blitted up) while a frame takes longer than kPaintBudgetMs, and returns to full
    /// resolution when there is time.
    double lastPaintMs() const;
    double renderScale() const;
    /// Frames drawn on screen so far (grabs not counted).
    uint64_t paintCount() const;
    static constexpr double kPaintBudgetMs = 25.0, kMinScale = 0.25;

signals:
    void bodyClicked(const QString& name);
    void paintPressed(const Viewport::SurfaceHit& hit);
    void paintMoved(const Viewport::SurfaceHit& hit);
    /// Paint mode: the cursor is over `hit` (with or without a button): where the brush outline
    /// goes. brushLeft(): over no surface.
    void brushHovered(const Viewport::SurfaceHit& hit);
    void brushLeft();
    void paintReleased();
    void paintCancelled();
    /// Esc in paint mode with no stroke under way: the tool that set the mode ends.
    void paintEscaped();
    /// Paint mode, F (radius) or Shift+F (strength) then a mouse move: `dx` pixels moved right
    /// since the key; `done` on the click that sets it (Esc: done with dx 0, the value restored).
    void brushAdjusted(bool strength, double dx, bool done);
    void rendererFailed(const QString& why);

protected:
    void mousePressEvent(QMouseEvent*) override;
    void mouseMoveEvent(QMouseEvent*) override;
    void mouseReleaseEvent(QMouseEvent*) override;
    void wheelEvent(QWheelEvent*) override;
    void keyPressEvent(QKeyEvent*) override;

private:
    friend class ViewportCanvas;
    /// The camera's mono eye at the widget's aspect (what ray() and toScreen() map through).
    render::EyeView eye() const;
    /// The snapshot of what to draw now (the scene is shared until it changes).
    ViewportFrame frame();
    void requestFrame();
    /// m_view changed: the next frame hands over a new snapshot.
    void viewChanged();
    void updateCamera();
    /// The eye ray through widget position `pos`: origin and unit direction, world frame.

    ViewportHost m_host;
    ViewportCanvas* m_canvas = nullptr;                   ///< owned through the Qt object tree
    render::SceneView m_view;                             ///< the UI thread's copy: picking and the next snapshot
    std::shared_ptr<const render::SceneView> m_published; ///< m_view as last handed over
    uint64_t m_sceneSerial = 0, m_lookSerial = 0;
    render::Camera m_camera;
    QString m_selected;
    std::string m_caseRender;
    std::vector<uint32_t> m_baseMaterial; ///< per mesh, its material before highlighting
    // orbit camera
    Eigen::Vector3f m_target = Eigen::Vector3f::Zero();
    float m_distance = 0.3f, m_yaw = -1.5708f, m_pitch = 0.5f;
    QPoint m_pressPos, m_lastPos;
    Qt::MouseButton m_button = Qt::NoButton;
    HandleGrabber* m_grabber = nullptr;
    bool m_handleDrag = false; ///< a left drag on a handle the grabber took
    bool m_dragged = false;
    bool m_framed = false;
    Look m_look = Look::Authoring;
    /// The authoring look's grid and the selection's outline (rebuilt with the scene and the
    /// selection), drawn after the authoring meshes.
    std::vector<render::RenderMesh> m_guides;
    uint64_t m_guideRevision = 0;
    void rebuildGuides();
    bool m_paintMode = false, m_painting = false;
    int m_restBody = -1; ///< the mesh drawn at rest: its source index and kind
    render::RenderMesh::Source m_restSource = render::RenderMesh::Source::Body;
    enum class Adjust { None, Radius, Strength } m_adjust = Adjust::None;
    QPoint m_adjustFrom;
    std::vector<render::RenderMesh> m_authoring; ///< the layers' meshes, in layer order
    std::array<size_t, static_cast<size_t>(Layer::Count)> m_layerSize{};
    /// Where `layer`'s meshes start in m_authoring.
    size_t layerStart(Layer layer) const;
    void applyRestPose();
    void trackMouse(bool on);
};

} // namespace viscera::studio
