#pragma once
/// Load-time stability check for XPBD bodies.
///
/// One Gauss–Seidel sweep per substep resolves an element only while the elastic wave crosses
/// less than about one element per substep. The check computes, per tet, the stiffness number
///     s = k w h² / (ρ L²),   k = the model's largest tangent stiffness between −25% and +25%
///     strain (λ + 2μ at rest for the classic laws), w = stiffness weight,
///     h = substep, ρ = density, L = (6 V)^(1/3) the element's length scale,
/// and refuses bodies whose largest s exceeds kMaxStiffnessNumber, telling the user
/// how many substeps would make it run. The threshold is measured against actual energy growth
/// (bench/bench_stability_margin: every free node kicked with 5 cm/s rms random velocity, then
/// 3 s under gravity; a run fails when the total energy rises above the start by more than 5 % of
/// m g L, L the body's extent, the bound of the stability suite). Largest s that passed / smallest
/// that failed: the suite's cantilever (1 cm cells) 1.86 / 4.2 at ν = 0.45, 1.34 / 2.38 at
/// ν = 0.49, 2.15 / 5.98 at ν = 0.499; the tissue-slab sample 2.79 / 6.29; the 30,000-tet block
/// 4.19 / 16.8; the rectum's fat pad 10.9 / 43.8; the CGAL organs of organ-blob and liver pass at
/// 19.6 and 33.8. Every body that passed settled. A limit of 1 stays below the first failure
/// (ν = 0.49, between 1.34 and 2.38) by a factor of about 2; the earlier limit of 0.25 (from runs
/// of an older solver) asked for twice the substeps.
/// Embedded bodies: see the tiedMass overload (their nodes move with their cage).
#include "sim/material/constraint_model.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <string>
#include <vector>

namespace viscera::sim {

inline constexpr double kMaxStiffnessNumber = 1.0;

struct StabilityFigures {
    double maxStiffnessNumber = 0; ///< largest s over the tets
    int worstTet = -1;
    int requiredSubsteps = 1; ///< smallest substep count with s ≤ limit
    bool ok() const { return maxStiffnessNumber <= kMaxStiffnessNumber; }
};

/// nodeWeights: empty (all 1) or one per node (tet weight = mean of its nodes).
StabilityFigures assessStability(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                 const std::vector<double>& nodeWeights, const XpbdSettings& settings);
/// The same for a body some of whose nodes are hard-tied to another body (an embedded vessel in its
/// cage): tiedMass, empty or one per node (kg, ≥ 0, may be +inf; XpbdSystem::tiedInertia), is the
/// inertia the ties add. A tet's constraints then move m_i + tiedMass_i at node i instead of its own
/// lumped mass m_i (ρ V / 4 summed over the node's tets), so s is divided by the smallest
/// (m_i + tiedMass_i) / m_i over its four nodes. All zero: the figures of the overload above.
StabilityFigures assessStability(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                 const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                                 const std::vector<double>& tiedMass);

/// Selective inertia scaling: the extra inertia per node (kg, #V, ≥ 0) that brings every tet of
/// the body under the limit at settings.substeps, given the inertia ties already add (tiedMass as
/// above; empty: none). A tet with stiffness number s > 1 needs (m_i + tied_i + extra_i) / m_i ≥
/// s · r at each of its nodes (r: its present ratio), so extra_i is the largest such need over the
/// node's tets, capped at (maxScale − 1) m_i (m_i: the node's own lumped mass). All zero when no
/// tet is over the limit. The cap may leave some tets over it: assessStability with tiedMass +
/// extra tells. Extra inertia slows only the dynamics of those nodes (XpbdSystem::setAddedInertia
/// keeps their weight). O(#tets).
std::vector<double> stabilizingInertia(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                       const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                                       const std::vector<double>& tiedMass, double maxScale);

/// Empty when stable, else one line: "body 'slab': stiffness number 22 at tet 17 exceeds 1
/// (substep 0.83 ms); use at least 95 substeps per frame or a softer material".
std::string stabilityProblem(const std::string& body, const StabilityFigures& f, const XpbdSettings& settings);

} // namespace viscera::sim
