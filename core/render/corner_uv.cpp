#include "render/corner_uv.hpp"

#include "render/scene_view.hpp"
#include "sim/util/error.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <tuple>

namespace viscera::render {
namespace {

constexpr char kMagic[4] = {'V', 'U', 'V', '1'};

void putU32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i)
        out.push_back(char((v >> (8 * i)) & 0xffu));
}

void putF32(std::string& out, float f) {
    uint32_t v = 0;
    std::memcpy(&v, &f, 4);
    putU32(out, v);
}

uint32_t getU32(std::string_view b, size_t at) {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
        v |= uint32_t(uint8_t(b[at + size_t(i)])) << (8 * i);
    return v;
}

float getF32(std::string_view b, size_t at) {
    const uint32_t v = getU32(b, at);
    float f = 0;
    std::memcpy(&f, &v, 4);
    return f;
}

bool usable(float f) {
    return std::isfinite(f) && std::abs(f) <= kMaxCornerUv;
}

/// Copies the per-vertex attributes of `from` (vertex `v`) onto the end of `to`'s arrays.
void appendVertex(const RenderMesh& from, size_t v, RenderMesh& to) {
    auto copy = [v](const std::vector<float>& src, std::vector<float>& dst, size_t width) {
        if (src.size() < width * (v + 1)) return;
        dst.insert(dst.end(), src.begin() + long(width * v), src.begin() + long(width * (v + 1)));
    };
    copy(from.positions, to.positions, 3);
    copy(from.rest, to.rest, 3);
    copy(from.normals, to.normals, 3);
    copy(from.thickness, to.thickness, 1);
    copy(from.sampleMap, to.sampleMap, 1);
    copy(from.heat, to.heat, 1);
    copy(from.overlay, to.overlay, 4);
    if (v < from.sourceVertex.size()) to.sourceVertex.push_back(from.sourceVertex[v]);
}

} // namespace

std::string cornerUvBytes(const std::vector<CornerUvF>& uv) {
    std::string out(kMagic, 4);
    putU32(out, uint32_t(uv.size()));
    out.reserve(8 + 24 * uv.size());
    for (size_t t = 0; t < uv.size(); ++t)
        for (const Eigen::Vector2f& c : uv[t]) {
            if (!usable(c.x()) || !usable(c.y()))
                throw std::invalid_argument("render::cornerUvBytes(): triangle " + std::to_string(t) +
                                            ": a UV is not finite or beyond " + std::to_string(kMaxCornerUv));
            putF32(out, c.x());
            putF32(out, c.y());
        }
    return out;
}

std::vector<CornerUvF> parseCornerUv(std::string_view bytes, const std::string& origin, size_t triangles) {
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 4) != 0)
        throw InputError(origin + ": not a corner-UV file (it must start with 'VUV1' and a triangle count)");
    const size_t count = getU32(bytes, 4);
    if (count != triangles)
        throw InputError(origin + ": " + std::to_string(count) + " triangles, the body's boundary has " +
                         std::to_string(triangles));
    if (bytes.size() != 8 + 24 * count)
        throw InputError(origin + ": " + std::to_string(bytes.size()) + " bytes, " + std::to_string(count) +
                         " triangles take " + std::to_string(8 + 24 * count));
    std::vector<CornerUvF> uv(count);
    for (size_t t = 0; t < count; ++t)
        for (int k = 0; k < 3; ++k) {
            const size_t at = 8 + 24 * t + 8 * size_t(k);
            uv[t][size_t(k)] = Eigen::Vector2f(getF32(bytes, at), getF32(bytes, at + 4));
            if (!usable(uv[t][size_t(k)].x()) || !usable(uv[t][size_t(k)].y()))
                throw InputError(origin + ": triangle " + std::to_string(t) + " corner " + std::to_string(k) +
                                 ": the UV is not finite or beyond " + std::to_string(int(kMaxCornerUv)));
        }
    return uv;
}

size_t applyCornerUv(SceneView& view, const std::string& target, const std::vector<CornerUvF>& uv) {
    for (RenderMesh& m : view.meshes()) {
        if (m.name != target || m.cutSurface || m.source != RenderMesh::Source::Body) continue;
        if (uv.size() != m.triangleCount())
            throw std::invalid_argument("render::applyCornerUv(): " + target + ": " + std::to_string(uv.size()) +
                                        " UV triangles for " + std::to_string(m.triangleCount()) + " triangles");
        RenderMesh out;
        std::map<std::tuple<uint32_t, float, float>, uint32_t> index;
        out.indices.resize(m.indices.size());
        for (size_t t = 0; t < uv.size(); ++t)
            for (size_t k = 0; k < 3; ++k) {
                const uint32_t v = m.indices[3 * t + k];
                const auto [it, fresh] =
                    index.try_emplace({v, uv[t][k].x(), uv[t][k].y()}, uint32_t(out.uv.size() / 2));
                if (fresh) {
                    appendVertex(m, v, out);
                    out.uv.push_back(uv[t][k].x());
                    out.uv.push_back(uv[t][k].y());
                    out.weld.push_back(v); // the copies of one vertex share its normal
                }
                out.indices[3 * t + k] = it->second;
            }
        // weld: the first copy of each original vertex stands for all of them
        std::vector<uint32_t> first(m.vertexCount(), UINT32_MAX);
        for (uint32_t n = 0; n < out.weld.size(); ++n) {
            uint32_t& f = first[out.weld[n]];
            if (f == UINT32_MAX) f = n;
            out.weld[n] = f;
        }
        m.indices = std::move(out.indices);
        m.positions = std::move(out.positions);
        m.rest = std::move(out.rest);
        m.normals = std::move(out.normals);
        m.thickness = std::move(out.thickness);
        m.sampleMap = std::move(out.sampleMap);
        m.heat = std::move(out.heat);
        m.overlay = std::move(out.overlay);
        m.sourceVertex = std::move(out.sourceVertex);
        m.uv = std::move(out.uv);
        m.weld = std::move(out.weld);
        ++m.revision;
        ++m.staticRevision;
        return 1;
    }
    return 0;
}

} // namespace viscera::render
