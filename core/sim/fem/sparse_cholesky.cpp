#include "sim/fem/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace viscera::sim::fem {

int UpperPattern::find(int r, int c) const {
    if (c < 0 || c >= size()) return -1;
    const auto first = rowIdx.begin() + colPtr[c], last = rowIdx.begin() + colPtr[c + 1];
    const auto it = std::lower_bound(first, last, r);
    return (it != last && *it == r) ? static_cast<int>(it - rowIdx.begin()) : -1;
}

struct SparseCholesky::Impl {
    cholmod_common common{};
    cholmod_sparse* matrix = nullptr;
    cholmod_factor* factor = nullptr;
    cholmod_dense* rhs = nullptr; // reused workspaces of cholmod_solve2
    cholmod_dense* sol = nullptr;
    cholmod_dense* y = nullptr;
    cholmod_dense* e = nullptr;
    bool ok = false;
    int n = 0;

    std::string why(const char* call) const {
        const char* w = "error";
        switch (common.status) {
        case CHOLMOD_OUT_OF_MEMORY: w = "out of memory"; break;
        case CHOLMOD_NOT_POSDEF: w = "matrix not positive definite"; break;
        case CHOLMOD_INVALID: w = "invalid input"; break;
        default: break;
        }
        return std::string("CHOLMOD: ") + call + " failed: " + w + " (status " + std::to_string(common.status) + ")";
    }
};

SparseCholesky::SparseCholesky(const UpperPattern& p) : m(std::make_unique<Impl>()) {
    const int n = p.size();
    if (n <= 0 || static_cast<int>(p.rowIdx.size()) != p.colPtr[n])
        throw std::invalid_argument("sim::fem::SparseCholesky(): empty or malformed pattern");
    cholmod_start(&m->common);
    m->common.print = 0;
    m->common.error_handler = nullptr;
    m->common.supernodal = CHOLMOD_SUPERNODAL;
    m->common.final_ll = 1;
    m->n = n;
    m->matrix = cholmod_allocate_sparse(n, n, p.rowIdx.size(), 1, 1, 1, CHOLMOD_REAL, &m->common);
    if (!m->matrix) throw std::runtime_error(m->why("cholmod_allocate_sparse"));
    std::copy(p.colPtr.begin(), p.colPtr.end(), static_cast<int*>(m->matrix->p));
    std::copy(p.rowIdx.begin(), p.rowIdx.end(), static_cast<int*>(m->matrix->i));
    std::fill_n(static_cast<double*>(m->matrix->x), p.rowIdx.size(), 0.0);
    m->factor = cholmod_analyze(m->matrix, &m->common);
    if (!m->factor) throw std::runtime_error(m->why("cholmod_analyze"));
}

SparseCholesky::~SparseCholesky() {
    for (cholmod_dense** d : {&m->rhs, &m->sol, &m->y, &m->e})
        if (*d) cholmod_free_dense(d, &m->common);
    if (m->factor) cholmod_free_factor(&m->factor, &m->common);
    if (m->matrix) cholmod_free_sparse(&m->matrix, &m->common);
    cholmod_finish(&m->common);
}

int SparseCholesky::size() const { return m->n; }
bool SparseCholesky::factorized() const { return m->ok; }
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

bool SparseCholesky::factorize(const std::vector<double>& values, std::string& error) {
    m->ok = false;
    if (values.size() != m->matrix->nzmax) {
        error = "sim::fem::SparseCholesky::factorize(): value count does not match the pattern";
        return false;
    }
    std::copy(values.begin(), values.end(), static_cast<double*>(m->matrix->x));
    const int ok = cholmod_factorize(m->matrix, m->factor, &m->common);
    if (!ok || m->common.status < CHOLMOD_OK) {
        error = m->why("cholmod_factorize");
        return false;
    }
    if (m->common.status == CHOLMOD_NOT_POSDEF || m->factor->minor < m->factor->n) {
        error = "CHOLMOD: the stiffness matrix is not positive definite (column " + std::to_string(m->factor->minor) +
                " of " + std::to_string(m->factor->n) + "); fix enough nodes to remove rigid motions";
        return false;
    }
    m->ok = true;
    return true;
}

bool SparseCholesky::solveInPlace(double* b, int columns, std::string& error) {
    if (!m->ok) {
        error = "sim::fem::SparseCholesky::solveInPlace(): no valid factorization";
        return false;
    }
    if (columns <= 0) return true;
    const size_t n = static_cast<size_t>(m->n);
    if (!m->rhs || m->rhs->ncol != static_cast<size_t>(columns)) {
        if (m->rhs) cholmod_free_dense(&m->rhs, &m->common);
        m->rhs = cholmod_allocate_dense(n, columns, n, CHOLMOD_REAL, &m->common);
        if (!m->rhs) {
            error = m->why("cholmod_allocate_dense");
            return false;
        }
    }
    std::memcpy(m->rhs->x, b, sizeof(double) * n * columns);
    if (!cholmod_solve2(CHOLMOD_A, m->factor, m->rhs, nullptr, &m->sol, nullptr, &m->y, &m->e, &m->common)) {
        error = m->why("cholmod_solve2");
        return false;
    }
    std::memcpy(b, m->sol->x, sizeof(double) * n * columns);
    return true;
}

} // namespace viscera::sim::fem
