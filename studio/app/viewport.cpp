#include "app/viewport.hpp"

#include "render/camera.hpp"
#include "render/case_settings.hpp"
#include "render/headless.hpp"

#include <Eigen/Geometry>
#include <QElapsedTimer>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <limits>

namespace viscera::studio {
namespace {

void* resolve(const char* name, void* user) {
    auto* ctx = static_cast<QOpenGLContext*>(user);
    return reinterpret_cast<void*>(ctx->getProcAddress(name));
}

/// Möller–Trumbore; t of the hit or +inf.
float hitTriangle(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
    const Eigen::Vector3f e1 = b - a, e2 = c - a, p = d.cross(e2);
    const float det = e1.dot(p);
    if (std::abs(det) < 1e-14f) return INFINITY;
    const float inv = 1.0f / det;
    const Eigen::Vector3f s = o - a;
    const float u = s.dot(p) * inv;
    if (u < 0 || u > 1) return INFINITY;
    const Eigen::Vector3f q = s.cross(e1);
    const float v = d.dot(q) * inv;
    if (v < 0 || u + v > 1) return INFINITY;
    const float t = e2.dot(q) * inv;
    return t > 0 ? t : INFINITY;
}

} // namespace

Viewport::Viewport(QWidget* parent) : QOpenGLWidget(parent) {
    setFocusPolicy(Qt::StrongFocus);
    setMinimumSize(320, 240);
}

Viewport::~Viewport() {
    makeCurrent();
    m_renderer.reset(); // GL objects go with the widget's context
    doneCurrent();
}

void Viewport::initializeGL() {
    std::string why;
    render::RenderSettings s; // framed on the first frame that has meshes
    s.width = std::max(1, width());
    s.height = std::max(1, height());
    try {
        m_renderer = render::createRendererForCurrentContext(resolve, context(), s, &why);
    } catch (const std::exception& e) {
        why = e.what();
    }
    if (m_renderer) {
        m_info = QString::fromStdString(m_renderer->backend().deviceName());
    } else {
        m_info = tr("viewport: no renderer (%1)").arg(QString::fromStdString(why));
        emit rendererFailed(m_info);
    }
}

void Viewport::resizeGL(int, int) {}

void Viewport::setScene(const render::SceneView& view) {
    m_view = view;
    m_baseMaterial.clear();
    const size_t base = m_view.materials().size();
    for (size_t i = 0; i < base; ++i) {
        render::TissueMaterial h = m_view.materials()[i];
        h.surface.colour = 0.5f * h.surface.colour + Eigen::Vector3f(0.25f, 0.3f, 0.45f);
        h.name += " (selected)";
        m_view.addMaterial(h);
    }
    for (const render::RenderMesh& m : m_view.meshes())
        m_baseMaterial.push_back(m.material);
    if (m_renderer && context()) {
        // a new scene gets new GPU buffers: a fresh renderer on the same context
        makeCurrent();
        std::string why;
        const render::RenderSettings s = m_renderer->settings();
        m_renderer = render::createRendererForCurrentContext(resolve, context(), s, &why);
        if (!m_renderer) m_info = tr("viewport: no renderer (%1)").arg(QString::fromStdString(why));
        doneCurrent();
    }
    if (!m_framed) frameAll();
    setSelectedName(m_selected);
    update();
}

void Viewport::setCaseRender(const std::string& json) {
    if (json == m_caseRender) return;
    m_caseRender = json;
    m_framed = false; // settings are made again on the next paint
    update();
}

void Viewport::setPositions(const std::vector<std::vector<Eigen::Vector3d>>& bodies,
                            const std::vector<std::vector<Eigen::Vector3d>>& surfaces) {
    auto& meshes = m_view.meshes();
    for (size_t i = 0; i < meshes.size(); ++i) {
        render::RenderMesh& m = meshes[i];
        const std::vector<Eigen::Vector3d>* src = nullptr;
        if (m.source == render::RenderMesh::Source::Body && m.sourceIndex < bodies.size()) src = &bodies[m.sourceIndex];
        if (m.source == render::RenderMesh::Source::Surface && m.sourceIndex < surfaces.size())
            src = &surfaces[m.sourceIndex];
        if (!src) continue;
        bool ok = true;
        for (size_t v = 0; v < m.sourceVertex.size() && ok; ++v)
            ok = m.sourceVertex[v] >= 0 && static_cast<size_t>(m.sourceVertex[v]) < src->size() &&
                 (*src)[m.sourceVertex[v]].allFinite();
        if (!ok) continue; // never draw a non-finite or mismatched state
        for (size_t v = 0; v < m.sourceVertex.size(); ++v) {
            const Eigen::Vector3d& p = (*src)[m.sourceVertex[v]];
            m.positions[3 * v] = static_cast<float>(p.x());
            m.positions[3 * v + 1] = static_cast<float>(p.y());
            m.positions[3 * v + 2] = static_cast<float>(p.z());
        }
        m_view.recomputeNormals(i);
    }
    update();
}

void Viewport::setSelectedName(const QString& name) {
    m_selected = name;
    auto& meshes = m_view.meshes();
    const size_t base = m_view.materials().size() / 2;
    for (size_t i = 0; i < meshes.size() && i < m_baseMaterial.size(); ++i)
        meshes[i].material = m_baseMaterial[i] + (QString::fromStdString(meshes[i].name) == name && base ? base : 0);
    update();
}

void Viewport::frameAll() {
    if (m_view.meshes().empty()) return;
    const auto [lo, hi] = m_view.bounds();
    if (!lo.allFinite() || !hi.allFinite()) return;
    m_target = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * (hi - lo).norm(), 1e-3f);
    m_distance = radius / std::sin(0.5f * 55.0f * 3.14159265f / 180.0f) * 1.1f;
    m_framed = true;
    updateCamera();
    update();
}

void Viewport::updateCamera() {
    m_pitch = std::clamp(m_pitch, -1.55f, 1.55f);
    m_distance = std::clamp(m_distance, 1e-3f, 100.0f);
    const Eigen::Vector3f dir(std::cos(m_pitch) * std::cos(m_yaw), std::cos(m_pitch) * std::sin(m_yaw),
                              std::sin(m_pitch));
    m_camera.target = m_target;
    m_camera.position = m_target + m_distance * dir;
    m_camera.up = Eigen::Vector3f(0, 0, 1);
    m_camera.nearPlane = std::max(1e-4f, 0.02f * m_distance);
    m_camera.farPlane = 20.0f * m_distance + 1.0f;
}

void Viewport::paintGL() {
    if (!m_renderer) return;
    const qreal dpr = devicePixelRatioF();
    const int w = std::max(1, static_cast<int>(width() * dpr)), h = std::max(1, static_cast<int>(height() * dpr));
    render::RenderSettings s = m_renderer->settings();
    if (m_view.meshes().empty()) {
        QOpenGLFunctions* f = context()->functions(); // nothing to draw yet
        f->glClearColor(0.05f, 0.02f, 0.02f, 1.0f);
        f->glClear(GL_COLOR_BUFFER_BIT);
        return;
    }
    QElapsedTimer timer;
    timer.start();
    const int rw = std::max(1, static_cast<int>(w * m_scale)), rh = std::max(1, static_cast<int>(h * m_scale));
    if (s.width != rw || s.height != rh || !m_framed) {
        render::RenderSettings d = render::defaultSettingsFor(m_view, rw, rh);
        try {
            render::applyCaseRender(d, m_caseRender, "project.json");
        } catch (const std::exception& e) {
            m_info = tr("viewport: %1").arg(QString::fromStdString(e.what())); // load checked it already
        }
        d.stereo.mode = render::StereoMode::Off; // the author's view is mono
        d.timePasses = false;
        s = d;
    }
    updateCamera();
    s.camera = m_camera;
    s.light.followCamera = true;
    try {
        m_renderer->setSettings(s);
        m_renderer->renderFrame(m_view);
        m_renderer->present(defaultFramebufferObject(), w, h); // scaled up when rendered smaller
    } catch (const std::exception& e) {
        m_info = tr("viewport: %1").arg(QString::fromStdString(e.what()));
    }
    m_lastPaintMs = timer.nsecsElapsed() * 1e-6;
    // resolution follows the paint budget (the cost scales with the pixel count, ~scale²)
    if (m_lastPaintMs > kPaintBudgetMs && m_scale > kMinScale)
        m_scale = std::max(kMinScale, m_scale * std::sqrt(kPaintBudgetMs / m_lastPaintMs) * 0.9);
    else if (m_lastPaintMs < 0.4 * kPaintBudgetMs && m_scale < 1.0)
        m_scale = std::min(1.0, m_scale * 1.25);
}

void Viewport::ray(QPoint pos, Eigen::Vector3f& origin, Eigen::Vector3f& dir) const {
    const float aspect = static_cast<float>(std::max(1, width())) / static_cast<float>(std::max(1, height()));
    const render::EyeView eye = render::monoEye(m_camera, aspect);
    const float nx = 2.0f * (pos.x() + 0.5f) / std::max(1, width()) - 1.0f;
    const float ny = 1.0f - 2.0f * (pos.y() + 0.5f) / std::max(1, height());
    Eigen::Vector4f a = eye.inverseViewProjection * Eigen::Vector4f(nx, ny, -1, 1);
    Eigen::Vector4f b = eye.inverseViewProjection * Eigen::Vector4f(nx, ny, 1, 1);
    origin = a.head<3>() / a.w();
    dir = (b.head<3>() / b.w() - origin).normalized();
}

QString Viewport::pick(QPoint pos) const {
    Eigen::Vector3f o, d;
    ray(pos, o, d);
    float best = INFINITY;
    QString name;
    for (const render::RenderMesh& m : m_view.meshes()) {
        if (!m.visible) continue;
        const auto P = [&](uint32_t v) {
            return Eigen::Vector3f(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]);
        };
        for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
            const float t = hitTriangle(o, d, P(m.indices[f]), P(m.indices[f + 1]), P(m.indices[f + 2]));
            if (t < best) {
                best = t;
                name = QString::fromStdString(m.name);
            }
        }
    }
    return name;
}

void Viewport::mousePressEvent(QMouseEvent* e) {
    setFocus(Qt::MouseFocusReason);
    m_pressPos = m_lastPos = e->position().toPoint();
    m_button = e->button();
    m_dragged = false;
}

void Viewport::mouseMoveEvent(QMouseEvent* e) {
    const QPoint p = e->position().toPoint();
    const QPoint dp = p - m_lastPos;
    m_lastPos = p;
    if ((p - m_pressPos).manhattanLength() > 3) m_dragged = true;
    const bool pan =
        m_button == Qt::MiddleButton || (m_button == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier));
    if (pan) {
        const Eigen::Vector3f fwd = (m_camera.target - m_camera.position).normalized();
        const Eigen::Vector3f right = fwd.cross(Eigen::Vector3f(0, 0, 1)).normalized();
        const Eigen::Vector3f up = right.cross(fwd);
        const float scale = 2.0f * m_distance * std::tan(0.5f * 55.0f * 3.14159265f / 180.0f) / std::max(1, height());
        m_target += (-dp.x() * right + dp.y() * up) * scale;
    } else if (m_button == Qt::LeftButton) {
        m_yaw -= 0.01f * dp.x();
        m_pitch += 0.01f * dp.y();
    } else {
        return;
    }
    updateCamera();
    update();
}

void Viewport::mouseReleaseEvent(QMouseEvent* e) {
    if (e->button() == Qt::LeftButton && !m_dragged) {
        const QString name = pick(e->position().toPoint());
        if (!name.isEmpty()) emit bodyClicked(name);
    }
    m_button = Qt::NoButton;
}

void Viewport::wheelEvent(QWheelEvent* e) {
    m_distance *= std::pow(0.85f, e->angleDelta().y() / 120.0f);
    updateCamera();
    update();
    e->accept();
}

void Viewport::keyPressEvent(QKeyEvent* e) {
    if (e->key() == Qt::Key_F || e->key() == Qt::Key_Home) {
        frameAll();
        return;
    }
    QOpenGLWidget::keyPressEvent(e);
}

} // namespace viscera::studio
