#include "sim/fem/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <thread>

namespace viscera::sim {

int UpperPattern::find(int r, int c) const {
    if (c < 0 || c >= size()) return -1;
    const auto first = rowIdx.begin() + colPtr[c], last = rowIdx.begin() + colPtr[c + 1];
    const auto it = std::lower_bound(first, last, r);
    return (it != last && *it == r) ? static_cast<int>(it - rowIdx.begin()) : -1;
}

namespace {

/// Reused right-hand side and workspaces of cholmod_solve2 for one thread, with the Common they
/// were allocated from.
struct SolveSpace {
    cholmod_dense* rhs = nullptr;
    cholmod_dense* sol = nullptr;
    cholmod_dense* y = nullptr;
    cholmod_dense* e = nullptr;

    void release(cholmod_common& c) {
        for (cholmod_dense** d : {&rhs, &sol, &y, &e})
            if (*d) cholmod_free_dense(d, &c);
    }
    /// Solves A X = B for the `columns` column-major right-hand sides at b (n rows), in place.
    bool solve(cholmod_factor* factor, size_t n, double* b, int columns, cholmod_common& c) {
        if (!rhs || rhs->ncol != static_cast<size_t>(columns)) {
            if (rhs) cholmod_free_dense(&rhs, &c);
            rhs = cholmod_allocate_dense(n, columns, n, CHOLMOD_REAL, &c);
            if (!rhs) return false;
        }
        std::memcpy(rhs->x, b, sizeof(double) * n * columns);
        if (!cholmod_solve2(CHOLMOD_A, factor, rhs, nullptr, &sol, nullptr, &y, &e, &c)) return false;
        std::memcpy(b, sol->x, sizeof(double) * n * columns);
        return true;
    }
};

} // namespace

struct SparseCholesky::Impl {
    cholmod_common common{};
    cholmod_sparse* matrix = nullptr;
    cholmod_factor* factor = nullptr;
    SolveSpace space; // this thread's solves (allocated from `common`)
    // A second thread's solves with the same factor (read only by cholmod_solve2): its own Common
    // and workspaces, started on first use.
    cholmod_common helperCommon{};
    bool helperStarted = false;
    SolveSpace helperSpace;
    bool ok = false;
    int n = 0;

    std::string why(const char* call) const {
        const char* w = "error";
        switch (common.status) {
        case CHOLMOD_OUT_OF_MEMORY:
            w = "out of memory";
            break;
        case CHOLMOD_TOO_LARGE:
            w = "problem too large";
            break;
        case CHOLMOD_NOT_POSDEF:
            w = "matrix not positive definite";
            break;
        case CHOLMOD_INVALID:
            w = "invalid input";
            break;
        case CHOLMOD_NOT_INSTALLED:
            w = "method not installed";
            break;
        default:
            break;
        }
        return std::string("CHOLMOD: ") + call + " failed: " + w + " (status " + std::to_string(common.status) + ")";
    }

    /// Copies the pattern and runs the symbolic analysis (fill-reducing ordering, supernodes).
    bool analyze(const UpperPattern& p, std::string& error) {
        const int size = p.size();
        if (size <= 0 || static_cast<int>(p.rowIdx.size()) != p.colPtr[size])
            throw std::invalid_argument("sim::SparseCholesky(): empty or malformed pattern");
        n = size;
        matrix = cholmod_allocate_sparse(n, n, p.rowIdx.size(), 1, 1, 1, CHOLMOD_REAL, &common);
        if (!matrix) {
            error = why("cholmod_allocate_sparse");
            return false;
        }
        std::copy(p.colPtr.begin(), p.colPtr.end(), static_cast<int*>(matrix->p));
        std::copy(p.rowIdx.begin(), p.rowIdx.end(), static_cast<int*>(matrix->i));
        std::fill_n(static_cast<double*>(matrix->x), p.rowIdx.size(), 0.0);
        factor = cholmod_analyze(matrix, &common);
        if (!factor) {
            error = why("cholmod_analyze");
            return false;
        }
        return true;
    }
};

SparseCholesky::SparseCholesky(NoAnalysis, CholeskyMethod method) : m(std::make_unique<Impl>()) {
    cholmod_start(&m->common);
    m->common.print = 0;               // the library never prints
    m->common.error_handler = nullptr; // errors come back through common.status
    m->common.supernodal = method == CholeskyMethod::Simplicial ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL;
    m->common.final_ll = 1;
}

SparseCholesky::SparseCholesky(const UpperPattern& p, CholeskyMethod method) : SparseCholesky(NoAnalysis{}, method) {
    std::string error;
    if (!m->analyze(p, error)) throw std::runtime_error(error);
}

std::unique_ptr<SparseCholesky> SparseCholesky::tryCreate(const UpperPattern& p, std::string& error,
                                                          CholeskyMethod method) {
    std::unique_ptr<SparseCholesky> chol(new SparseCholesky(NoAnalysis{}, method));
    if (!chol->m->analyze(p, error)) return nullptr;
    return chol;
}

SparseCholesky::~SparseCholesky() {
    m->space.release(m->common);
    if (m->helperStarted) {
        m->helperSpace.release(m->helperCommon);
        cholmod_finish(&m->helperCommon);
    }
    if (m->factor) cholmod_free_factor(&m->factor, &m->common);
    if (m->matrix) cholmod_free_sparse(&m->matrix, &m->common);
    cholmod_finish(&m->common);
}

int SparseCholesky::size() const {
    return m->n;
}
bool SparseCholesky::factorized() const {
    return m->ok;
}
long SparseCholesky::factorNonZeros() const {
    if (!m->ok) return 0;
    if (m->factor->is_super) {
        // Supernodal: sum of the supernode column heights times widths.
        const int* super = static_cast<const int*>(m->factor->super);
        const int* pi = static_cast<const int*>(m->factor->pi);
        long nz = 0;
        for (size_t s = 0; s < m->factor->nsuper; ++s) {
            const long w = super[s + 1] - super[s], h = pi[s + 1] - pi[s];
            nz += w * h - w * (w - 1) / 2;
        }
        return nz;
    }
    return static_cast<long>(m->factor->nzmax);
}

int SparseCholesky::failedColumn() const {
    return m->factor ? static_cast<int>(m->factor->minor) : m->n;
}

bool SparseCholesky::factorize(const std::vector<double>& values, std::string& error, bool* notPositiveDefinite) {
    m->ok = false;
    if (notPositiveDefinite) *notPositiveDefinite = false;
    if (values.size() != m->matrix->nzmax) {
        error = "sim::SparseCholesky::factorize(): value count does not match the pattern";
        return false;
    }
    std::copy(values.begin(), values.end(), static_cast<double*>(m->matrix->x));
    const int ok = cholmod_factorize(m->matrix, m->factor, &m->common);
    if (!ok || m->common.status < CHOLMOD_OK) {
        error = m->why("cholmod_factorize");
        return false;
    }
    if (m->common.status == CHOLMOD_NOT_POSDEF || m->factor->minor < m->factor->n) {
        if (notPositiveDefinite) *notPositiveDefinite = true;
        error = "CHOLMOD: the stiffness matrix is not positive definite (column " + std::to_string(m->factor->minor) +
                " of " + std::to_string(m->factor->n) + "); fix enough nodes to remove rigid motions";
        return false;
    }
    m->ok = true;
    return true;
}

bool SparseCholesky::solveInPlace(double* b, int columns, std::string& error) {
    if (!m->ok) {
        error = "sim::SparseCholesky::solveInPlace(): no valid factorization";
        return false;
    }
    if (columns <= 0) return true;
    const size_t n = static_cast<size_t>(m->n);
    // Columns are independent: from kSplitColumns on, a second thread solves the first half with
    // the same factor. The split depends on the count only: a run stays repeatable.
    const int mine = columns >= kSplitColumns ? columns / 2 : columns, theirs = columns - mine;
    bool helperOk = true;
    std::thread helper;
    if (theirs > 0) {
        if (!m->helperStarted) {
            cholmod_start(&m->helperCommon);
            m->helperCommon.print = 0;
            m->helperCommon.error_handler = nullptr;
            m->helperStarted = true;
        }
        try {
            helper = std::thread([this, n, b, theirs, &helperOk] {
                helperOk = m->helperSpace.solve(m->factor, n, b, theirs, m->helperCommon);
            });
        } catch (const std::system_error&) { // no thread to be had: all columns here
            return m->space.solve(m->factor, n, b, columns, m->common) || (error = m->why("cholmod_solve2"), false);
        }
    }
    const bool ok = m->space.solve(m->factor, n, b + n * static_cast<size_t>(theirs), mine, m->common);
    if (helper.joinable()) helper.join();
    if (!ok) {
        error = m->why("cholmod_solve2");
        return false;
    }
    if (!helperOk) {
        error = std::string("CHOLMOD: cholmod_solve2 failed on the second thread (status ") +
                std::to_string(m->helperCommon.status) + ")";
        return false;
    }
    return true;
}

} // namespace viscera::sim
