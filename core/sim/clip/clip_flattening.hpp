#pragma once
/// Visual flattening of a clipped vessel [A eq. 5.19]: render vertices near the clip are pushed
/// towards the vessel's skeleton curve, between the jaws, just before rendering. Only the copy of
/// the positions handed to the renderer changes, never the simulated positions.
///
/// For a render vertex x_i, with x_iᴾ and x_cmᴾ the closest points of the skeleton polyline to
/// x_i and to the clip region's centre x′_cm, s_i = |x_iᴾ − x_cmᴾ|, ρ_i = |x_i − x_iᴾ|,
/// r̂_i = (x_i − x_iᴾ)/ρ_i and n the clip's current jaw normal (the direction the jaws close):
///   factor  f_i = η / max(s_i, s₀)^γ − η / s_max^γ        for s_i < s_max, else 0
///   d_i = −min(f_i, κ ρ_i) (r̂_i · n) n
/// The factor is that of [A eq. 5.19] (η intensity, γ fading), with the denominator clamped at
/// s₀ (no division by zero at the centre) and shifted so that it reaches 0 at the influence
/// radius s_max (no visible seam where the effect ends). The direction is the documented choice
/// for a clip: [A eq. 5.19]'s radial unit direction (x_i − x_iᴾ)/ρ_i, reduced to its component
/// along the jaw normal and pointed towards the skeleton, so the vessel is squeezed between the
/// jaws (a radial direction alone would shrink or inflate the tube uniformly, not flatten it).
/// The magnitude is capped at κ ρ_i (κ = maxSqueeze < 1): a vertex never crosses the jaws'
/// mid-plane, vertices keep their order along every radial ray (new height (ρ − min(f, κρ)) cos θ
/// is increasing in ρ), and a vertex on the skeleton (ρ_i below 1e-12 m) is left where it is.
///
/// Skeleton: a polyline (≥ 2 points) given at application in the same frame as the vessel. By
/// default it is carried rigidly with the clip (the clip's own transform, exact near the clip,
/// which is the only place that matters); an overload takes the current polyline instead (e.g.
/// one deformed by following the vessel). Cost per frame O(#candidates × #kept segments).
#include "sim/clip/clip_attachment.hpp"

#include <memory>
#include <vector>

namespace viscera::sim {

struct FlattenSettings {
    double eta = 2e-6;         ///< η, intensity, m^(1+γ) (f is in metres)
    double gamma = 1.0;        ///< γ, fading exponent (> 0; the shifted factor vanishes at γ = 0)
    double minDistance = 1e-3; ///< s₀, m (> 0): clamp of the denominator
    double influence = 6e-3;   ///< s_max, m (> s₀): no displacement beyond this along the skeleton
    double maxSqueeze = 0.8;   ///< κ in [0, 1): cap as a fraction of the distance to the skeleton
};

class ClipFlattening {
public:
    /// Selects the render vertices (positions at application, #R, m) whose skeleton projection
    /// lies within s_max of the centre's, and keeps the polyline segments within reach of them.
    /// Throws std::invalid_argument ("sim::ClipFlattening::create(): ...") on bad settings, a
    /// polyline with fewer than 2 points, or non-finite positions.
    static std::unique_ptr<ClipFlattening> create(const ClipAttachment& clip, const std::vector<Vec3>& renderPositions,
                                                  const std::vector<Vec3>& skeleton,
                                                  const FlattenSettings& settings = {});
    ClipFlattening(const ClipFlattening&) = delete;
    ClipFlattening& operator=(const ClipFlattening&) = delete;

    /// out = renderPositions + d (resized and copied). The skeleton is carried with the clip.
    /// Never throws: a size mismatch copies the input unchanged and returns false; non-finite
    /// input vertices are copied and left undisplaced.
    bool flattenInto(const ClipAttachment& clip, const std::vector<Vec3>& renderPositions,
                     std::vector<Vec3>& out) const;
    /// Same with the current skeleton polyline (same point count as at create, else false).
    bool flattenInto(const ClipAttachment& clip, const std::vector<Vec3>& renderPositions,
                     const std::vector<Vec3>& skeletonNow, std::vector<Vec3>& out) const;

    const std::vector<int32_t>& candidates() const { return m_candidates; } ///< render indices
    const FlattenSettings& settings() const { return m_settings; }

private:
    ClipFlattening() = default;
    bool run(const ClipAttachment& clip, const std::vector<Vec3>& x, const Vec3* skel, bool carried,
             std::vector<Vec3>& out) const;

    FlattenSettings m_settings;
    size_t m_renderCount = 0, m_skeletonCount = 0;
    std::vector<int32_t> m_candidates;
    std::vector<int32_t> m_segments; ///< kept segments (i, i + 1) of the polyline
    std::vector<Vec3> m_skeleton0;   ///< polyline at application
};

/// Closest point of a polyline to p over the segments starting at the listed indices (all when
/// `segments` is empty); the first one wins ties. O(#segments).
Vec3 closestPointOnPolyline(const Vec3& p, const Vec3* polyline, size_t count,
                            const std::vector<int32_t>& segments = {});

} // namespace viscera::sim
