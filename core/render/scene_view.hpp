#pragma once
/// What the renderer draws: triangle meshes (the boundary triangles of each simulated body and the
/// fascia surfaces), their materials and per-vertex data. Topology and static attributes are fixed
/// when a mesh is added; positions, normals and heat change every frame and are written into the
/// same arrays (and, by the backends, into the same GPU buffers) without reallocation.
#include "render/material.hpp"
#include "render/thickness_bake.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {
class World;
class TriMesh;
class TetMesh;
} // namespace viscera::sim

namespace viscera::render {

/// The thickness a thickness map's code 255 stands for (m), the G-buffer's thickness range.
inline constexpr float kThicknessMapRange = 0.05f;

struct RenderMesh {
    std::string name;
    uint32_t material = 0;    ///< index into SceneView::materials()
    bool doubleSided = false; ///< open surfaces (fascia): no culling, normal faces the viewer
    bool drawOnTop = false;   ///< polygon offset towards the camera (a layer lying on a body)
    bool visible = true;
    /// Authoring (the studio's paint tools): drawn through a 50 % screen door, every other pixel,
    /// so what lies inside the mesh (a curve skeleton) shows through it.
    bool translucent = false;
    /// The cavity mesh SceneView::addBodyCut made (its slots change with the cut; sample maps
    /// skip it, material maps of its body reach it).
    bool cutSurface = false;
    // ---- fixed at creation ----------------------------------------------------------------
    std::vector<uint32_t> indices; ///< #F × 3, counter-clockwise from outside
    std::vector<float> rest;       ///< #V × 3, m: rest positions (procedural pattern space)
    std::vector<float> thickness;  ///< #V, m: baked thickness [A §6.3.1]
    std::vector<float> sampleMap;  ///< #V: painted light samples (0 unpainted, else 1, 4 or 8)
    /// #V × 2 or empty: texture coordinates for the material's maps (none: triplanar on `rest`)
    std::vector<float> uv;
    /// #V or empty: for vertices split at UV seams (applyCornerUv), the first copy of each
    /// vertex: the copies' normals are accumulated there and shared, so a seam shades smoothly.
    std::vector<uint32_t> weld;
    /// Empty, or with `uv`: the thickness baked per texel (bakeThicknessTexture, R = thickness /
    /// 0.05 m), sampled by the G-buffer pass instead of the per-vertex `thickness`.
    Image thicknessMap;
    /// #V × 4 (RGBA) or empty: an authoring overlay (the studio's weight ramp) blended over the
    /// diffuse colour by its alpha. Set with SceneView::setOverlay.
    std::vector<float> overlay;
    // ---- per frame ------------------------------------------------------------------------
    std::vector<float> positions; ///< #V × 3, m, world frame
    std::vector<float> normals;   ///< #V × 3, unit, area-weighted vertex normals
    std::vector<float> heat;      ///< #V in [0, 1]: 0 fresh, ~0.5 coagulated, 1 charred
    /// Dissection [A §5.3.1]: empty (every face drawn) or #F flags, 0 = face not drawn. Set it
    /// with SceneView::setFaceMask (bumps faceMaskRevision); the backend then writes the visible
    /// faces' indices, compacted, into the same index buffer and draws only those (no buffer is
    /// created or resized).
    std::vector<uint8_t> faceMask;
    uint64_t faceMaskRevision = 0;
    uint64_t revision = 0;       ///< bumped whenever per-frame data change
    uint64_t staticRevision = 0; ///< bumped when sampleMap, thickness or overlay change
    // ---- where the per-frame positions come from -----------------------------------------
    enum class Source : uint8_t { Static, Body, Surface } source = Source::Static;
    size_t sourceIndex = 0;            ///< body or surface index in sim::World
    std::vector<int32_t> sourceVertex; ///< #V: node of the source for each render vertex

    size_t vertexCount() const { return positions.size() / 3; }
    size_t triangleCount() const { return indices.size() / 3; }
    /// Faces drawn: all without a mask, else the flagged ones. O(#F).
    size_t drawnTriangleCount() const;
    /// The indices of the drawn faces, in face order, into out (resized; #drawn × 3). O(#F).
    void drawnIndicesInto(std::vector<uint32_t>& out) const;
};

/// The boundary of a tet body at rest as a render mesh: positions and rest from `rest`'s nodes,
/// Source::Body with sourceIndex `body` and sourceVertex the boundary's node map; material 0, no
/// thickness baked. What SceneView::fromWorld draws for a body, and what the studio paints on.
RenderMesh bodySurfaceMesh(const sim::TetMesh& rest, const std::string& name, size_t body = 0);

class SceneView;
/// Adds a scenery surface (sim::SceneryDesc: drawn, never simulated) to `view` with the material
/// defaultMaterialFor(name), drawn from the side its triangles face only (a wall around the
/// working space does not hide the tissue from outside). Returns its mesh index.
size_t addScenery(SceneView& view, const std::string& name, const sim::TriMesh& mesh);

class SceneView {
public:
    SceneView() = default;

    /// The boundary of every body and every fascia surface of `world`, with a material from
    /// defaultMaterialFor(name) and thickness baked in the rest configuration (bodies against their
    /// own boundary, surfaces against all bodies). Cost: one BVH build and #V·rays ray casts.
    static SceneView fromWorld(const sim::World& world, const ThicknessBakeSettings& bake = {});

    /// Adds a static mesh (e.g. a generated organ surface), bakes its thickness against itself when
    /// it is closed (against `bakeTarget` when given). Returns its index.
    size_t addMesh(const std::string& name, const sim::TriMesh& mesh, uint32_t material,
                   const ThicknessBakeSettings& bake = {});
    uint32_t addMaterial(const TissueMaterial& material);

    /// Copies the current positions of `world` into the meshes that came from it and recomputes
    /// their normals, and applies the dissection face masks of surfaces the world cuts. Meshes whose
    /// source index is out of range are left as they are.
    void updateFromWorld(const sim::World& world);

    /// Sets the heat of every vertex of mesh `i` (values clamped to [0, 1]); `heat` has #V entries
    /// (std::invalid_argument otherwise).
    void setHeat(size_t i, const std::vector<float>& heat);
    /// Sets the overlay of mesh `i`: empty (none) or #V × 4 values (RGBA, clamped to [0, 1]);
    /// std::invalid_argument otherwise. Bumps staticRevision.
    void setOverlay(size_t i, const std::vector<float>& rgba);
    /// Sets the face mask of mesh `i` [A §5.3.1]: empty (draw every face) or one flag per
    /// triangle (#F entries, std::invalid_argument otherwise), nonzero = drawn. Allocation-free
    /// after the first call. Bumps the mesh's faceMaskRevision only when the mask changed.
    void setFaceMask(size_t i, const std::vector<uint8_t>& mask);
    /// Paints `samples` (1, 4 or 8; 0 erases) into the sample map of every vertex of every mesh
    /// within `radius` (m) of `centre` in the current positions.
    void paintSampleMap(const Eigen::Vector3f& centre, float radius, int samples);

    /// Bakes mesh i's thickness into a `size` × `size` texture in its UV space against the mesh
    /// itself at rest (bakeThicknessTexture, range kThicknessMapRange) and bumps its
    /// staticRevision. Throws std::invalid_argument when the mesh has no UVs. Returns the texels
    /// covered by a triangle.
    size_t bakeThicknessMap(size_t i, int size, const ThicknessBakeSettings& bake = {});

    /// Recomputes the normals of mesh i from its positions (allocation-free); bumps its revision.
    void recomputeNormals(size_t i);

    /// The cut surface of a dissected tet body [A §5.3.1]: adds a mesh of `capacity` face slots
    /// (Source::Body, same body and material as mesh `bodyMesh`, which must be the body's
    /// boundary as bodySurfaceMesh makes it) that setBodyCut fills with the faces a cut exposes.
    /// The topology never changes (each slot has its own three vertices, flat shaded); unused
    /// slots are masked out. Returns the new mesh's index. fromWorld adds one for every body the
    /// world's interaction dissects.
    static constexpr size_t kCutFaceCapacity = 16384;
    size_t addBodyCut(size_t bodyMesh, const sim::TetMesh& rest, size_t capacity = kCutFaceCapacity);
    /// Applies body `body`'s tet mask (1 intact, 0 cut; #T entries): the body's boundary faces
    /// whose tet is cut are dropped, and every face of an intact tet whose neighbour is cut is
    /// shown in the cut mesh, facing into the cavity (the first `capacity` of them, in tet
    /// order). The same mask as last time changes nothing; a body without addBodyCut or a mask
    /// of the wrong size is ignored. Positions follow with the next copy from the source.
    void setBodyCut(size_t body, const std::vector<uint8_t>& tetMask);
    /// Faces the last setBodyCut exposed for `body` (all of them, also past the capacity).
    size_t exposedCutFaces(size_t body) const;
    /// Sets the heat of mesh i from per-node heat of its source (through sourceVertex; a node
    /// out of range gets 0). Ignored unless the mesh has a source and heat per vertex.
    void setSourceHeat(size_t i, const std::vector<float>& nodeHeat);

    std::vector<RenderMesh>& meshes() { return m_meshes; }
    const std::vector<RenderMesh>& meshes() const { return m_meshes; }
    std::vector<TissueMaterial>& materials() { return m_materials; }
    const std::vector<TissueMaterial>& materials() const { return m_materials; }
    /// Axis-aligned bounds of the current positions of all visible meshes, {min, max}.
    std::array<Eigen::Vector3f, 2> bounds() const;

private:
    std::vector<RenderMesh> m_meshes;
    std::vector<TissueMaterial> m_materials;
    std::vector<uint8_t> m_maskScratch;    ///< updateFromWorld: the dissection mask of a surface
    std::vector<float> m_heatScratch;      ///< updateFromWorld: the heat of a dissected surface
    std::vector<uint8_t> m_tetMaskScratch; ///< updateFromWorld: a dissected body's tet mask
    struct BodyCut {
        size_t body = 0, bodyMesh = 0, cutMesh = 0, capacity = 0, exposed = 0;
        std::shared_ptr<const sim::TetMesh> rest; ///< level 3: opp() and the boundary's half-facets
        std::vector<uint8_t> lastMask;
    };
    std::vector<BodyCut> m_cuts;
};

} // namespace viscera::render
