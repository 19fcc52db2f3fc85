#pragma once
/// Geometric clip [A §5.4]: a clip applied to a vessel follows the local rigid motion of the
/// clipped region, without rigid-body dynamics and without changing the simulation.
///
/// At application (ClipAttachment::apply) the clipped region is identified with the clip's
/// bounds (box or sphere, world frame) in the vessel's current positions:
///   - vessel vertices inside the bounds, and
///   - virtual auxiliary nodes [A §5.4]: one fixed barycentric pattern of k points, used in
///     every tet of the vessel and kept where it falls inside the bounds. The pattern is the
///     first k points of the Halton sequence (bases 2, 3, 5) in the unit cube folded into the
///     tet (Rocchini–Cignoni folding: uniform, all points inside, no two at the same height, so
///     that even a thin clip slab catches points at several depths, which a regular lattice
///     does not). Each node keeps its tet and barycentric coordinates and follows that tet each
///     frame, so a coarse mesh with few or no vertices under the clip still defines the region's
///     motion.
/// Per-node weights (the documented choice): with s the node's normalised distance from the
/// bounds' centre (sphere: |p − c| / r; box: |Lᵀ(p − c) ⊘ h| / √3, so s = 1 on the sphere and at
/// the box corners) w = f + (1 − f)(1 − s²)², f = ClipSettings::weightFloor: a smooth bump,
/// 1 at the centre, f at the boundary, never zero.
///
/// Every frame (update) the MLS transform from the rest configuration X′ to the current one x′
/// about the weighted centres is [A eq. 5.15]
///   A = [Σ w_i (x′_i − x′_cm)(X′_i − X′_cm)ᵀ] [Σ w_i (X′_i − X′_cm)(X′_i − X′_cm)ᵀ]⁺
/// (the right factor is constant and pseudo-inverted once at application: eigenvalues below
/// 1e-6 of the largest count as zero, so a coplanar region gives a rank-2 A instead of
/// infinities). Its rotation R is kept across frames and refined by the exponential-map update
/// [A eq. 5.17–5.18] (exp_map_rotation.hpp); if the warm-started R ends more than 90° from A
/// (tr(RᵀA) < 0, e.g. a 180° flip within one frame, where the update has a saddle) it is
/// re-seeded from the polar decomposition (counted in fallbackCount()).
///
/// Clip pose. [A eq. 5.16] moves the clip with the region's rotation about the region centre
/// plus the centre's translation. The clip is placed in the *deformed* configuration at
/// application, where the region already has rotation R₀ from rest, so the transform
/// implemented is, for a clip point p₀ given at application:
///   p(t) = Q(t) (p₀ − x′_cm(0)) + x′_cm(t),      Q(t) = R(t) R₀ᵀ,
/// i.e. the rotation relative to the application pose about the region centre, then the centre's
/// translation x′_cm(t) − x′_cm(0). All clip points (render vertices, contact points, the jaw
/// normal) move rigidly with this one transform.
///
/// Units metres, world frame (the frame of the positions passed in). Cost per update
/// O(#region vertices + #auxiliary nodes + #clip points), allocation-free.
#include "sim/clip/exp_map_rotation.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace viscera::sim {

/// The clip's bounding volume at application, world frame.
struct ClipBounds {
    Vec3 centre = Vec3::Zero();      ///< m
    Mat3 axes = Mat3::Identity();    ///< box axes as orthonormal columns (box only)
    Vec3 halfExtents = Vec3::Zero(); ///< box half sizes along the axes, m (box only)
    double radius = 0;               ///< > 0: a sphere of this radius (axes/halfExtents unused)

    static ClipBounds box(const Vec3& centre, const Mat3& axes, const Vec3& halfExtents);
    static ClipBounds sphere(const Vec3& centre, double radius);
    bool isSphere() const { return radius > 0; }
    bool contains(const Vec3& p) const;
    /// Normalised distance s from the centre (see the header comment); > 1 outside a sphere.
    double normalisedDistance(const Vec3& p) const;
};

struct ClipDesc {
    ClipBounds bounds;               ///< clipped region at application
    std::vector<Vec3> vertices;      ///< clip render vertices at application, m (may be empty)
    std::vector<Vec3> contactPoints; ///< inner-jaw points touching the vessel at application, m
    Vec3 jawNormal = Vec3::UnitY();  ///< direction in which the jaws close (normalised), world
};

struct ClipSettings {
    int auxiliaryPerTet = 10; ///< auxiliary pattern points per tet, in [0, 64] (0: none)
    double weightFloor = 0.1; ///< w at the bounds' boundary, in (0, 1]
    /// Per-frame exp-map update [A eq. 5.17–5.18], warm-started from the previous frame. Each
    /// iteration shrinks the error of R about the k-th principal axis of the stretch S (A = R S)
    /// by the factor s_k / tr S (1/3 for a rigid region, 1/2 about the in-plane axes of a
    /// coplanar one), so a region turning by δ per frame lags by about δ ρⁿ / (1 − ρⁿ) after n
    /// iterations (ρ the largest factor): 10 iterations keep a rigid region within 2e-5 δ.
    ExpMapOptions rotation{10, 1e-9, 1e-12};
};

/// Result of one update; on anything but Ok the pose of the previous frame is kept.
enum class ClipUpdateStatus { Ok, NonFiniteInput, SizeMismatch };

/// A virtual auxiliary node: a fixed point of one vessel tet.
struct AuxiliaryNode {
    int32_t tet = 0;
    std::array<int32_t, 4> nodes{}; ///< the tet's vertices
    Eigen::Vector4d bary = Eigen::Vector4d::Constant(0.25);
};

class ClipAttachment {
public:
    /// Applies a clip. `vessel` is the rest mesh (X), `positions` the vessel's current positions
    /// (#V, m) at application. Throws std::invalid_argument ("sim::ClipAttachment::apply(): ...")
    /// on a size mismatch, non-finite positions or clip points, bounds that are not finite or not
    /// positive (or box axes that are not orthonormal within 1e-6), a zero jaw normal, bad
    /// settings, or a region that contains no vessel vertex and no auxiliary node.
    static std::unique_ptr<ClipAttachment> apply(const TetMesh& vessel, const std::vector<Vec3>& positions,
                                                 const ClipDesc& clip, const ClipSettings& settings = {});
    ClipAttachment(const ClipAttachment&) = delete;
    ClipAttachment& operator=(const ClipAttachment&) = delete;

    /// Follows the vessel: MLS transform, exp-map rotation, clip pose, clip points. Never throws;
    /// non-finite region positions or a wrong size leave the pose unchanged and are reported.
    ClipUpdateStatus update(const std::vector<Vec3>& positions);

    // ---- pose --------------------------------------------------------------------------------
    const Mat3& transform() const { return m_A; }                    ///< A of [A eq. 5.15], rest → current
    const Mat3& rotation() const { return m_R; }                     ///< R (rest → current), exp-map state
    const Mat3& applicationRotation() const { return m_R0; }         ///< R₀ at application
    Mat3 relativeRotation() const { return m_R * m_R0.transpose(); } ///< Q = R R₀ᵀ
    const Vec3& centre() const { return m_centre; }                  ///< x′_cm(t), m
    const Vec3& applicationCentre() const { return m_centre0; }      ///< x′_cm(0), m
    const Vec3& restCentre() const { return m_restCentre; }          ///< X′_cm, m
    /// p(t) = Q (p₀ − x′_cm(0)) + x′_cm(t) for a point p₀ given at application.
    Vec3 transformPoint(const Vec3& pAtApplication) const;

    // ---- clip points (current) ---------------------------------------------------------------
    const std::vector<Vec3>& vertices() const { return m_vertices; }
    const std::vector<Vec3>& contactPoints() const { return m_contacts; }
    const std::vector<Vec3>& applicationVertices() const { return m_vertices0; }
    const std::vector<Vec3>& applicationContactPoints() const { return m_contacts0; }
    Vec3 jawNormal() const { return relativeRotation() * m_jawNormal0; } ///< unit, current

    // ---- region ------------------------------------------------------------------------------
    const std::vector<int32_t>& regionVertices() const { return m_regionVertices; }
    const std::vector<AuxiliaryNode>& auxiliaryNodes() const { return m_aux; }
    /// Weights: region vertices first, then auxiliary nodes.
    const std::vector<double>& weights() const { return m_weights; }
    /// Rank of the rest covariance Σ w (X′ − X′_cm)(X′ − X′_cm)ᵀ (3 normally, 2 coplanar, ...).
    int regionRank() const { return m_rank; }
    /// Current positions x′ of the auxiliary nodes (computed from `positions`).
    void auxiliaryPositionsInto(const std::vector<Vec3>& positions, std::vector<Vec3>& out) const;

    // ---- diagnostics -------------------------------------------------------------------------
    int lastIterations() const { return m_lastIterations; } ///< exp-map updates in the last frame
    int fallbackCount() const { return m_fallbacks; }       ///< polar re-seeds since application
    int rejectedCount() const { return m_rejected; }        ///< updates rejected since application
    size_t vesselVertexCount() const { return m_vertexCount; }
    const ClipSettings& settings() const { return m_settings; }

private:
    ClipAttachment() = default;
    /// x′_cm = Σ w x′ / Σ w and Apq = Σ w (x′ − x′_cm)(X′ − X′_cm)ᵀ in one pass about `ref`;
    /// false if non-finite.
    bool accumulate(const std::vector<Vec3>& x, const Vec3& ref, Vec3& centre, Mat3& Apq) const;
    void placeClipPoints();

    ClipSettings m_settings;
    size_t m_vertexCount = 0;
    std::vector<int32_t> m_regionVertices;
    std::vector<AuxiliaryNode> m_aux;
    std::vector<double> m_weights;   ///< vertices, then auxiliary nodes
    std::vector<Vec3> m_restOffsets; ///< X′_i − X′_cm, same order
    double m_weightSum = 0;
    Vec3 m_offsetSum = Vec3::Zero(); ///< Σ w (X′ − X′_cm), zero up to round-off
    Mat3 m_AqqPinv = Mat3::Zero();
    int m_rank = 0;
    Vec3 m_restCentre = Vec3::Zero(), m_centre0 = Vec3::Zero(), m_centre = Vec3::Zero();
    Mat3 m_A = Mat3::Identity(), m_R = Mat3::Identity(), m_R0 = Mat3::Identity();
    Vec3 m_jawNormal0 = Vec3::UnitY();
    std::vector<Vec3> m_vertices0, m_contacts0, m_vertices, m_contacts;
    int m_lastIterations = 0, m_fallbacks = 0, m_rejected = 0;
};

} // namespace viscera::sim
