#pragma once
/// One implicit-Euler (sub)step of a tetrahedral body: the problem that XPBD iterates on and that
/// the Newton reference solves to tight tolerance [A eq. 4.38–4.45]:
///
///     minimize f(x) = ½ Σ_i m_i |x_i − x̃_i|² + h² Σ_e V_e w_e Ψ_e(F_e(x)),
///
/// with x̃ = x^n + h v^n + h² g (inertia and gravity), Ψ_e the constraint-model energy density of
/// the tet (J/m^3), w_e its stiffness weight, and fixed nodes held at x̃. Units: metres, kg,
/// seconds; f in kg·m² (energy × h²).
#include "sim/material/constraint_model.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>

namespace viscera::sim {

struct StepProblem {
    double h = 0;               ///< step, s
    std::vector<Vec3> xTilde;   ///< #V, predicted positions, m
    std::vector<double> mass;   ///< #V, kg
    std::vector<uint8_t> fixed; ///< #V, 1 = held at xTilde
    std::vector<Tet> tets;      ///< #T
    std::vector<Mat3> dmInv;    ///< #T, inverse rest shape matrices, 1/m
    std::vector<double> volume; ///< #T, rest volumes, m^3
    std::vector<double> weight; ///< #T, stiffness weights (1 = material as given)
    std::shared_ptr<const TetConstraintModel> model;

    /// Deformation gradient of tet t at x.
    Mat3 deformationGradient(const std::vector<Vec3>& x, size_t t) const;
    /// f(x). O(#V + #T).
    double objective(const std::vector<Vec3>& x) const;
    /// ∇f(x) into g (#V); entries of fixed nodes are zero. O(#V + #T).
    void gradientInto(const std::vector<Vec3>& x, std::vector<Vec3>& g) const;
};

/// (f(x_k) − f(x*)) / (f(x_0) − f(x*)) [A eq. 4.45]; 0 when f(x_0) = f(x*).
double relativeError(double fk, double f0, double fStar);

} // namespace viscera::sim
