#include "render/scene_view.hpp"

#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"
#include "sim/scene/world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace viscera::render {

namespace {

using Tri3 = std::array<uint32_t, 3>;

std::vector<Eigen::Vector3f> toFloat(const std::vector<sim::Vec3>& p) {
    std::vector<Eigen::Vector3f> out(p.size());
    for (size_t i = 0; i < p.size(); ++i)
        out[i] = p[i].cast<float>();
    return out;
}

/// Area-weighted vertex normals; with `weld` (#V: the vertex each one's normal is shared with)
/// the copies of a vertex split at a UV seam get one normal.
void computeNormals(const std::vector<float>& pos, const std::vector<uint32_t>& idx, std::vector<float>& nrm,
                    const std::vector<uint32_t>& weld = {}) {
    std::fill(nrm.begin(), nrm.end(), 0.0f);
    const bool welded = !weld.empty() && weld.size() * 3 == nrm.size();
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        const Eigen::Map<const Eigen::Vector3f> a(&pos[3 * idx[t]]), b(&pos[3 * idx[t + 1]]), c(&pos[3 * idx[t + 2]]);
        const Eigen::Vector3f n = (b - a).cross(c - a); // area-weighted
        for (int k = 0; k < 3; ++k)
            Eigen::Map<Eigen::Vector3f>(&nrm[3 * (welded ? weld[idx[t + k]] : idx[t + k])]) += n;
    }
    if (welded)
        for (size_t v = 0; v < weld.size(); ++v)
            if (weld[v] != v)
                for (int c = 0; c < 3; ++c)
                    nrm[3 * v + size_t(c)] = nrm[3 * weld[v] + size_t(c)];
    for (size_t v = 0; v < nrm.size(); v += 3) {
        Eigen::Map<Eigen::Vector3f> n(&nrm[v]);
        const float len = n.norm();
        if (len > 0)
            n /= len;
        else
            n = Eigen::Vector3f::UnitZ();
    }
}

std::vector<Eigen::Vector3f> asVectors(const std::vector<float>& flat) {
    std::vector<Eigen::Vector3f> out(flat.size() / 3);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = Eigen::Vector3f(flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]);
    return out;
}

RenderMesh makeMesh(const std::string& name, const std::vector<Eigen::Vector3f>& pos, const std::vector<Tri3>& tris) {
    RenderMesh m;
    m.name = name;
    m.indices.reserve(tris.size() * 3);
    for (const Tri3& t : tris)
        m.indices.insert(m.indices.end(), t.begin(), t.end());
    m.positions.resize(pos.size() * 3);
    for (size_t i = 0; i < pos.size(); ++i)
        for (int k = 0; k < 3; ++k)
            m.positions[3 * i + k] = pos[i][k];
    m.rest = m.positions;
    m.normals.resize(m.positions.size());
    computeNormals(m.positions, m.indices, m.normals);
    m.thickness.assign(pos.size(), 0.0f);
    m.sampleMap.assign(pos.size(), 0.0f);
    m.heat.assign(pos.size(), 0.0f);
    return m;
}

std::vector<Tri3> trianglesOf(const sim::TriMesh& mesh) {
    std::vector<Tri3> tris;
    tris.reserve(mesh.triangleCount());
    for (const sim::Tri& t : mesh.triangles())
        tris.push_back({uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
    return tris;
}

} // namespace

RenderMesh bodySurfaceMesh(const sim::TetMesh& rest, const std::string& name, size_t body) {
    auto mesh = rest.clone();
    mesh->requireLevel(3);
    const std::vector<int32_t>& map = mesh->boundaryVertexMap();
    std::vector<Eigen::Vector3f> pos(map.size());
    for (size_t i = 0; i < map.size(); ++i)
        pos[i] = mesh->positions()[map[i]].cast<float>();
    RenderMesh m = makeMesh(name, pos, trianglesOf(mesh->boundary()));
    m.source = RenderMesh::Source::Body;
    m.sourceIndex = body;
    m.sourceVertex = map;
    return m;
}

uint32_t SceneView::addMaterial(const TissueMaterial& material) {
    m_materials.push_back(material);
    return uint32_t(m_materials.size() - 1);
}

size_t addScenery(SceneView& view, const std::string& name, const sim::TriMesh& mesh) {
    const size_t i = view.addMesh(name, mesh, view.addMaterial(defaultMaterialFor(name)));
    view.meshes()[i].doubleSided = false; // seen from the side it faces (the working space)
    return i;
}

size_t SceneView::addMesh(const std::string& name, const sim::TriMesh& mesh, uint32_t material,
                          const ThicknessBakeSettings& bake) {
    if (material >= m_materials.size())
        throw std::invalid_argument("render::SceneView::addMesh(): " + name + ": material " + std::to_string(material) +
                                    " does not exist (" + std::to_string(m_materials.size()) + " materials)");
    const auto pos = toFloat(mesh.positions());
    const auto tris = trianglesOf(mesh);
    RenderMesh m = makeMesh(name, pos, tris);
    m.material = material;
    m.doubleSided = !mesh.isClosedOriented();
    const TriangleBvh bvh(pos, tris);
    m.thickness = bakeThickness(pos, asVectors(m.normals), bvh, bake);
    m_meshes.push_back(std::move(m));
    return m_meshes.size() - 1;
}

size_t SceneView::bakeThicknessMap(size_t i, int size, const ThicknessBakeSettings& bake) {
    RenderMesh& m = m_meshes.at(i);
    if (m.uv.size() != 2 * m.vertexCount() || m.uv.empty())
        throw std::invalid_argument("render::SceneView::bakeThicknessMap(): mesh '" + m.name + "' has no UVs");
    const std::vector<Eigen::Vector3f> pos = asVectors(m.rest);
    std::vector<Tri3> tris(m.triangleCount());
    for (size_t t = 0; t < tris.size(); ++t)
        tris[t] = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
    std::vector<Eigen::Vector2f> uv(m.vertexCount());
    for (size_t v = 0; v < uv.size(); ++v)
        uv[v] = Eigen::Vector2f(m.uv[2 * v], m.uv[2 * v + 1]);
    std::vector<Eigen::Vector3f> normals = asVectors(m.normals); // at rest when baked before a frame
    size_t covered = 0;
    m.thicknessMap =
        bakeThicknessTexture(pos, normals, tris, uv, TriangleBvh(pos, tris), size, kThicknessMapRange, bake, &covered);
    ++m.staticRevision;
    return covered;
}

SceneView SceneView::fromWorld(const sim::World& world, const ThicknessBakeSettings& bake) {
    SceneView view;
    std::vector<Eigen::Vector3f> allPos;
    std::vector<Tri3> allTris;
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        RenderMesh m = bodySurfaceMesh(world.restMesh(b), world.bodyName(b), b);
        const std::vector<Eigen::Vector3f> pos = asVectors(m.rest);
        std::vector<Tri3> tris(m.triangleCount());
        for (size_t t = 0; t < tris.size(); ++t)
            tris[t] = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
        m.material = view.addMaterial(defaultMaterialFor(world.bodyName(b)));
        m.thickness = bakeThickness(pos, asVectors(m.normals), TriangleBvh(pos, tris), bake);
        const uint32_t base = uint32_t(allPos.size());
        allPos.insert(allPos.end(), pos.begin(), pos.end());
        for (const Tri3& t : tris)
            allTris.push_back({t[0] + base, t[1] + base, t[2] + base});
        view.m_meshes.push_back(std::move(m));
    }
    if (const sim::InteractionRuntime* in = world.interaction(); in && in->dissects())
        for (size_t b = 0; b < world.bodyCount(); ++b) // the fat's cut surface, shown as it opens
            if (in->dissectsBody(b)) view.addBodyCut(b, world.restMesh(b));
    std::unique_ptr<TriangleBvh> bodies;
    if (!allTris.empty()) bodies = std::make_unique<TriangleBvh>(allPos, allTris);
    for (size_t s = 0; s < world.surfaceCount(); ++s) {
        // The surface mesh the world was assembled with is the layer at rest (also once it has moved).
        const std::vector<Tri3> tris = trianglesOf(world.surfaceMesh(s));
        const auto pos = toFloat(world.surfaceMesh(s).positions());
        const std::string name = world.surfaceName(s);
        RenderMesh m = makeMesh(name, pos, tris);
        m.material = view.addMaterial(defaultMaterialFor(name));
        m.doubleSided = true;
        m.drawOnTop = true;
        m.source = RenderMesh::Source::Surface;
        m.sourceIndex = s;
        m.sourceVertex.resize(pos.size());
        for (size_t i = 0; i < pos.size(); ++i)
            m.sourceVertex[i] = int32_t(i);
        if (bodies) {
            // The membrane sits on a body: its normal points away from the body, so −n enters it.
            m.thickness = bakeThickness(pos, asVectors(m.normals), *bodies, bake);
        }
        view.m_meshes.push_back(std::move(m));
    }
    view.updateFromWorld(world); // baked in the rest state, shown in the current one
    return view;
}

void SceneView::updateFromWorld(const sim::World& world) {
    const sim::InteractionRuntime* cut =
        world.interaction() && world.interaction()->dissects() ? world.interaction() : nullptr;
    if (cut) // before the positions are copied: the cut mesh's slots name the nodes to copy
        for (const BodyCut& c : m_cuts) {
            cut->bodyTetMaskInto(c.body, m_tetMaskScratch); // setBodyCut uses m_maskScratch itself
            setBodyCut(c.body, m_tetMaskScratch);
        }
    for (size_t i = 0; i < m_meshes.size(); ++i) {
        RenderMesh& m = m_meshes[i];
        const std::vector<sim::Vec3>* src = nullptr;
        if (m.source == RenderMesh::Source::Body && m.sourceIndex < world.bodyCount())
            src = &world.positions(m.sourceIndex);
        else if (m.source == RenderMesh::Source::Surface && m.sourceIndex < world.surfaceCount())
            src = &world.surfacePositions(m.sourceIndex);
        if (!src) continue;
        const size_t n = m.vertexCount();
        for (size_t v = 0; v < n; ++v) {
            const int32_t s = m.sourceVertex[v];
            if (s < 0 || size_t(s) >= src->size()) continue;
            const sim::Vec3& p = (*src)[s];
            m.positions[3 * v] = float(p.x());
            m.positions[3 * v + 1] = float(p.y());
            m.positions[3 * v + 2] = float(p.z());
        }
        recomputeNormals(i);
        if (!cut) continue;
        // Energized dissection [A §5.3.1]: cut faces are dropped from the same buffers, and the
        // heat channel of the G-buffer tints coagulated and charred tissue along the cut.
        if (m.source == RenderMesh::Source::Surface) {
            cut->surfaceFaceMaskInto(m.sourceIndex, m_maskScratch);
            if (m_maskScratch.size() == m.triangleCount()) setFaceMask(i, m_maskScratch);
            cut->surfaceHeatInto(m.sourceIndex, m_heatScratch);
        } else {
            cut->bodyHeatInto(m.sourceIndex, m_heatScratch);
        }
        if (!m_heatScratch.empty()) setSourceHeat(i, m_heatScratch);
    }
}

void SceneView::setSourceHeat(size_t i, const std::vector<float>& nodeHeat) {
    RenderMesh& m = m_meshes.at(i);
    if (m.source == RenderMesh::Source::Static || m.heat.size() != m.vertexCount() ||
        m.sourceVertex.size() != m.vertexCount())
        return;
    for (size_t v = 0; v < m.heat.size(); ++v) {
        const int32_t s = m.sourceVertex[v];
        const float h = s >= 0 && size_t(s) < nodeHeat.size() ? nodeHeat[size_t(s)] : 0.0f;
        m.heat[v] = std::isfinite(h) ? std::clamp(h, 0.0f, 1.0f) : 0.0f;
    }
    ++m.revision;
}

size_t SceneView::addBodyCut(size_t bodyMesh, const sim::TetMesh& rest, size_t capacity) {
    const RenderMesh& body = m_meshes.at(bodyMesh); // a reference only until m_meshes grows below
    const size_t bodySource = body.sourceIndex;
    if (body.source != RenderMesh::Source::Body)
        throw std::invalid_argument("render::SceneView::addBodyCut(): mesh " + body.name + " is not a body's boundary");
    if (rest.tetCount() == 0 || capacity == 0)
        throw std::invalid_argument("render::SceneView::addBodyCut(): " + body.name + ": no tets or no capacity");
    auto mesh = std::shared_ptr<sim::TetMesh>(rest.clone());
    mesh->requireLevel(3);
    if (mesh->boundaryHalfFacets().size() != body.triangleCount())
        throw std::invalid_argument("render::SceneView::addBodyCut(): mesh " + body.name +
                                    " is not the boundary of the given tet mesh");
    RenderMesh m;
    m.name = body.name + " cut surface";
    m.material = body.material;
    m.source = RenderMesh::Source::Body;
    m.sourceIndex = body.sourceIndex;
    m.visible = false; // nothing cut yet
    m.cutSurface = true;
    const size_t nv = 3 * capacity;
    const int32_t anyNode = mesh->tets()[0][0]; // unused slots sit on the body (bounds stay true)
    m.sourceVertex.assign(nv, anyNode);
    m.indices.resize(nv);
    for (size_t k = 0; k < nv; ++k)
        m.indices[k] = uint32_t(k);
    m.positions.resize(3 * nv);
    const sim::Vec3& p0 = mesh->positions()[size_t(anyNode)];
    for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c)
            m.positions[3 * v + c] = float(p0[c]);
    m.rest = m.positions;
    m.normals.assign(3 * nv, 0.0f);
    m.thickness.assign(nv, 0.0f);
    m.sampleMap.assign(nv, 0.0f);
    m.heat.assign(nv, 0.0f);
    m.faceMask.assign(capacity, 0);
    m_meshes.push_back(std::move(m));
    BodyCut c;
    c.body = bodySource;
    c.bodyMesh = bodyMesh;
    c.cutMesh = m_meshes.size() - 1;
    c.capacity = capacity;
    c.rest = std::move(mesh);
    c.lastMask.assign(c.rest->tetCount(), 1);
    m_cuts.push_back(std::move(c));
    return m_meshes.size() - 1;
}

void SceneView::setBodyCut(size_t body, const std::vector<uint8_t>& tetMask) {
    for (BodyCut& c : m_cuts) {
        if (c.body != body || tetMask.size() != c.lastMask.size()) continue;
        bool same = true;
        for (size_t t = 0; t < tetMask.size() && same; ++t)
            same = (tetMask[t] != 0) == (c.lastMask[t] != 0);
        if (same) continue;
        for (size_t t = 0; t < tetMask.size(); ++t)
            c.lastMask[t] = tetMask[t] ? 1 : 0;
        const sim::TetMesh& T = *c.rest;
        // The body's own boundary: a face goes with its tet.
        const std::vector<int32_t>& bhf = T.boundaryHalfFacets();
        m_maskScratch.resize(bhf.size());
        for (size_t f = 0; f < bhf.size(); ++f)
            m_maskScratch[f] = c.lastMask[size_t(sim::TetMesh::cellOf(bhf[f]))];
        setFaceMask(c.bodyMesh, m_maskScratch);
        // The cavity: faces of intact tets across from a cut one, oriented out of the intact tet.
        RenderMesh& m = m_meshes[c.cutMesh];
        const int32_t anyNode = T.tets()[0][0];
        size_t k = 0;
        c.exposed = 0;
        for (size_t t = 0; t < T.tetCount(); ++t) {
            if (!c.lastMask[t]) continue;
            for (int i = 0; i < 4; ++i) {
                const int32_t hf = int32_t(4 * t + i);
                const int32_t o = T.opp(hf);
                if (o == sim::kNone || c.lastMask[size_t(sim::TetMesh::cellOf(o))]) continue;
                ++c.exposed;
                if (k >= c.capacity) continue;
                const std::array<int32_t, 3> v = T.halfFacetVertices(hf);
                for (int j = 0; j < 3; ++j) {
                    m.sourceVertex[3 * k + j] = v[j];
                    const sim::Vec3& r = T.positions()[size_t(v[j])];
                    for (int a = 0; a < 3; ++a)
                        m.rest[3 * (3 * k + j) + a] = float(r[a]);
                }
                ++k;
            }
        }
        for (size_t s = k; s < c.capacity; ++s)
            for (int j = 0; j < 3; ++j)
                m.sourceVertex[3 * s + j] = anyNode;
        m_maskScratch.assign(c.capacity, 0);
        std::fill(m_maskScratch.begin(), m_maskScratch.begin() + long(k), 1);
        setFaceMask(c.cutMesh, m_maskScratch);
        m.visible = k > 0;
        ++m.staticRevision; // rest positions (the pattern space) of the refilled slots
    }
}

size_t SceneView::exposedCutFaces(size_t body) const {
    for (const BodyCut& c : m_cuts)
        if (c.body == body) return c.exposed;
    return 0;
}

void SceneView::recomputeNormals(size_t i) {
    RenderMesh& m = m_meshes.at(i);
    computeNormals(m.positions, m.indices, m.normals, m.weld);
    ++m.revision;
}

void SceneView::setOverlay(size_t i, const std::vector<float>& rgba) {
    RenderMesh& m = m_meshes.at(i);
    if (!rgba.empty() && rgba.size() != 4 * m.vertexCount())
        throw std::invalid_argument("render::SceneView::setOverlay(): mesh " + m.name + " has " +
                                    std::to_string(m.vertexCount()) + " vertices, got " + std::to_string(rgba.size()) +
                                    " overlay values (4 per vertex, or none)");
    m.overlay.resize(rgba.size());
    for (size_t k = 0; k < rgba.size(); ++k)
        m.overlay[k] = std::isfinite(rgba[k]) ? std::clamp(rgba[k], 0.0f, 1.0f) : 0.0f;
    ++m.staticRevision;
}

void SceneView::setHeat(size_t i, const std::vector<float>& heat) {
    RenderMesh& m = m_meshes.at(i);
    if (heat.size() != m.vertexCount())
        throw std::invalid_argument("render::SceneView::setHeat(): mesh " + m.name + " has " +
                                    std::to_string(m.vertexCount()) + " vertices, got " + std::to_string(heat.size()) +
                                    " heat values");
    for (size_t v = 0; v < heat.size(); ++v)
        m.heat[v] = std::clamp(heat[v], 0.0f, 1.0f);
    ++m.revision;
}

size_t RenderMesh::drawnTriangleCount() const {
    if (faceMask.size() != triangleCount()) return triangleCount();
    size_t n = 0;
    for (uint8_t f : faceMask)
        n += f ? 1 : 0;
    return n;
}

void RenderMesh::drawnIndicesInto(std::vector<uint32_t>& out) const {
    if (faceMask.size() != triangleCount()) {
        out.assign(indices.begin(), indices.end());
        return;
    }
    out.resize(3 * drawnTriangleCount());
    size_t k = 0;
    for (size_t f = 0; f < faceMask.size(); ++f)
        if (faceMask[f])
            for (int c = 0; c < 3; ++c)
                out[k++] = indices[3 * f + c];
}

void SceneView::setFaceMask(size_t i, const std::vector<uint8_t>& mask) {
    RenderMesh& m = m_meshes.at(i);
    if (!mask.empty() && mask.size() != m.triangleCount())
        throw std::invalid_argument("render::SceneView::setFaceMask(): mesh " + m.name + " has " +
                                    std::to_string(m.triangleCount()) + " triangles, got " +
                                    std::to_string(mask.size()) + " flags");
    bool same = mask.size() == m.faceMask.size();
    for (size_t f = 0; same && f < mask.size(); ++f)
        same = (mask[f] != 0) == (m.faceMask[f] != 0);
    if (same) return;
    m.faceMask.resize(mask.size());
    for (size_t f = 0; f < mask.size(); ++f)
        m.faceMask[f] = mask[f] ? 1 : 0;
    ++m.faceMaskRevision;
}

void SceneView::paintSampleMap(const Eigen::Vector3f& centre, float radius, int samples) {
    if (samples != 0 && samples != 1 && samples != 4 && samples != 8)
        throw std::invalid_argument("render::SceneView::paintSampleMap(): samples must be 0, 1, 4 or 8, got " +
                                    std::to_string(samples));
    for (RenderMesh& m : m_meshes) {
        bool changed = false;
        for (size_t v = 0; v < m.vertexCount(); ++v)
            if ((Eigen::Map<const Eigen::Vector3f>(&m.positions[3 * v]) - centre).norm() <= radius) {
                m.sampleMap[v] = float(samples);
                changed = true;
            }
        if (changed) ++m.staticRevision;
    }
}

std::array<Eigen::Vector3f, 2> SceneView::bounds() const {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
    bool any = false;
    for (const RenderMesh& m : m_meshes) {
        if (!m.visible) continue;
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const Eigen::Map<const Eigen::Vector3f> p(&m.positions[3 * v]);
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
            any = true;
        }
    }
    if (!any) return {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
    return {lo, hi};
}

} // namespace viscera::render
