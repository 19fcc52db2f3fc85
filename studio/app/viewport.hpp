#pragma once
/// The studio's 3D viewport: a QOpenGLWidget drawing the preview's bodies and surfaces with
/// core/render on the widget's own OpenGL context (render::createRendererForCurrentContext:
/// the deferred PBR renderer of the player, presented into the widget's framebuffer).
///
/// Left drag orbits about the target, middle drag (or Shift + left) pans, the wheel zooms,
/// F (or frameAll()) frames every mesh; a left click without a drag picks the body under the
/// cursor (a ray against the drawn triangles) and emits bodyClicked.
#include "render/renderer.hpp"
#include "render/scene_view.hpp"

#include <QOpenGLWidget>
#include <QPoint>
#include <QString>

#include <memory>
#include <vector>

namespace viscera::studio {

class Viewport : public QOpenGLWidget {
    Q_OBJECT
public:
    explicit Viewport(QWidget* parent = nullptr);
    ~Viewport() override;

    /// The meshes to draw (the preview's SceneView; copied, the viewport then owns its data).
    void setScene(const render::SceneView& view);
    /// New positions per body and surface (m), as the preview publishes them.
    void setPositions(const std::vector<std::vector<Eigen::Vector3d>>& bodies,
                      const std::vector<std::vector<Eigen::Vector3d>>& surfaces);
    /// The case's "render" block (project.json; empty: renderer defaults): the viewport shows the
    /// case's look (SSS, light sampling, post effects), in mono.
    void setCaseRender(const std::string& json);
    /// Highlights the body (or surface) named `name` (empty: none).
    void setSelectedName(const QString& name);
    void frameAll();

    /// The mesh name under widget position `pos` (empty: none): what a click selects.
    QString pick(QPoint pos) const;
    /// One line: "llvmpipe (...)", or why the renderer could not be made.
    const QString& rendererInfo() const { return m_info; }
    bool rendererReady() const { return m_renderer != nullptr; }
    int meshCount() const { return static_cast<int>(m_view.meshes().size()); }
    const render::Camera& camera() const { return m_camera; }
    /// Wall time of the last paint (render + present), ms, and the resolution scale in use: the
    /// viewport renders at a lower resolution (down to kMinScale of the widget's pixels, blitted
    /// up) while a frame takes longer than kPaintBudgetMs, so that painting never stalls the UI
    /// thread for long on a software renderer; it returns to full resolution when there is time.
    double lastPaintMs() const { return m_lastPaintMs; }
    double renderScale() const { return m_scale; }
    static constexpr double kPaintBudgetMs = 12.0, kMinScale = 0.25;

signals:
    void bodyClicked(const QString& name);
    void rendererFailed(const QString& why);

protected:
    void initializeGL() override;
    void paintGL() override;
    void resizeGL(int w, int h) override;
    void mousePressEvent(QMouseEvent*) override;
    void mouseMoveEvent(QMouseEvent*) override;
    void mouseReleaseEvent(QMouseEvent*) override;
    void wheelEvent(QWheelEvent*) override;
    void keyPressEvent(QKeyEvent*) override;

private:
    void updateCamera();
    /// The eye ray through widget position `pos`: origin and unit direction, world frame.
    void ray(QPoint pos, Eigen::Vector3f& origin, Eigen::Vector3f& dir) const;

    std::unique_ptr<render::Renderer> m_renderer;
    render::SceneView m_view;
    render::Camera m_camera;
    QString m_info, m_selected;
    std::string m_caseRender;
    std::vector<uint32_t> m_baseMaterial; ///< per mesh, its material before highlighting
    // orbit camera
    Eigen::Vector3f m_target = Eigen::Vector3f::Zero();
    float m_distance = 0.3f, m_yaw = -1.5708f, m_pitch = 0.5f;
    QPoint m_pressPos, m_lastPos;
    Qt::MouseButton m_button = Qt::NoButton;
    bool m_dragged = false;
    bool m_framed = false;
    double m_lastPaintMs = 0, m_scale = 1.0;
};

} // namespace viscera::studio
