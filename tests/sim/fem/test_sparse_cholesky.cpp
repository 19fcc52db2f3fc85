#include "sim/fem/corotational_fem.hpp"
#include "sim/fem/sparse_cholesky.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace viscera::sim;

namespace {

/// The stiffness matrix of a clamped bar: its upper triangle as a pattern and values.
struct Spd {
    UpperPattern pattern;
    std::vector<double> values;
    Eigen::SparseMatrix<double> full;
};

Spd barStiffness() {
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.06, 0.02, 0.02), {8, 3, 3}});
    std::vector<int32_t> fixed;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].x() < 1e-9) fixed.push_back(v);
    auto fem = CorotationalFem::create(*mesh, fixed, FemSettings{});
    Spd s;
    s.full = fem->stiffnessMatrix();
    s.full.makeCompressed();
    const int n = static_cast<int>(s.full.cols());
    s.pattern.colPtr.push_back(0);
    for (int c = 0; c < n; ++c) {
        for (Eigen::SparseMatrix<double>::InnerIterator it(s.full, c); it; ++it)
            if (it.row() <= c) {
                s.pattern.rowIdx.push_back(static_cast<int>(it.row()));
                s.values.push_back(it.value());
            }
        s.pattern.colPtr.push_back(static_cast<int>(s.pattern.rowIdx.size()));
    }
    return s;
}

} // namespace

// A solve of many columns is split over two threads by counts alone: the same solve gives the same
// bits every time (a run stays repeatable), each column agrees with the column solved alone to
// rounding (CHOLMOD blocks its column loops, so the bits may differ) and solves the system.
TEST(SparseCholesky, ASplitSolveIsRepeatableAndSolvesEveryColumn) {
    const Spd s = barStiffness();
    const int n = s.pattern.size();
    for (CholeskyMethod method : {CholeskyMethod::Simplicial, CholeskyMethod::Supernodal}) {
        SparseCholesky chol(s.pattern, method);
        std::string error;
        ASSERT_TRUE(chol.factorize(s.values, error)) << error;
        const int columns = 2 * SparseCholesky::kSplitColumns + 1; // odd: the halves differ in size
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> uni(-1, 1);
        Eigen::MatrixXd b(n, columns);
        for (Eigen::Index i = 0; i < b.size(); ++i)
            b.data()[i] = uni(rng);
        Eigen::MatrixXd first = b, second = b;
        ASSERT_TRUE(chol.solveInPlace(first.data(), columns, error)) << error;
        ASSERT_TRUE(chol.solveInPlace(second.data(), columns, error)) << error;
        for (Eigen::Index i = 0; i < b.size(); ++i)
            ASSERT_EQ(first.data()[i], second.data()[i]) << "entry " << i;
        for (int c = 0; c < columns; ++c) {
            Eigen::VectorXd alone = b.col(c);
            ASSERT_TRUE(chol.solveInPlace(alone.data(), 1, error)) << error;
            EXPECT_LE((first.col(c) - alone).cwiseAbs().maxCoeff(), 1e-12 * alone.cwiseAbs().maxCoeff())
                << "column " << c;
            const double residual = (s.full * first.col(c) - b.col(c)).cwiseAbs().maxCoeff();
            EXPECT_LT(residual, 1e-9 * b.col(c).cwiseAbs().maxCoeff()) << "column " << c;
        }
    }
}

TEST(SparseCholesky, ASplitSolveWithoutAFactorIsRefusedWithAMessage) {
    const Spd s = barStiffness();
    SparseCholesky chol(s.pattern, CholeskyMethod::Simplicial);
    std::vector<double> b(static_cast<size_t>(s.pattern.size()) * SparseCholesky::kSplitColumns, 1.0);
    std::string error;
    EXPECT_FALSE(chol.solveInPlace(b.data(), SparseCholesky::kSplitColumns, error));
    EXPECT_NE(error.find("no valid factorization"), std::string::npos) << error;
    // A matrix that is not positive definite leaves no factor to solve with either.
    std::vector<double> negative = s.values;
    for (double& v : negative)
        v = -v;
    bool notPd = false;
    EXPECT_FALSE(chol.factorize(negative, error, &notPd));
    EXPECT_TRUE(notPd);
    EXPECT_FALSE(chol.solveInPlace(b.data(), SparseCholesky::kSplitColumns, error));
}
