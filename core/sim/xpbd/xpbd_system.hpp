#pragma once
/// Multi-layer soft tissue for XPBD [A §4.2, §4.3.4, §4.4.2]: several bodies and all their
/// constraints in one coloured system.
///
/// Bodies:
///   - tet bodies (fat, embedded tissue such as vessels or nerves): elasticity from any
///     TetConstraintModel with per-node stiffness weights, optional anisotropic strain limits;
///   - surface bodies (fascia, membranes): triangles with their own particles, a membrane stretch
///     model (membrane.hpp) and optional strain limits in the UV frame.
/// Couplings (coupling.hpp), two-way, hard or compliant:
///   - surface attachment: every surface vertex within maxDistance of a tet body's boundary is
///     tied to its closest boundary point (barycentric on a boundary triangle) [A eq. 4.1];
///   - embedding: every node of an embedded tet body is tied to the cage tet of another body that
///     contains it (barycentric in that tet), the shared-tetrahedron idea of [A Fig. 4.2].
///
/// Solver: one particle array for all bodies; each frame runs substeps × iterations of
/// Gauss–Seidel XPBD over all constraints [A eq. 4.43–4.44], multipliers restarted each substep,
/// with velocity damping, a speed clamp and rollback of a non-finite frame (XpbdSettings). All
/// constraints are greedy-coloured by shared particles and each colour is split over
/// settings.threads threads; results are bit-identical for every thread count. Sweep order:
/// elasticity and membranes, then strain limits, then ties, each with colours of its own, so
/// that limits and ties have the last word in every sweep (one iteration per substep leaves
/// hard ties satisfied to ~1e-5 m in the tests). Stability and equilibrium limits of the
/// method: see xpbd_solver.hpp.
///
/// Masses: tet bodies density · V / 4 per tet node, surfaces arealDensity · A / 3 per triangle
/// vertex. An embedded body's mass adds to its cage's (give it the density difference to the
/// host tissue when that matters).
#include "sim/material/constraint_model.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"
#include "sim/xpbd/strain_limit.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {

namespace detail {
class Engine;
class WorkerPool;
} // namespace detail

struct TetBodyDesc {
    std::string name;                                ///< used in messages
    const TetMesh* mesh = nullptr;                   ///< rest state; non-owning, read during create only
    std::shared_ptr<const TetConstraintModel> model; ///< elasticity (count() 1 or 2)
    double density = 1050.0;                         ///< kg/m^3
    std::vector<int32_t> fixedNodes;                 ///< held where they are (see setTetState)
    /// Empty (all 1) or one stiffness weight per node (> 0); a tet's weight is the mean of its
    /// four nodes' and divides its compliances (α/w) [A §4.3.5].
    std::vector<double> nodeWeights;
    std::optional<TetStrainLimits> strainLimits;
};

struct SurfaceBodyDesc {
    std::string name;
    const TriMesh* mesh = nullptr;  ///< rest state; non-owning, read during create only
    std::vector<Vec2> uv;           ///< empty or one per vertex; needed by strainLimits
    double arealDensity = 0.1;      ///< kg/m^2 (e.g. 1000 kg/m^3 × 0.1 mm)
    double stretchStiffness = 50.0; ///< membrane k, N/m (≈ Young's modulus × thickness); 0 = none
    std::vector<int32_t> fixedNodes;
    /// Empty (all 1) or one stiffness weight per vertex (> 0), painted on the layer's triangles
    /// [A §4.3.5, Fig. 4.11]; a triangle's k is stretchStiffness × the mean of its three weights.
    std::vector<double> nodeWeights;
    std::optional<TriStrainLimits> strainLimits;
};

struct SurfaceAttachmentDesc {
    size_t surface = 0;        ///< index into XpbdSystemDesc::surfaces
    size_t tetBody = 0;        ///< index into XpbdSystemDesc::tetBodies
    double maxDistance = 1e-3; ///< m; surface vertices farther from the boundary stay free
    double compliance = 0;     ///< m/N; 0 = hard
    /// Move each tied surface vertex onto its boundary point before anything else is computed,
    /// so that the rest state is a fixed point of the ties.
    bool snap = true;
};

struct EmbeddingDesc {
    size_t embedded = 0;     ///< tet body whose nodes are tied (index into tetBodies)
    size_t cage = 0;         ///< tet body that contains them
    double compliance = 0;   ///< m/N; 0 = hard
    double tolerance = 1e-6; ///< m; nodes outside the cage by at most this are tied to the nearest tet
};

struct XpbdSystemDesc {
    std::vector<TetBodyDesc> tetBodies;
    std::vector<SurfaceBodyDesc> surfaces;
    std::vector<SurfaceAttachmentDesc> attachments;
    std::vector<EmbeddingDesc> embeddings;
};

class XpbdSystem {
public:
    /// Throws viscera::PreconditionError, a std::invalid_argument whose rule has no function
    /// prefix (sim/util/error.hpp) ("sim::XpbdSystem::create(): tet body 1 ('vessel'): tet 3
    /// has non-positive rest volume -1e-9 m^3") on invalid settings, a missing mesh or model, a
    /// model with other than 1 or 2 constraints, bad density, weights, fixed nodes or strain
    /// limits, a degenerate element, an attachment that ties nothing, an embedded node outside its
    /// cage, or a system without a free particle.
    static std::unique_ptr<XpbdSystem> create(const XpbdSystemDesc& desc, const XpbdSettings& settings);
    ~XpbdSystem();
    XpbdSystem(const XpbdSystem&) = delete;
    XpbdSystem& operator=(const XpbdSystem&) = delete;

    /// Advances one frame (settings().dt). Never throws; a non-finite result is rolled back.
    StepStats step();

    size_t tetBodyCount() const { return m_tet.size(); }
    size_t surfaceCount() const { return m_surf.size(); }
    const std::string& tetBodyName(size_t b) const { return m_tet[b].name; }
    const std::string& surfaceName(size_t s) const { return m_surf[s].name; }
    const std::vector<Vec3>& tetPositions(size_t b) const { return m_tet[b].x; }  ///< #V, m
    const std::vector<Vec3>& tetVelocities(size_t b) const { return m_tet[b].v; } ///< #V, m/s
    const std::vector<Vec3>& surfacePositions(size_t s) const { return m_surf[s].x; }
    const std::vector<Vec3>& surfaceVelocities(size_t s) const { return m_surf[s].v; }
    /// Per-tet stiffness weights of tet body b (mean of the node weights).
    const std::vector<double>& tetWeights(size_t b) const { return m_tet[b].tetWeight; }

    /// Teleports a body (x and v: #V each, finite); fixed nodes are then held at the new x.
    /// Between frames only. Throws viscera::PreconditionError on a size mismatch or non-finite
    /// value.
    void setTetState(size_t b, const std::vector<Vec3>& x, const std::vector<Vec3>& v);
    void setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v);

    // ---- dissection [A §5.3]: per-element switches, between frames, O(1) each ----------------
    /// Element counts of tet body b and surface s.
    size_t tetCount(size_t b) const { return m_tet.at(b).elems.size(); }
    size_t triangleCount(size_t s) const { return m_surf.at(s).elems.size(); }
    /// Switches the elasticity of tet t of body b on or off, together with its strain limits. An
    /// inactive (cut) tet exerts no force and stores no energy; its nodes keep their mass, so a
    /// node whose tets are all cut moves freely. Throws std::out_of_range on a bad b or t.
    void setTetActive(size_t b, size_t t, bool active);
    bool tetActive(size_t b, size_t t) const;
    /// Holds node v of tet body b where it is from now on (inverse mass 0, velocity 0), as a fixed
    /// node: dissection holds a node whose tets are all cut. Throws std::out_of_range on a bad b or v.
    void holdTetNode(size_t b, size_t v);
    /// Shrinkage [A §5.3.3, eq. 5.12]: with F = Fe·Fs the elastic part is measured from the rest
    /// edge matrix Fs·Dm₀ (Dm₀: the rest shape at create(); not cumulative, Fs = I restores it).
    /// Fs is a 3 × 3 matrix in the world rest frame, finite with det Fs > 0. The energy stays
    /// integrated over the creation rest volume (compliance unchanged). The tet's strain limits
    /// are switched off while Fs ≠ I (burnt tissue). Throws std::invalid_argument on a bad Fs.
    void setTetRestShape(size_t b, size_t t, const Mat3& Fs);
    /// The same for triangle t of surface s (membrane constraints and strain limits).
    void setTriangleActive(size_t s, size_t t, bool active);
    bool triangleActive(size_t s, size_t t) const;
    /// Shrinkage of triangle t of surface s: its rest triangle becomes x₀ + Fs (xₖ − x₀) (rest
    /// positions, world frame; not cumulative); throws std::invalid_argument when that triangle is
    /// degenerate or Fs is not finite.
    void setTriangleRestShape(size_t s, size_t t, const Mat3& Fs);

    /// Number of coupling ties (attachments and embeddings).
    size_t tieCount() const { return m_ties.size(); }
    /// Largest |x_p − Σ b_k x_k| over all ties, m (0 without ties).
    double maxTieGap() const;
    /// Inertia that hard ties (compliance 0) add to the nodes of tet body b, kg (one per node; 0
    /// where a node is not hard-tied; +inf where it is tied to fixed nodes only). A node tied to the
    /// point Σ b_k x_k of another body (an embedded node to its cage tet) moves with that point
    /// within every sweep (the tie stage follows elasticity), so its own constraints move its mass
    /// plus the point's, 1 / Σ_k b_k B_k / m_k: node k's mass m_k is shared among all the ties that
    /// use it in proportion to their weights (B_k: the sum of those weights), so that no mass counts
    /// twice. The load-time stability check (stability_check.hpp) divides by it. O(ties).
    std::vector<double> tiedInertia(size_t b) const;

    /// Selective inertia scaling (XpbdSettings::inertiaScaling): node i of tet body b moves with
    /// inertia m_i + extra[i] instead of its lumped mass m_i, and feels the fraction
    /// m_i / (m_i + extra[i]) of gravity, so that its weight m_i g (and every static equilibrium)
    /// is unchanged; only its dynamics slow down. extra: #V values, finite and ≥ 0 (a fixed node
    /// keeps inverse mass 0 and only records its value, which addedInertia returns); all zero
    /// restores the plain masses. Between frames. The kinetic energy counts the scaled inertia,
    /// the potential energy the weight. Throws viscera::PreconditionError on a size mismatch or a
    /// bad value. O(#V).
    void setAddedInertia(size_t b, const std::vector<double>& extra);
    /// The extra inertia of tet body b's nodes, kg (#V; zeros unless set).
    std::vector<double> addedInertia(size_t b) const;

    /// J: elasticity, membranes, compliant ties and strain limits, relative to rest. Summed on the
    /// system's worker threads: not concurrently with step() or another elasticEnergy().
    double elasticEnergy() const;
    double kineticEnergy() const;   ///< J
    double potentialEnergy() const; ///< J, gravity relative to the rest configuration
    double totalMass() const;       ///< kg

    const XpbdSettings& settings() const { return m_settings; }
    int colourCount() const;

    /// Installs (or, with an empty function, removes) a hook called after every sweep of every
    /// substep with the particles at the current iterate, and once per substep after its
    /// velocity update (XpbdIterationHook; e.g. tool contacts
    /// from sim/collision, makeCollisionHook). Between frames only. Without a hook step() runs
    /// exactly as before (bit-identical, same schedule).
    void setIterationHook(XpbdIterationHook hook);
    /// Whether the next frames call the hook (true after setIterationHook). A frame without the
    /// hook runs the schedule of a system without one (the end and start of each substep in one
    /// pass, no hook phases): for frames in which the hook has nothing to do.
    void setIterationHookActive(bool active);
    /// The particles the hook reads and writes: [first, first + count) of its XpbdParticles
    /// (setIterationHook resets it to all). A hook that touches only part of the particles lets
    /// the rest end each substep beside it instead of after it; touching any other particle is
    /// then a data race.
    void setIterationHookParticles(size_t first, size_t count);
    /// First particle index of tet body b / surface s in the XpbdParticles of a hook.
    int32_t tetParticleOffset(size_t b) const { return m_tet.at(b).first; }
    int32_t surfaceParticleOffset(size_t s) const { return m_surf.at(s).first; }
    /// True when the stable Neo-Hookean AVX2 kernel runs (settings().simd and CPU support).
    bool usesSimd() const { return m_simd; }

private:
    friend class XpbdSolver;
    struct Range {
        std::string name;
        int32_t first = 0;      ///< first particle
        std::vector<Vec3> x, v; ///< mirrors of the particle state, refreshed after step()
        std::vector<double> tetWeight;
        // Dissection: element vertices (global particles), blocks holding them (−1: none) and
        // the element → unit map of the strain-limit block (−1: not limited).
        std::vector<std::array<int32_t, 4>> elems;
        int elasticBlock = -1, strainBlock = -1;
        std::vector<int32_t> strainUnit;
        std::vector<uint8_t> active, reshaped;
    };
    void syncStrainUnit(Range& r, size_t t);
    struct TieRecord {
        int32_t p;
        std::array<int32_t, 4> t;
        std::array<double, 4> b;
        int n;
        double compliance;
    };
    XpbdSystem();
    static std::unique_ptr<XpbdSystem> build(const XpbdSystemDesc& desc, const XpbdSettings& settings,
                                             const std::string& where, bool singleBody);
    void refreshMirrors();
    void setState(Range& r, const std::vector<Vec3>& x, const std::vector<Vec3>& v, const char* what);

    XpbdSettings m_settings;
    std::unique_ptr<detail::Engine> m_engine;
    std::unique_ptr<detail::WorkerPool> m_pool;
    std::vector<Range> m_tet, m_surf;
    std::vector<Vec3> m_rest; ///< all particles, rest positions
    std::vector<TieRecord> m_ties;
    std::vector<double> m_added; ///< empty, or one per particle: extra inertia, kg
    bool m_simd = false;
};

} // namespace viscera::sim
