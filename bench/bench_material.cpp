// Per-tet cost of the material laws: ns per evaluation on random deformation gradients.
//
// BM_DensityPsiStress/<law>: Ψ(F) and P(F) through the EnergyDensity interface (two calls).
// BM_EnergyConstraintEvaluate/<law>: EnergyConstraintModel::evaluate (C = sqrt(2Ψ), ∂C/∂F = P/C),
//   the call the XPBD tet loop makes once per tet-iteration.
// BM_StableNeoHookeanEvaluate: the stable Neo-Hookean fast path, for reference.
// BM_SignedSvd: the signed SVD alone. BM_CurveValue/<points>: one curve lookup.
//
// Laws: 0 vl_neo_hookean (preset, 1,201-point h′), 1 vl_corotated, 2 vl_st_venant_kirchhoff,
// 3 corotated, 4 st_venant_kirchhoff, 5 neo_hookean (analytic).
// Samples: 1,024 F = R1 diag(s) R2ᵀ with s in [0.6, 1.6]³, one in eight inverted (s3 < 0).
#include "sim/material/energy_constraint.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/material/valanis_landel.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <memory>
#include <random>
#include <vector>

using namespace viscera::sim;

namespace {

constexpr double kMu = 10000.0, kLambda = 100000.0; // E ≈ 29.5 kPa, ν ≈ 0.45

const std::vector<Mat3>& samples() {
    static const std::vector<Mat3> fs = [] {
        std::mt19937 rng(1234);
        std::uniform_real_distribution<double> u(0.6, 1.6);
        std::normal_distribution<double> n(0.0, 1.0);
        const auto rotation = [&] {
            return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
        };
        std::vector<Mat3> out;
        for (int i = 0; i < 1024; ++i) {
            Eigen::Vector3d s(u(rng), u(rng), u(rng));
            if (i % 8 == 7) s(2) = -0.3 * s(2);
            out.push_back(rotation() * s.asDiagonal() * rotation().transpose());
        }
        return out;
    }();
    return fs;
}

struct Law {
    const char* label;
    std::shared_ptr<const EnergyDensity> density;
};

Law makeLaw(int index) {
    switch (index) {
    case 0:
        return {"vl_neo_hookean",
                std::make_shared<ValanisLandelDensity>("nh", valanisLandelCurves("neo_hookean", kMu, kLambda))};
    case 1:
        return {"vl_corotated",
                std::make_shared<ValanisLandelDensity>("corot", valanisLandelCurves("corotated", kMu, kLambda))};
    case 2:
        return {"vl_st_venant_kirchhoff", std::make_shared<ValanisLandelDensity>(
                                              "stvk", valanisLandelCurves("st_venant_kirchhoff", kMu, kLambda))};
    case 3:
        return {"corotated", std::make_shared<CorotatedLinearDensity>(kMu, kLambda)};
    case 4:
        return {"st_venant_kirchhoff", std::make_shared<StVenantKirchhoffDensity>(kMu, kLambda)};
    default:
        return {"neo_hookean", std::make_shared<NeoHookeanDensity>(kMu, kLambda)};
    }
}

void BM_DensityPsiStress(benchmark::State& state) {
    const Law law = makeLaw(static_cast<int>(state.range(0)));
    state.SetLabel(law.label);
    const auto& fs = samples();
    std::size_t i = 0;
    for (auto _ : state) {
        const Mat3& F = fs[i++ & 1023];
        benchmark::DoNotOptimize(law.density->psi(F));
        benchmark::DoNotOptimize(law.density->stress(F));
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_EnergyConstraintEvaluate(benchmark::State& state) {
    const Law law = makeLaw(static_cast<int>(state.range(0)));
    state.SetLabel(law.label);
    const EnergyConstraintModel model(law.density);
    const auto& fs = samples();
    TetConstraintValues v;
    std::size_t i = 0;
    for (auto _ : state) {
        model.evaluate(fs[i++ & 1023], v);
        benchmark::DoNotOptimize(v);
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_StableNeoHookeanEvaluate(benchmark::State& state) {
    const StableNeoHookeanModel model(kMu, kLambda);
    const auto& fs = samples();
    TetConstraintValues v;
    std::size_t i = 0;
    for (auto _ : state) {
        model.evaluate(fs[i++ & 1023], v);
        benchmark::DoNotOptimize(v);
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_SignedSvd(benchmark::State& state) {
    const auto& fs = samples();
    std::size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(signedSvd(fs[i++ & 1023]));
    state.SetItemsProcessed(state.iterations());
}

void BM_CurveValue(benchmark::State& state) {
    const auto curve = MonotoneCurve::fit("h'", [](double J) { return (1e5 * std::log(J) - 1e4) / J; },
                                          {.xmin = 1e-2,
                                           .xmax = 1e2,
                                           .count = static_cast<int>(state.range(0)),
                                           .spacing = CurveSpacing::Geometric,
                                           .shape = CurveShape::Unconstrained});
    const auto& fs = samples();
    std::size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(curve.value(fs[i++ & 1023].determinant()));
    state.SetItemsProcessed(state.iterations());
}

} // namespace

BENCHMARK(BM_DensityPsiStress)->ArgName("law")->DenseRange(0, 5);
BENCHMARK(BM_EnergyConstraintEvaluate)->ArgName("law")->DenseRange(0, 5);
BENCHMARK(BM_StableNeoHookeanEvaluate);
BENCHMARK(BM_SignedSvd);
BENCHMARK(BM_CurveValue)->ArgName("points")->Arg(9)->Arg(1201);
