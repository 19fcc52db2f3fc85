#include "app/uv_preview.hpp"

#include "render/headless.hpp"
#include "render/scene_view.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>

namespace viscera::studio {

render::Image uvCheckerImage(int size, int checks) {
    render::Image img;
    img.width = img.height = size;
    img.rgba.resize(size_t(size) * size * 4);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double u = (x + 0.5) / size, v = 1.0 - (y + 0.5) / size; // first row is v = 1
            const bool light = ((int(u * checks) + int(v * checks)) & 1) == 0;
            const double k = light ? 1.0 : 0.35;
            uint8_t* p = &img.rgba[(size_t(y) * size + x) * 4];
            p[0] = uint8_t(std::lround(255 * k * (0.35 + 0.65 * u)));
            p[1] = uint8_t(std::lround(255 * k * (0.35 + 0.65 * v)));
            p[2] = uint8_t(std::lround(255 * k * 0.55));
            p[3] = 255;
        }
    return img;
}

std::vector<float> stretchOverlay(const sim::TriMesh& mesh, const std::vector<double>& faceStretch,
                                  const std::vector<std::array<int32_t, 2>>& seamEdges) {
    std::vector<double> worst(mesh.vertexCount(), 1.0);
    for (size_t t = 0; t < mesh.triangleCount() && t < faceStretch.size(); ++t)
        for (int32_t v : mesh.triangles()[t])
            worst[size_t(v)] = std::max(worst[size_t(v)], faceStretch[t]);
    std::vector<float> rgba(4 * worst.size());
    for (size_t v = 0; v < worst.size(); ++v) {
        float* c = &rgba[4 * v];
        if (std::isinf(worst[v])) { // flipped
            c[0] = 1, c[1] = 0, c[2] = 1, c[3] = 0.9f;
            continue;
        }
        // 1 → blue, the threshold and beyond → red, on a log scale
        const float s = float(std::clamp(std::log(worst[v]) / std::log(bake::kUvStretchThreshold), 0.0, 1.0));
        c[0] = s, c[1] = 0.25f * (1 - s), c[2] = 1 - s, c[3] = 0.75f;
    }
    for (const auto& e : seamEdges)
        for (int32_t v : e)
            if (size_t(v) < worst.size()) {
                float* c = &rgba[4 * size_t(v)];
                c[0] = c[1] = c[2] = 0.02f, c[3] = 1.0f;
            }
    return rgba;
}

void writeUvPreview(const std::filesystem::path& png, const std::vector<UvPreviewItem>& items, int width, int height) {
    if (items.empty()) throw std::invalid_argument("studio::writeUvPreview(): nothing to show");
    double span = 0;
    for (const UvPreviewItem& it : items) {
        if (it.uv.size() != it.mesh.triangleCount())
            throw std::invalid_argument("studio::writeUvPreview(): " + it.name +
                                        ": one UV triangle per triangle expected");
        const auto b = it.mesh.bounds();
        span = std::max(span, b[1].x() - b[0].x());
    }
    render::SceneView view;
    auto maps = std::make_shared<render::MaterialMaps>();
    maps->diffuse = uvCheckerImage();
    render::TissueMaterial checker = render::defaultMaterialFor("organ");
    checker.name = "uv checker";
    checker.maps = maps;
    checker.reflection = 0.05f;
    checker.sssWeight = 0.1f;
    const uint32_t material = view.addMaterial(checker);
    render::ThicknessBakeSettings bake;
    bake.rays = 1;
    for (size_t i = 0; i < items.size(); ++i) {
        // A render vertex per distinct (point, UV) pair: the seams split the mesh.
        const UvPreviewItem& it = items[i];
        std::map<std::tuple<int32_t, double, double>, int32_t> index;
        std::vector<sim::Vec3> pos;
        std::vector<float> uv, overlay;
        const bool withOverlay = it.overlay.size() == 4 * it.mesh.vertexCount();
        std::vector<sim::Tri> tris;
        const sim::Vec3 shift(1.25 * span * double(i), 0, 0);
        for (size_t t = 0; t < it.mesh.triangleCount(); ++t) {
            sim::Tri f{};
            for (int k = 0; k < 3; ++k) {
                const int32_t v = it.mesh.triangles()[t][k];
                const auto [slot, fresh] =
                    index.try_emplace({v, it.uv[t][k].x(), it.uv[t][k].y()}, int32_t(pos.size()));
                if (fresh) {
                    pos.push_back(it.mesh.positions()[v] + shift);
                    uv.push_back(float(it.uv[t][k].x()));
                    uv.push_back(float(it.uv[t][k].y()));
                    if (withOverlay)
                        overlay.insert(overlay.end(), it.overlay.begin() + 4 * long(v),
                                       it.overlay.begin() + 4 * long(v + 1));
                }
                f[k] = slot->second;
            }
            tris.push_back(f);
        }
        const size_t m =
            view.addMesh(it.name, sim::TriMesh::fromArrays(std::move(pos), std::move(tris), it.name), material, bake);
        view.meshes()[m].uv = std::move(uv);
        view.meshes()[m].doubleSided = true;
        if (withOverlay) view.setOverlay(m, overlay);
    }
    // Seen from above (+z, y up), framed on the row of surfaces, the head light at the camera.
    render::RenderSettings s = render::defaultSettingsFor(view, width, height);
    const auto [lo, hi] = view.bounds();
    const Eigen::Vector3f centre = 0.5f * (lo + hi), extent = hi - lo;
    const float halfFov = 0.5f * s.camera.fovYDeg * float(M_PI) / 180.0f;
    const float aspect = float(width) / float(height);
    const float dist =
        1.08f * std::max(0.5f * extent.y() / std::tan(halfFov), 0.5f * extent.x() / (std::tan(halfFov) * aspect)) +
        0.5f * extent.z();
    s.camera.target = centre;
    s.camera.position = centre + Eigen::Vector3f(0, 0, dist);
    s.camera.up = Eigen::Vector3f(0, 1, 0);
    s.camera.nearPlane = std::max(1e-4f, 0.2f * dist);
    s.camera.farPlane = 3.0f * dist + extent.z();
    s.light.intensity = 1.6f * dist * dist;
    s.sampling.bands = {{0.8f * dist, 8}, {1.0f * dist, 4}, {std::numeric_limits<float>::infinity(), 1}};
    std::string why;
    auto renderer = render::HeadlessRenderer::create(s, &why);
    if (!renderer) throw std::runtime_error("the UV preview needs an OpenGL context: " + why);
    renderer->renderFrame(view);
    renderer->writePng(png);
}

} // namespace viscera::studio
