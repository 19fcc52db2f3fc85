#pragma once
/// Energized dissection of fascia (triangles) and fat (tets) in an XpbdSystem [A §5.3].
///
/// Each frame, update(tool, dt):
///   1. heat: the tool-centred grid (heat_grid.hpp) follows the tool tip and advances dt;
///   2. edge heat [A eq. 5.11]: for every intact edge that overlaps the tool's implicit sphere
///      during the frame, τ_e += ξ · (u_a + u_b)/2 · δt / t_ref (see "units" below);
///   3. cut: an edge with τ_e ≥ δ (ignition) is dissected; the share_count of every primitive
///      around it drops by one (edge_structure.hpp) and a primitive whose share_count leaves its
///      initial value is switched off in the XPBD system (no elasticity, not rendered);
///   4. shrinkage [A §5.3.3, eq. 5.12]: every intact primitive that shares an edge with a freshly
///      cut one gets, once, the rest shape Fs·Dm with Fs = Rᵀ diag(Sx, Sy, Sz) R in the contact
///      frame: Nc = ∇f at the contact point x_c (where the line from the tool centre to the
///      element centre meets the sphere), Na = Nf × Nc, Nb = Nc × Na, with Nf the element's face
///      normal (a tet: its face nearest the tool); R's rows are (Nc, Na, Nb), so Sx shrinks
///      perpendicular to the contact surface. Nc and Nf are taken in the current configuration.
/// No vertex is created or removed: vertex counts never change.
///
/// Units of eq. 5.11. τ_e = (u_a + u_b) ξ Δt / 2 multiplies a temperature by the overlap time, yet
/// is compared with an ignition temperature. We read Δt as the overlap time counted in reference
/// frames, Δt / t_ref with t_ref = 1/60 s (the frame time of the thesis' fascia scene), and
/// accumulate it with the temperature of each moment: τ_e = Σ ξ ū_e δt / t_ref, in °C (equal to
/// eq. 5.11 while ū_e is constant). With the thesis parameters (tool 170 °C, ξ = 0.4, δ = 160 °C)
/// an edge held at the tool temperature burns through after 160 / (0.4 · 170) = 2.35 reference
/// frames, ≈ 40 ms of contact; an edge touching the sphere only at its cooler rim needs a few
/// frames more, and one held at body temperature never gets there in a brief touch (0.4 · 37 =
/// 14.8 per frame). The overlap time δt ∈ [0, dt] is exact for a tool moving on a straight line
/// during the frame: the distance from the moving centre to the edge is convex in time, so the
/// overlap is one interval, found by bisection on each side of the closest approach (a fast
/// tool cannot tunnel through an edge).
///
/// Edge springs of fully cut edges ([A §5.3.3], end) are not modelled: an orphaned edge simply
/// has no primitive left.
///
/// Temperatures °C, lengths m, times s. Serial and deterministic (repeat runs are bit-identical).
/// Cost per frame: O(N³ · substeps) for the grid + O(#edges) for the overlap test (AABB reject) +
/// O(primitives around new cuts).
#include "sim/dissection/edge_structure.hpp"
#include "sim/dissection/heat_grid.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include <array>
#include <memory>
#include <optional>
#include <vector>

namespace viscera::sim {

/// Per-tissue parameters [A §5.3.4].
struct TissueDissectionParams {
    double ignition = 160.0;           ///< δ, °C (compared with τ_e, eq. 5.11)
    double conductivity = 0.4;         ///< ξ, dimensionless, > 0: how much heat the tissue absorbs
    Vec3 shrink = Vec3(0.1, 0.3, 1.0); ///< (Sx, Sy, Sz), each in [0.01, 10] (1 = no shrink)
    bool shrinkage = true;             ///< apply eq. 5.12 to the primitives next to a fresh cut
};

/// Fascia defaults from [A §5.3.4] (ignition 160 °C, ξ = 0.4, Sx = 0.1, Sy = 0.3).
inline TissueDissectionParams fasciaDissectionDefaults() {
    return {160.0, 0.4, Vec3(0.1, 0.3, 1.0), true};
}
/// Fat defaults from [A §5.3.4] (ignition 78 °C, ξ = 0.6, Sx = 0.1, Sy = Sz = 1).
inline TissueDissectionParams fatDissectionDefaults() {
    return {78.0, 0.6, Vec3(0.1, 1.0, 1.0), true};
}

struct DissectionDesc {
    XpbdSystem* system = nullptr; ///< non-owning; must outlive the Dissection
    /// Fascia: surface index in the system and its mesh (the TriMesh given to create(); same
    /// vertex count and triangles). Null mesh: no fascia layer.
    const TriMesh* fascia = nullptr;
    size_t surface = 0;
    TissueDissectionParams fasciaTissue = fasciaDissectionDefaults();
    /// Fat: tet body index and its mesh. Null: no fat layer.
    const TetMesh* fat = nullptr;
    size_t tetBody = 0;
    TissueDissectionParams fatTissue = fatDissectionDefaults();
    HeatGridSettings grid;
    double referenceTime = 1.0 / 60.0; ///< t_ref of eq. 5.11, s (> 0)
};

/// The energy tool's tip for one frame.
struct EnergyTool {
    Vec3 centre = Vec3::Zero(); ///< sphere centre, m, world frame
    double radius = 1e-3;       ///< m (> 0)
    double temperature = 170.0; ///< °C (>= −273.15)
    bool energized = true;      ///< false: no heat source, no edge heating (the grid cools)
};

struct DissectionLayerStats {
    size_t edgesTouched = 0;       ///< intact edges overlapping the tool this frame
    size_t edgesCut = 0;           ///< dissected this frame
    Vec3 cutCentre = Vec3::Zero(); ///< m: the mean midpoint of the edges dissected this frame (0 without any)
    size_t primitivesCut = 0;      ///< became cut this frame
    size_t primitivesShrunk = 0;   ///< rest shape changed this frame
    size_t totalEdgesCut = 0;
    size_t totalPrimitivesCut = 0;
    size_t vertexCount = 0; ///< never changes
    double maxEdgeHeat = 0; ///< largest τ_e over intact edges, °C
};

struct DissectionFrameStats {
    DissectionLayerStats fascia, fat;
    /// shear(): the wedge the blades swept (clevis, one tip, the other) when it cut anything.
    std::optional<std::array<Vec3, 3>> swept;
    int heatSubsteps = 0;
    double gridMin = 0, gridMax = 0; ///< °C
};

class Dissection {
public:
    /// Throws std::invalid_argument ("sim::Dissection::create(): fascia: surface 2 does not
    /// exist") on a null system, no layer, a body index out of range, a mesh whose vertex or
    /// element count differs from the system's, bad tissue parameters, grid settings or t_ref.
    static std::unique_ptr<Dissection> create(const DissectionDesc& desc);
    Dissection(const Dissection&) = delete;
    Dissection& operator=(const Dissection&) = delete;

    /// One frame of dt seconds (call before XpbdSystem::step()). Reads the current positions of
    /// the system and switches/reshapes its elements. Throws std::invalid_argument (changing
    /// nothing) on a non-finite or out-of-range tool or dt ≤ 0; valid input never throws.
    DissectionFrameStats update(const EnergyTool& tool, double dt);
    /// A cold cut (scissors closing): every edge of each layer that passes within `radius` of the
    /// wedge the blades sweep as they shut, the triangle clevis–tipA–tipB (m, world frame; the two
    /// tips where the open blades' tips were), is cut at once, with no heat and no shrinking.
    /// tipA = tipB: one blade, the segment clevis–tip. Throws std::invalid_argument (changing
    /// nothing) on a non-finite point or radius ≤ 0.
    DissectionFrameStats shear(const Vec3& clevis, const Vec3& tipA, const Vec3& tipB, double radius);

    bool hasFascia() const { return m_fascia.has_value(); }
    bool hasFat() const { return m_fat.has_value(); }
    /// Edge structures (std::logic_error when the layer is absent).
    const EdgeStructure& fasciaEdges() const;
    const EdgeStructure& fatEdges() const;
    /// τ_e per edge, °C (eq. 5.11 as above).
    const std::vector<double>& fasciaEdgeHeat() const;
    const std::vector<double>& fatEdgeHeat() const;
    /// Render masks [A §5.3.1]: 1 for every intact triangle (fascia) / tet (fat), in mesh order.
    void fasciaFaceMaskInto(std::vector<uint8_t>& out) const;
    /// Heat of every fascia vertex for the renderer's heat channel, in [0, 1]: the largest τ_e of
    /// its edges over the ignition temperature (1 where an edge burnt through: charred).
    void fasciaVertexHeatInto(std::vector<float>& out) const;
    /// The same for the fat's nodes (its cut surface shows the heat).
    void fatVertexHeatInto(std::vector<float>& out) const;
    void fatTetMaskInto(std::vector<uint8_t>& out) const;
    /// Mask of the fat mesh's boundary triangles (TetMesh::boundary() order, which is the order of
    /// the render mesh SceneView makes for a tet body): 1 while the tet behind the face is intact.
    /// Faces inside the block that a cut exposes are not part of that mesh. Needs the fat mesh at
    /// adjacency level 3 when create() ran (std::logic_error otherwise).
    void fatBoundaryMaskInto(std::vector<uint8_t>& out) const;
    const HeatGrid& heat() const { return m_heat; }

private:
    struct Layer {
        bool tets = false;
        size_t body = 0;
        TissueDissectionParams tissue;
        EdgeStructure edges;
        std::vector<double> heat;    ///< τ_e
        std::vector<uint8_t> shrunk; ///< per primitive
        std::vector<std::array<int32_t, 4>> prims;
        std::vector<int32_t> liveTets; ///< tets: per node, its tets not cut yet
    };
    explicit Dissection(const HeatGridSettings& grid) : m_heat(grid) {}
    void updateLayer(Layer& L, const EnergyTool& tool, const Vec3& from, double dt, DissectionLayerStats& st);
    /// Cuts `edges` of L (those not cut yet), switches off the elements that lost an edge and,
    /// with `shrinkBy`, shrinks their neighbours [A eq. 5.12]; the layer's totals into `st`.
    void cutEdges(Layer& L, const std::vector<int32_t>& edges, const EnergyTool* shrinkBy, DissectionLayerStats& st);
    Mat3 shrinkFrame(const Layer& L, const std::vector<Vec3>& x, size_t p, const EnergyTool& tool) const;

    XpbdSystem* m_sys = nullptr;
    std::optional<Layer> m_fascia, m_fat;
    HeatGrid m_heat;
    double m_tref = 1.0 / 60.0;
    std::optional<Vec3> m_prevCentre;
    std::vector<int32_t> m_fatBoundaryTet; ///< tet behind each boundary triangle of the fat mesh
    bool m_hasFatBoundary = false;
    std::vector<int32_t> m_newlyCut;
};

} // namespace viscera::sim
