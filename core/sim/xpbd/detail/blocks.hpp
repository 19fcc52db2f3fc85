#pragma once
/// Constraint blocks of the XPBD engine (private to sim/xpbd). Particle indices are global
/// (into Engine::xw). Every block accumulates its multipliers over the iterations of a substep
/// and restarts them from 0 at the first iteration [A eq. 4.43–4.44].
#include "sim/material/constraint_model.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/xpbd/detail/engine.hpp"
#include "sim/xpbd/strain_limit.hpp"

#include <array>
#include <memory>
#include <vector>

namespace viscera::sim::detail {

/// Elastic tets of one body: E = Σ V w Σ_k C_k² / (2 α_k) (constraint_model.hpp).
struct ElasticTets {
    std::vector<Tet> tets;      ///< global particle indices
    std::vector<Mat3> dmInv;    ///< 1/m
    std::vector<double> volume; ///< m^3
    std::vector<double> weight; ///< stiffness weights (> 0)
    std::shared_ptr<const TetConstraintModel> model;
};

/// A StableNeoHookeanModel gets the packed fast path (AVX2 when simd and the CPU allow, else the
/// scalar pack kernel); any other model the generic path through TetConstraintModel::evaluate.
/// usesSimd (optional) reports whether the AVX2 kernel was chosen.
std::unique_ptr<Block> makeElasticBlock(ElasticTets tets, bool simd, bool* usesSimd = nullptr);

/// One scalar strain-limit constraint C = ε_ij − s. side: +1 upper (ε ≤ s, λ ≤ 0), −1 lower
/// (ε ≥ s, λ ≥ 0), 0 bilateral (ε = s).
struct ScalarStrainLimit {
    int i = 0, j = 0;
    double s = 0;
    int side = 0;
    double compliance = 0; ///< per unit rest volume (tets) or area (triangles)
};
std::vector<ScalarStrainLimit> expandStrainLimits(const std::vector<StrainLimit>& limits);

/// Strain limits on tets; dmInv in material axes (tetMaterialDmInv).
std::unique_ptr<Block> makeTetStrainBlock(std::vector<Tet> tets, std::vector<Mat3> dmInv, std::vector<double> volume,
                                          std::vector<ScalarStrainLimit> limits);
/// Strain limits on triangles; dmInv of the UV frame (triangleUvDmInv).
std::unique_ptr<Block> makeTriStrainBlock(std::vector<Tri> tris, std::vector<Mat2> dmInv, std::vector<double> area,
                                          std::vector<ScalarStrainLimit> limits);
/// Membrane constraints (membrane.hpp), α = 1/(k A) with k the triangle's own stiffness (N/m,
/// one per triangle: painted fascia). simd: the AVX2 kernel when the CPU has it
/// (membrane_kernel.hpp), else the scalar path.
std::unique_ptr<Block> makeMembraneBlock(std::vector<Tri> tris, std::vector<Mat2> dmInv, std::vector<double> area,
                                         std::vector<double> stiffness, bool simd);

/// C = x_p − Σ_{k<n} b_k x_k, n = 3 or 4.
struct Tie {
    int32_t p = -1;
    std::array<int32_t, 4> t{};
    std::array<double, 4> b{};
    int n = 0;
    double compliance = 0; ///< m/N
};
std::unique_ptr<Block> makeCouplingBlock(std::vector<Tie> ties);

} // namespace viscera::sim::detail
