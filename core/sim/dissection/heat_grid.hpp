#pragma once
/// Heat transfer between an energized tool and tissue [A §5.3.2].
///
/// A local N × N × N uniform grid (spacing dl) centred on the heat source, an implicit sphere at
/// the tool tip held at the tool temperature. The parabolic heat equation ∂u/∂t = α ∇²u
/// [A eq. 5.9] is advanced with explicit central differences [A eq. 5.10]:
///     u' = u + r Σ_axes (u(n+1) + u(n−1) − 2u(n)),   r = α h / dl²,
/// with the frame cut into the fewest equal substeps h ≤ dl²/(6α), so r ≤ 1/6 and every update is
/// a convex combination of old values: the maximum principle holds exactly (all values stay in
/// [min, max] of the body and tool temperatures). Dirichlet conditions: grid nodes inside the
/// sphere (at least the node nearest the centre) at the tool temperature, the outer layer of the
/// grid at body temperature.
///
/// The grid follows the tool: its origin is snapped to the world lattice dl·ℤ³ (node
/// i ↔ (originIndex + i)·dl), so a move shifts the values by whole nodes (exact, no resampling
/// blur); nodes that enter the grid start at body temperature.
///
/// Temperatures in °C; lengths in metres; times in seconds. Serial, deterministic; O(N³) per
/// substep.
#include "sim/mesh/tri_mesh.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viscera::sim {

struct HeatGridSettings {
    int nodes = 24;                ///< N, nodes per axis (4..256)
    double spacing = 0.5e-3;       ///< dl, m (> 0)
    double diffusivity = 4.2e-6;   ///< α, m²/s [A §5.3.4]
    double bodyTemperature = 37.0; ///< °C: tissue far from the tool and the grid boundary
};
/// Empty when valid, else the rule that failed, naming the field.
std::string validate(const HeatGridSettings& s);

/// The implicit sphere f(x) = |x − c| − r at the tip of the energy tool.
struct HeatSource {
    Vec3 centre = Vec3::Zero(); ///< m, world frame
    double radius = 1e-3;       ///< m (> 0)
    double temperature = 170.0; ///< °C [A §5.3.4]
};

class HeatGrid {
public:
    /// Throws std::invalid_argument ("sim::HeatGrid: nodes is 2 (must be 4..256)") on bad settings.
    explicit HeatGrid(const HeatGridSettings& settings);

    /// Moves the grid onto the source (shift by whole nodes), then advances dt seconds with the
    /// source held at its temperature. Throws std::invalid_argument on a non-finite source or dt,
    /// radius ≤ 0, dt < 0 or a temperature below −273.15 °C (nothing changes then). Returns the
    /// number of substeps taken.
    int advance(const HeatSource& source, double dt);
    /// Moves the grid onto `centre` and advances dt seconds without a source (the tissue cools).
    int advanceUnheated(const Vec3& centre, double dt);

    /// Temperature at x, °C: the source temperature inside the sphere of the last advance(),
    /// trilinear interpolation of the grid inside it, body temperature outside the grid or before
    /// the first advance.
    double temperatureAt(const Vec3& x) const;
    /// Substeps for a frame of dt seconds (ceil(dt / (dl²/(6α))), at least 1).
    int substepsFor(double dt) const;
    double stableSubstep() const { return m_settings.spacing * m_settings.spacing / (6.0 * m_settings.diffusivity); }

    const HeatGridSettings& settings() const { return m_settings; }
    /// Grid values (N³, index (k·N + j)·N + i), °C.
    const std::vector<double>& values() const { return m_u; }
    /// World position of node (0, 0, 0), m.
    Vec3 origin() const;
    bool placed() const { return m_placed; }
    double minTemperature() const;
    double maxTemperature() const;
    /// Back to the unplaced state (all nodes at body temperature).
    void reset();

private:
    void place(const Vec3& centre);
    int run(double dt, const HeatSource* source);
    size_t id(int i, int j, int k) const { return (size_t(k) * m_n + j) * m_n + i; }

    HeatGridSettings m_settings;
    int m_n;
    std::vector<double> m_u, m_next;
    std::vector<uint8_t> m_fixed; ///< 1: Dirichlet (boundary or source) in the current advance
    std::array<int64_t, 3> m_originIndex{};
    bool m_placed = false;
    bool m_hasSource = false;
    HeatSource m_source;
};

} // namespace viscera::sim
