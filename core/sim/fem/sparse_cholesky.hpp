#pragma once
/// Sparse Cholesky LLᵀ of a symmetric positive-definite matrix (CHOLMOD, supernodal) with a fixed
/// pattern: the symbolic analysis (fill-reducing ordering) runs once, numeric factorizations reuse
/// it, and solves are forward/backward substitutions [B eq. 2.61–2.66]. CHOLMOD types stay in the
/// .cpp. One object is not thread-safe; two objects may be used from two threads. The one CHOLMOD
/// wrapper of the tree: the FEM solver and the Newton reference (sim/reference) both use it.
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

/// Upper triangle (diagonal included) in compressed columns: colPtr (n + 1), sorted rowIdx.
struct UpperPattern {
    std::vector<int> colPtr;
    std::vector<int> rowIdx;
    int size() const { return colPtr.empty() ? 0 : static_cast<int>(colPtr.size()) - 1; }
    int nonZeros() const { return static_cast<int>(rowIdx.size()); }
    /// Index of entry (r, c), r <= c, in rowIdx / values; -1 when absent.
    int find(int r, int c) const;
};

/// Supernodal: dense BLAS blocks, fastest to factorize and for many right-hand sides at once.
/// Simplicial: plain column loops; a solve with one to a few right-hand sides costs about nnz(L)
/// flops without a BLAS call per supernode, several times cheaper on a small factor (measured on
/// the 1,650-node anastomosis: about 0.5 against 1.5 ms for three columns).
enum class CholeskyMethod { Supernodal, Simplicial };

class SparseCholesky {
public:
    /// Analyses the pattern. Throws std::invalid_argument on an empty or malformed pattern and
    /// std::runtime_error when CHOLMOD fails (out of memory).
    explicit SparseCholesky(const UpperPattern& pattern, CholeskyMethod method = CholeskyMethod::Supernodal);
    /// As the constructor, but a CHOLMOD failure is returned: null with `error` set.
    static std::unique_ptr<SparseCholesky> tryCreate(const UpperPattern& pattern, std::string& error,
                                                     CholeskyMethod method = CholeskyMethod::Supernodal);
    ~SparseCholesky();
    SparseCholesky(const SparseCholesky&) = delete;
    SparseCholesky& operator=(const SparseCholesky&) = delete;

    int size() const;
    /// Numeric factorization of `values` (pattern order). False with a message when the matrix is
    /// not positive definite or CHOLMOD fails; the previous factor is then invalid. When not null,
    /// `notPositiveDefinite` tells that case apart; failedColumn() then names the column.
    bool factorize(const std::vector<double>& values, std::string& error, bool* notPositiveDefinite = nullptr);
    /// Column at which the last factorize() found the matrix not positive definite; size() if none.
    int failedColumn() const;
    bool factorized() const;
    /// Solves A X = B in place for `columns` right-hand sides stored column-major (size·columns).
    /// From kSplitColumns columns on, a second thread solves half of them: the split depends on the
    /// count only, so the same solve gives the same bits every time (they may differ from one call
    /// of all columns in the last place: CHOLMOD blocks its column loops).
    bool solveInPlace(double* b, int columns, std::string& error);
    /// Columns from which a solve is split over two threads: below it the thread's start (about
    /// 50 µs) costs more than half the columns save (about 0.2 ms per column on the 1,650-node
    /// anastomosis).
    static constexpr int kSplitColumns = 6;
    /// Non-zeros of the factor L (for reports).
    long factorNonZeros() const;

private:
    struct NoAnalysis {};
    SparseCholesky(NoAnalysis, CholeskyMethod method);
    struct Impl;
    std::unique_ptr<Impl> m;
};

} // namespace viscera::sim
