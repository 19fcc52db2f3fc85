#include "sim/fem/corotational_fem.hpp"

#include "sim/fem/sparse_cholesky.hpp"
#include "sim/util/format.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

namespace viscera::sim {
namespace {

constexpr const char* kWhere = "sim::CorotationalFem::";

/// A factorization of K_R with everything that depends on the rotations.
struct Factor {
    std::unique_ptr<SparseCholesky> chol;
    std::vector<Mat3> rotations; ///< per tet
    Eigen::VectorXd f;           ///< f_R, 3#V
    Eigen::VectorXd u0;          ///< K_R⁻¹ f_R
    std::vector<Vec3> xAt;       ///< positions the rotations were taken from
    long factorNonZeros = 0;     ///< nnz(L), for the cost model of a solve
};

struct Group {
    bool alive = false;
    ConstraintDesc desc;
    ConstraintState st;
};

/// A row of the current solve: free-node terms only, right-hand side in displacement form.
struct SolveRow {
    int group = 0, row = 0;
    int id = 0;                              ///< index among the rows of all live groups (key of the solve's M cache)
    std::vector<std::pair<int, Vec3>> terms; // (cache slot, coefficient)
    std::vector<std::pair<int32_t, Vec3>> nodeTerms; // (node, coefficient), free nodes
    double bu = 0;
};

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Removes row and column j from the k × k lower factor L (L Lᵀ = A → L' L'ᵀ = A without row and
/// column j): the rows below j take the rank-one update L₂₂L₂₂ᵀ + x xᵀ, x = L[j+1:k, j], by Givens
/// rotations, then move up one place. O((k − j)²) instead of the O((k − j)³) of factoring them again.
void deleteFactorRow(RowMatrix& L, int k, int j, Eigen::VectorXd& x) {
    const int n = k - j - 1;
    x.resize(n);
    for (int t = 0; t < n; ++t)
        x[t] = L(j + 1 + t, j);
    for (int i = 0; i < n; ++i) {
        const int ri = j + 1 + i;
        const double lii = L(ri, ri), r = std::hypot(lii, x[i]);
        const double c = r / lii, sn = x[i] / lii;
        L(ri, ri) = r;
        for (int t = i + 1; t < n; ++t) {
            const int rt = j + 1 + t;
            L(rt, ri) = (L(rt, ri) + sn * x[t]) / c;
            x[t] = c * x[t] - sn * L(rt, ri);
        }
    }
    for (int r = j; r + 1 < k; ++r) { // close the gap: row r ← row r + 1 without its column j
        L.row(r).head(j) = L.row(r + 1).head(j);
        L.row(r).segment(j, r - j + 1) = L.row(r + 1).segment(j + 1, r - j + 1);
    }
}

} // namespace

std::string validate(const FemSettings& s) {
    if (!(s.youngsModulus > 0) || !std::isfinite(s.youngsModulus))
        return "youngs_modulus " + formatNumber(s.youngsModulus, 3) + " must be positive";
    if (!(s.poissonRatio >= 0 && s.poissonRatio < 0.5))
        return "poisson_ratio " + formatNumber(s.poissonRatio, 3) + " must be in [0, 0.5)";
    if (!(s.refactorDisplacement > 0))
        return "refactor_displacement " + formatNumber(s.refactorDisplacement, 3) + " must be positive";
    if (s.refactorLatencySteps < 1) return "refactor_latency_steps must be >= 1";
    if (!(s.rankTolerance > 0 && s.rankTolerance < 1))
        return "rank_tolerance " + formatNumber(s.rankTolerance, 3) + " must be in (0, 1)";
    if (!(s.releaseTolerance >= 0) || !(s.activationTolerance >= 0))
        return "release/activation tolerances must be >= 0";
    if (s.maxActiveSetIterations < 1) return "max_active_set_iterations must be >= 1";
    if (s.cacheEvictSteps < 1) return "cache_evict_steps must be >= 1";
    if (s.refactorNodesPerSolve < 1) return "refactor_nodes_per_solve must be >= 1";
    if (s.prefetchNodesPerSolve < 0) return "prefetch_nodes_per_solve must be >= 0";
    if (s.stepSubstitutions < 0) return "step_substitutions must be >= 0";
    return {};
}

struct CorotationalFem::Impl {
    FemSettings s;
    double lambda = 0, mu = 0;
    std::vector<Tet> tets;
    std::vector<LinearTet> elems;
    Eigen::VectorXd fext;
    UpperPattern pattern;
    std::vector<int> scatter; // 144 per tet, −1 = not stored
    std::vector<int> fixedDiag;
    const std::vector<Vec3>* x0 = nullptr;
    const std::vector<uint8_t>* fixed = nullptr;

    Factor cur;
    // constrained-node cache: K_R⁻¹ blocks between cached nodes
    std::vector<int> slotOf, nodeOf, lastUsed, freeSlots;
    Eigen::MatrixXd kinv;
    // K_R⁻¹ columns of the cached nodes (3#V × 3 per slot): u = u0 − Σ cols·(Cᵀλ)_node replaces the
    // substitution of a solve (a dense product over the constrained nodes only).
    Eigen::MatrixXd cols;
    std::vector<double> rhsWork;
    // u at single nodes in the activation test, memoized per active-set iteration (uEpoch)
    std::vector<int64_t> uStamp;
    std::vector<Vec3> uMemo;
    int64_t uEpoch = 0;

    std::vector<Group> groups;
    size_t liveGroups = 0;
    int step = 0;

    // Background refactorization, in two phases. Worker: rotations, assembly, numeric factorization
    // and u0 of the positions at the request (joined exactly `refactorLatencySteps` solves later).
    // Main thread, amortized: the K⁻¹ columns of the nodes carried over (pinned or in recent use),
    // `refactorNodesPerSolve` nodes per solve with the new factor while the old one keeps serving
    // the solves; the swap happens at the first solve that finds every carried node done. All of it
    // counts solves and nodes, never time: the swap step is the same on every run.
    struct Job {
        std::vector<Vec3> x;
        Factor result;
        bool ok = false;
        std::string error;
        std::atomic<bool> finished{false};
        std::chrono::steady_clock::time_point started{}; // when the worker was started
        double seconds = 0;                              // the build's wall time (worker or here)
        bool joined = false;
        std::vector<int> nodes; // carried nodes, in order; columns of the first `done` are in cols
        int done = 0;
        bool topped = false;  // the nodes that came into use meanwhile were added (once: then the swap)
        Eigen::MatrixXd cols; // 3#V × 3·capacity
    };
    std::shared_ptr<Job> job;
    std::thread worker;
    std::vector<std::pair<std::thread, std::shared_ptr<Job>>> retired; // late workers, joined when done
    double lastBuildSeconds = 0; // wall time of the last factor built (0: none yet)
    int swapStep = 0;
    std::vector<uint8_t> pinned; // per node: kept in the cache and carried by a refactorization
    std::vector<int> prefetch;   // nodes queued for caching ahead of use (FIFO)
    bool stepMode = false;       // beginStep() was called: the amortized work waits for endStep()
    int stepWork = 0;            // the solves' work since beginStep(): substitutions and extra active-set iterations
    size_t prefetchHead = 0;

    std::vector<std::array<int32_t, 2>> edges; // unique tet edges, for the refactor test

    // last solve, for tests
    std::vector<SolveRow> lastRows;
    Eigen::VectorXd lastLambda;

    ~Impl() {
        if (worker.joinable()) worker.join();
        for (auto& r : retired)
            r.first.join();
    }

    int n3() const { return 3 * static_cast<int>(x0->size()); }

    void assemble(const std::vector<Mat3>& R, std::vector<double>& values, Eigen::VectorXd& f) const {
        values.assign(pattern.rowIdx.size(), 0.0);
        for (int d : fixedDiag)
            values[d] = 1.0;
        f = fext;
        const auto& X0 = *x0;
        for (size_t t = 0; t < tets.size(); ++t) {
            const Mat12& K = elems[t].stiffness;
            const Mat3& r = R[t];
            Mat12 KR;
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    KR.block<3, 3>(3 * a, 3 * b) = r * K.block<3, 3>(3 * a, 3 * b) * r.transpose();
            const int* map = &scatter[t * 144];
            for (int i = 0; i < 144; ++i)
                if (map[i] >= 0) values[map[i]] += KR(i / 12, i % 12);
            if (r.isIdentity(0)) continue;
            Vec12 d; // x0 − Rᵀ x0
            for (int a = 0; a < 4; ++a) {
                const Vec3& p = X0[tets[t][a]];
                d.segment<3>(3 * a) = p - r.transpose() * p;
            }
            const Vec12 kd = K * d;
            for (int a = 0; a < 4; ++a)
                f.segment<3>(3 * tets[t][a]) += r * kd.segment<3>(3 * a);
        }
        for (size_t v = 0; v < fixed->size(); ++v)
            if ((*fixed)[v]) f.segment<3>(3 * v).setZero();
    }

    std::vector<Mat3> rotationsAt(const std::vector<Vec3>& x) const {
        std::vector<Mat3> R(tets.size(), Mat3::Identity());
        if (!s.corotational) return R;
        for (size_t t = 0; t < tets.size(); ++t) {
            const Tet& e = tets[t];
            R[t] = elementRotation(deformationGradient(elems[t], {x[e[0]], x[e[1]], x[e[2]], x[e[3]]}));
        }
        return R;
    }

    bool buildFactor(const std::vector<Vec3>& x, Factor& out, std::string& error) const {
        out.rotations = rotationsAt(x);
        out.xAt = x;
        std::vector<double> values;
        assemble(out.rotations, values, out.f);
        if (!out.chol) out.chol = std::make_unique<SparseCholesky>(pattern, s.cholesky);
        if (!out.chol->factorize(values, error)) return false;
        out.factorNonZeros = out.chol->factorNonZeros();
        out.u0 = out.f;
        if (!out.chol->solveInPlace(out.u0.data(), 1, error)) return false;
        return out.u0.allFinite();
    }

    /// K⁻¹ blocks between `nodes` (3|N| × 3|N|) with factor F.
    static bool inverseBlocks(Factor& F, const std::vector<int>& nodes, int n3, Eigen::MatrixXd& out,
                              Eigen::MatrixXd& full, std::string& error) {
        const int k = static_cast<int>(nodes.size());
        Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n3, 3 * k);
        for (int i = 0; i < k; ++i)
            for (int c = 0; c < 3; ++c)
                rhs(3 * nodes[i] + c, 3 * i + c) = 1.0;
        if (!F.chol->solveInPlace(rhs.data(), 3 * k, error)) return false;
        out.resize(3 * k, 3 * k);
        for (int i = 0; i < k; ++i)
            out.middleRows(3 * i, 3) = rhs.middleRows(3 * nodes[i], 3);
        full.swap(rhs);
        return true;
    }

    int allocateSlot(int node) {
        int slot;
        if (!freeSlots.empty()) {
            slot = freeSlots.back();
            freeSlots.pop_back();
            nodeOf[slot] = node;
        } else {
            slot = static_cast<int>(nodeOf.size());
            nodeOf.push_back(node);
            lastUsed.push_back(step);
            if (3 * static_cast<int>(nodeOf.size()) > kinv.rows()) {
                const int cap = std::max<int>(96, 2 * static_cast<int>(kinv.rows()));
                Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(cap, cap);
                grown.topLeftCorner(kinv.rows(), kinv.cols()) = kinv;
                kinv.swap(grown);
                cols.conservativeResize(n3(), cap);
            }
        }
        slotOf[node] = slot;
        lastUsed[slot] = step;
        return slot;
    }

    /// Caches the K⁻¹ columns of `nodes` (not yet cached) with the current factor.
    bool cacheNodes(const std::vector<int>& nodes, std::string& error) {
        if (nodes.empty()) return true;
        const int k = static_cast<int>(nodes.size());
        const int n = n3();
        rhsWork.assign(static_cast<size_t>(n) * 3 * k, 0.0);
        for (int i = 0; i < k; ++i)
            for (int c = 0; c < 3; ++c)
                rhsWork[static_cast<size_t>(3 * i + c) * n + 3 * nodes[i] + c] = 1.0;
        if (!cur.chol->solveInPlace(rhsWork.data(), 3 * k, error)) return false;
        std::vector<int> slots(k);
        for (int i = 0; i < k; ++i)
            slots[i] = allocateSlot(nodes[i]);
        if (cols.rows() != n || cols.cols() < kinv.cols()) cols.conservativeResize(n, kinv.cols());
        for (int i = 0; i < k; ++i) {
            const int si = slots[i];
            cols.middleCols(3 * si, 3) =
                Eigen::Map<const Eigen::MatrixXd>(rhsWork.data() + static_cast<size_t>(3 * i) * n, n, 3);
            for (size_t s2 = 0; s2 < nodeOf.size(); ++s2) {
                const int node = nodeOf[s2];
                if (node < 0) continue;
                for (int c = 0; c < 3; ++c)
                    for (int r = 0; r < 3; ++r) {
                        const double v = rhsWork[static_cast<size_t>(3 * i + c) * n + 3 * node + r];
                        kinv(3 * s2 + r, 3 * si + c) = v;
                        kinv(3 * si + c, 3 * s2 + r) = v;
                    }
            }
        }
        return true;
    }

    void resetCache() {
        std::fill(slotOf.begin(), slotOf.end(), -1);
        nodeOf.clear();
        lastUsed.clear();
        freeSlots.clear();
    }

    void evict() {
        for (size_t s2 = 0; s2 < nodeOf.size(); ++s2)
            if (nodeOf[s2] >= 0 && !pinned[nodeOf[s2]] && step - lastUsed[s2] > s.cacheEvictSteps) {
                slotOf[nodeOf[s2]] = -1;
                nodeOf[s2] = -1;
                freeSlots.push_back(static_cast<int>(s2));
            }
    }

    /// Nodes cached now that a refactorization must carry: pinned or used in the last two solves.
    void carriedNodes(std::vector<int>& out) const {
        for (size_t s2 = 0; s2 < nodeOf.size(); ++s2) {
            const int node = nodeOf[s2];
            if (node >= 0 && (pinned[node] || step - lastUsed[s2] <= 1)) out.push_back(node);
        }
    }

    /// Advances a refactorization at the start of a solve: joins the worker at its step, computes
    /// the next chunk of carried columns, or swaps the new factor in. Deterministic (see Job).
    void advanceJob(FemSolveStats& st) {
        if (!job) return;
        if (!job->joined) {
            if (step < swapStep) return;
            const bool onTime = job->finished.load(std::memory_order_acquire);
            if (onTime || awaitWorker()) {
                worker.join();
                // The wait's bound: a build that finished before its join, undisturbed by one here.
                if (onTime && job->ok) lastBuildSeconds = job->seconds;
            } else {
                // The worker is late past the time a build took last (a core busy with other work):
                // compute the same factor here, from the same positions, instead of waiting for it
                // without bound. Same input, same code, same bits; the late worker finishes on its
                // own and its result is dropped.
                st.refactorWaited = true;
                auto mine = std::make_shared<Job>();
                mine->x = job->x;
                runJob(*mine);
                retired.emplace_back(std::move(worker), std::move(job));
                job = std::move(mine);
            }
            job->joined = true;
            if (!job->ok) {
                st.error = "background refactorization failed (the previous factor stays in use): " + job->error;
                cur.xAt = job->x; // do not retry at once
                job.reset();
                return;
            }
            carriedNodes(job->nodes);
        }
        Job& j = *job;
        if (j.done == static_cast<int>(j.nodes.size()) && !j.topped) {
            // Nodes that came into use while the columns were computed travel too, collected once:
            // then the swap, whatever came into use since (those are cached on demand with the new
            // factor), so a stream of new constraints cannot put the new rotations off for ever.
            j.topped = true;
            std::vector<int> more;
            carriedNodes(more);
            for (int node : more)
                if (std::find(j.nodes.begin(), j.nodes.end(), node) == j.nodes.end()) j.nodes.push_back(node);
        }
        const int k = static_cast<int>(j.nodes.size());
        if (j.done < k) {
            // Without steps every solve computes `refactorNodesPerSolve` nodes; with steps endStep() does.
            if (!stepMode) carryChunk(st, s.refactorNodesPerSolve);
            return;
        }
        takeJob(st);
    }

    /// Computes the K⁻¹ columns of up to `maxNodes` more carried nodes with the new factor.
    void carryChunk(FemSolveStats& st, int maxNodes) {
        Job& j = *job;
        const int k = static_cast<int>(j.nodes.size());
        {
            const int chunk = std::min(k - j.done, maxNodes);
            if (chunk <= 0) return;
            const int n = n3();
            if (j.cols.cols() < 3 * (j.done + chunk))
                j.cols.conservativeResize(n, std::max<Eigen::Index>(3 * k, 2 * j.cols.cols()));
            auto block = j.cols.middleCols(3 * j.done, 3 * chunk);
            block.setZero();
            for (int i = 0; i < chunk; ++i)
                for (int c = 0; c < 3; ++c)
                    block(3 * j.nodes[j.done + i] + c, 3 * i + c) = 1.0;
            if (!j.result.chol->solveInPlace(block.data(), 3 * chunk, st.error)) {
                job.reset();
                return;
            }
            j.done += chunk;
            st.substitutions += 3 * chunk;
        }
    }

    /// A refactorization's carried columns are being computed (the worker joined, the swap to come).
    bool carrying() const { return job && job->joined && job->done < static_cast<int>(job->nodes.size()); }

    void takeJob(FemSolveStats& st) {
        std::shared_ptr<Job> j = std::move(job);
        cur = std::move(j->result);
        resetCache();
        const int k = static_cast<int>(j->nodes.size());
        // The job's columns are laid out as the cache's (node i in slot i): taken over, not copied (a
        // copy of #V × 3k doubles and the page faults of a new buffer made the swap step a spike:
        // tens of ms with a few hundred carried nodes).
        cols = std::move(j->cols);
        if (cols.cols() < 96) cols.conservativeResize(n3(), 96);
        const Eigen::Index cap = cols.cols();
        // The same buffer when the size repeats (entries past the carried slots are rewritten when
        // their slots are allocated, and never read before).
        if (kinv.rows() != cap) kinv = Eigen::MatrixXd::Zero(cap, cap);
        for (int a = 0; a < k; ++a)
            for (int b = 0; b < k; ++b)
                kinv.block<3, 3>(3 * a, 3 * b) = cols.block<3, 3>(3 * j->nodes[a], 3 * b);
        for (int i = 0; i < k; ++i) {
            nodeOf.push_back(j->nodes[i]);
            lastUsed.push_back(step);
            slotOf[j->nodes[i]] = i;
        }
        st.refactored = true;
    }

    /// Builds the job's factor from its positions (on the worker, or here for a late one), timed.
    void runJob(Job& j) const {
        const auto t0 = std::chrono::steady_clock::now();
        try {
            j.ok = buildFactor(j.x, j.result, j.error);
        } catch (const std::exception& e) {
            j.ok = false;
            j.error = e.what();
        }
        j.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }

    /// True once the worker has finished: at once, or after waiting until the worker has run as
    /// long as the last build took (it is then at most that far from done, where a build here
    /// would take all of it and share the cores with the worker). False: still running then.
    bool awaitWorker() const {
        if (job->finished.load(std::memory_order_acquire)) return true;
        if (!(lastBuildSeconds > 0)) return false;
        const auto until = job->started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(lastBuildSeconds));
        while (std::chrono::steady_clock::now() < until) {
            if (job->finished.load(std::memory_order_acquire)) return true;
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        return job->finished.load(std::memory_order_acquire);
    }

    void startJob(const std::vector<Vec3>& x) {
        for (auto it = retired.begin(); it != retired.end();)
            if (it->second->finished.load(std::memory_order_acquire)) {
                it->first.join();
                it = retired.erase(it);
            } else {
                ++it;
            }
        job = std::make_shared<Job>();
        job->x = x;
        swapStep = step + s.refactorLatencySteps;
        std::shared_ptr<Job> jp = job;
        jp->started = std::chrono::steady_clock::now(); // read by awaitWorker: set before the thread
        worker = std::thread([this, jp] {
            runJob(*jp);
            jp->finished.store(true, std::memory_order_release);
        });
    }

    /// Caches up to `maxNodes` queued nodes that are not cached yet.
    bool prefetchStep(FemSolveStats& st, int maxNodes) {
        std::vector<int> batch;
        while (prefetchHead < prefetch.size() && static_cast<int>(batch.size()) < maxNodes) {
            const int node = prefetch[prefetchHead++];
            if (slotOf[node] < 0 && !(*fixed)[node]) batch.push_back(node);
        }
        if (prefetchHead == prefetch.size()) {
            prefetch.clear();
            prefetchHead = 0;
        }
        if (batch.empty()) return true;
        if (!cacheNodes(batch, st.error)) return false;
        st.newCachedNodes += static_cast<int>(batch.size());
        st.substitutions += 3 * static_cast<int>(batch.size());
        return true;
    }
};

// The Impl first: its destructor joins the background workers, which read m_x0 (a member destroyed
// before m if the defaults ran in reverse declaration order; AddressSanitizer: heap-use-after-free).
CorotationalFem::~CorotationalFem() {
    m.reset();
}

std::unique_ptr<CorotationalFem> CorotationalFem::create(const TetMesh& mesh, const std::vector<int32_t>& fixedNodes,
                                                         const FemSettings& settings,
                                                         std::vector<Vec3> externalForces) {
    auto fail = [](const std::string& why) { throw std::invalid_argument(std::string(kWhere) + "create(): " + why); };
    if (auto why = validate(settings); !why.empty()) fail(why);
    const size_t nv = mesh.vertexCount();
    std::unique_ptr<CorotationalFem> w(new CorotationalFem());
    w->m = std::make_unique<Impl>();
    Impl& m = *w->m;
    m.s = settings;
    const double E = settings.youngsModulus, nu = settings.poissonRatio;
    m.mu = E / (2 * (1 + nu));
    m.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    w->m_x0 = mesh.positions();
    w->m_x = w->m_x0;
    w->m_fixed.assign(nv, 0);
    m.x0 = &w->m_x0;
    m.fixed = &w->m_fixed;
    for (int32_t v : fixedNodes) {
        if (v < 0 || static_cast<size_t>(v) >= nv)
            fail("fixed node " + std::to_string(v) + " is out of range (mesh has " + std::to_string(nv) + " nodes)");
        w->m_fixed[v] = 1;
    }
    if (!externalForces.empty() && externalForces.size() != nv)
        fail("external forces have " + std::to_string(externalForces.size()) + " entries, the mesh " +
             std::to_string(nv) + " nodes");
    m.fext = Eigen::VectorXd::Zero(3 * nv);
    for (size_t v = 0; v < externalForces.size(); ++v) {
        if (!externalForces[v].allFinite()) fail("external force at node " + std::to_string(v) + " is not finite");
        m.fext.segment<3>(3 * v) = externalForces[v];
    }
    m.tets = mesh.tets();
    m.elems.reserve(m.tets.size());
    double edgeSum = 0;
    for (size_t t = 0; t < m.tets.size(); ++t) {
        const Tet& e = m.tets[t];
        const std::array<Vec3, 4> x = {w->m_x0[e[0]], w->m_x0[e[1]], w->m_x0[e[2]], w->m_x0[e[3]]};
        try {
            m.elems.push_back(makeLinearTet(x, m.lambda, m.mu));
        } catch (const std::invalid_argument&) {
            fail("tet " + std::to_string(t) + " has a non-positive rest volume");
        }
        edgeSum += (x[1] - x[0]).norm() + (x[2] - x[0]).norm() + (x[3] - x[0]).norm() + (x[2] - x[1]).norm() +
                   (x[3] - x[1]).norm() + (x[3] - x[2]).norm();
    }
    w->m_meanEdge = edgeSum / (6.0 * static_cast<double>(std::max<size_t>(1, m.tets.size())));

    // Pattern: upper triangle over free DOFs plus the diagonal of every DOF.
    const int n = static_cast<int>(3 * nv);
    std::vector<std::vector<int>> cols(n);
    for (int d = 0; d < n; ++d)
        cols[d].push_back(d);
    for (const Tet& e : m.tets)
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b) {
                if (w->m_fixed[e[a]] || w->m_fixed[e[b]]) continue;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) {
                        const int r = 3 * e[a] + i, c = 3 * e[b] + j;
                        if (r <= c) cols[c].push_back(r);
                    }
            }
    m.pattern.colPtr.assign(n + 1, 0);
    for (int c = 0; c < n; ++c) {
        std::sort(cols[c].begin(), cols[c].end());
        cols[c].erase(std::unique(cols[c].begin(), cols[c].end()), cols[c].end());
        m.pattern.colPtr[c + 1] = m.pattern.colPtr[c] + static_cast<int>(cols[c].size());
    }
    for (auto& c : cols)
        m.pattern.rowIdx.insert(m.pattern.rowIdx.end(), c.begin(), c.end());
    m.scatter.assign(m.tets.size() * 144, -1);
    for (size_t t = 0; t < m.tets.size(); ++t) {
        const Tet& e = m.tets[t];
        for (int i = 0; i < 12; ++i)
            for (int j = 0; j < 12; ++j) {
                if (w->m_fixed[e[i / 3]] || w->m_fixed[e[j / 3]]) continue;
                const int r = 3 * e[i / 3] + i % 3, c = 3 * e[j / 3] + j % 3;
                if (r <= c) m.scatter[t * 144 + i * 12 + j] = m.pattern.find(r, c);
            }
    }
    for (size_t v = 0; v < nv; ++v)
        if (w->m_fixed[v])
            for (int c = 0; c < 3; ++c)
                m.fixedDiag.push_back(m.pattern.find(3 * static_cast<int>(v) + c, 3 * static_cast<int>(v) + c));
    m.slotOf.assign(nv, -1);
    m.uStamp.assign(nv, 0);
    m.uMemo.assign(nv, Vec3::Zero());
    m.pinned.assign(nv, 0);
    std::string error;
    const auto t0 = std::chrono::steady_clock::now();
    if (!m.buildFactor(w->m_x0, m.cur, error)) fail(error);
    m.lastBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    w->m_factorizations = 1;
    for (size_t v = 0; v < nv; ++v)
        w->m_x[v] = w->m_x0[v] + m.cur.u0.segment<3>(3 * v);
    return w;
}

int CorotationalFem::addConstraint(ConstraintDesc desc) {
    const size_t nv = m_x0.size();
    for (size_t r = 0; r < desc.rows.size(); ++r) {
        for (const ConstraintTerm& t : desc.rows[r].terms)
            if (t.node < 0 || static_cast<size_t>(t.node) >= nv || !t.a.allFinite())
                throw std::invalid_argument(std::string(kWhere) + "addConstraint(): row " + std::to_string(r) +
                                            " has a node out of range or a non-finite coefficient");
        if (!std::isfinite(desc.rows[r].b))
            throw std::invalid_argument(std::string(kWhere) + "addConstraint(): row " + std::to_string(r) +
                                        " has a non-finite right-hand side");
    }
    if (desc.kind == ConstraintKind::Unilateral && desc.weights.empty()) desc.weights.assign(desc.rows.size(), 1.0);
    Group g;
    g.alive = true;
    g.st.active = desc.kind == ConstraintKind::Equality || desc.startActive;
    g.st.lambda.assign(desc.rows.size(), 0.0);
    g.st.status.assign(desc.rows.size(), RowStatus::Inactive);
    g.desc = std::move(desc);
    for (size_t i = 0; i < m->groups.size(); ++i)
        if (!m->groups[i].alive) {
            m->groups[i] = std::move(g);
            ++m->liveGroups;
            return static_cast<int>(i);
        }
    m->groups.push_back(std::move(g));
    ++m->liveGroups;
    return static_cast<int>(m->groups.size() - 1);
}

void CorotationalFem::setRows(int id, std::vector<ConstraintRow> rows) {
    Group& g = m->groups.at(id);
    if (g.desc.kind == ConstraintKind::Unilateral && g.desc.weights.size() != rows.size())
        g.desc.weights.assign(rows.size(), 1.0);
    g.desc.rows = std::move(rows);
    g.st.lambda.assign(g.desc.rows.size(), 0.0);
    g.st.status.assign(g.desc.rows.size(), RowStatus::Inactive);
}

void CorotationalFem::setRhs(int id, int row, double b) {
    m->groups.at(id).desc.rows.at(row).b = b;
}

void CorotationalFem::removeConstraint(int id) {
    if (!hasConstraint(id)) return;
    m->groups[id] = Group{};
    --m->liveGroups;
}

bool CorotationalFem::hasConstraint(int id) const {
    return id >= 0 && static_cast<size_t>(id) < m->groups.size() && m->groups[id].alive;
}
const ConstraintState& CorotationalFem::state(int id) const {
    return m->groups.at(id).st;
}
const ConstraintDesc& CorotationalFem::constraint(int id) const {
    return m->groups.at(id).desc;
}
size_t CorotationalFem::constraintCount() const {
    return m->liveGroups;
}

int CorotationalFem::cachedNodes() const {
    int c = 0;
    for (int n : m->nodeOf)
        c += n >= 0;
    return c;
}

void CorotationalFem::pinNodes(const std::vector<int32_t>& nodes) {
    std::fill(m->pinned.begin(), m->pinned.end(), 0);
    for (int32_t v : nodes)
        if (v >= 0 && static_cast<size_t>(v) < m->pinned.size()) m->pinned[v] = 1;
}

void CorotationalFem::prefetchNodes(const std::vector<int32_t>& nodes) {
    for (int32_t v : nodes)
        if (v >= 0 && static_cast<size_t>(v) < m_fixed.size() && !m_fixed[v] && m->slotOf[v] < 0 &&
            std::find(m->prefetch.begin() + static_cast<long>(m->prefetchHead), m->prefetch.end(), v) ==
                m->prefetch.end())
            m->prefetch.push_back(v);
}

void CorotationalFem::beginStep() {
    m->stepMode = true;
    m->stepWork = 0;
}

FemSolveStats CorotationalFem::endStep() {
    Impl& I = *m;
    FemSolveStats st;
    if (!I.stepMode) return st;
    // What the step's solves left of its budget, in nodes (three substitutions each); a
    // refactorization's carried columns always advance by one node, so the swap comes in bounded steps.
    int nodes = std::max(0, I.s.stepSubstitutions - I.stepWork) / 3;
    if (I.carrying()) {
        const int carried = std::clamp(nodes, 1, I.s.refactorNodesPerSolve);
        I.carryChunk(st, carried);
        nodes -= carried;
    }
    if (nodes > 0 && !I.prefetch.empty()) I.prefetchStep(st, std::min(nodes, I.s.prefetchNodesPerSolve));
    I.stepWork += st.substitutions;
    return st;
}

bool CorotationalFem::refactorPending() const {
    return m->job != nullptr;
}

bool CorotationalFem::refactorNow(std::string* error) {
    return refactorAt(m_x, error);
}

bool CorotationalFem::refactorAt(const std::vector<Vec3>& x, std::string* error) {
    if (x.size() != m_x.size()) {
        if (error) *error = std::string(kWhere) + "refactorAt(): positions have the wrong size";
        return false;
    }
    if (m->worker.joinable()) m->worker.join();
    m->job.reset();
    Factor f;
    std::string err;
    if (!m->buildFactor(x, f, err)) {
        if (error) *error = err;
        return false;
    }
    m->cur = std::move(f);
    m->resetCache();
    ++m_factorizations;
    return true;
}

FemSolveStats CorotationalFem::solve() {
    Impl& I = *m;
    FemSolveStats st;
    struct CountWork { // the step's own work, what endStep() fills up to its budget
        Impl& impl;
        const FemSolveStats& stats;
        ~CountWork() {
            if (impl.stepMode) impl.stepWork += stats.substitutions + std::max(0, stats.activeSetIterations - 1);
        }
    } count{I, st};
    ++I.step;
    // The amortized work runs in every solve, or once a step in endStep() when the caller marks steps.
    I.advanceJob(st);
    if (st.refactored) ++m_factorizations;
    I.evict();
    if (!I.stepMode && !I.prefetch.empty())
        I.prefetchStep(st, I.s.prefetchNodesPerSolve); // a failure is reported in st.error; the solve goes on
    const int n = I.n3();
    const auto& X0 = m_x0;

    std::vector<int> order;
    for (size_t g = 0; g < I.groups.size(); ++g)
        if (I.groups[g].alive) order.push_back(static_cast<int>(g));
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return I.groups[a].desc.priority < I.groups[b].desc.priority; });
    for (int g : order) {
        auto& gs = I.groups[g].st;
        std::fill(gs.lambda.begin(), gs.lambda.end(), 0.0);
        std::fill(gs.status.begin(), gs.status.end(), RowStatus::Inactive);
    }

    std::vector<SolveRow> rows;
    Eigen::VectorXd lam, u(n);
    // M = C K⁻¹ Cᵀ entries are computed once per solve, when a pair of rows first meets: the rows
    // of a group do not change within a solve, only which groups are active, so the active-set
    // iterations reuse them.
    std::vector<int> rowBase(I.groups.size(), 0);
    int allRows = 0;
    for (int g : order) {
        rowBase[g] = allRows;
        allRows += static_cast<int>(I.groups[g].desc.rows.size());
    }
    Eigen::MatrixXd mCache(allRows, allRows);
    std::vector<int> mIds; // row ids whose M entries with each other are in mCache
    std::vector<uint8_t> mKnown(static_cast<size_t>(allRows), 0);                        // per row id: in mIds
    std::vector<std::vector<std::pair<int, Vec3>>> mTerms(static_cast<size_t>(allRows)); // (slot, a) per known id
    Eigen::VectorXd w; // K⁻¹c_rᵀ at the cached slots of the row being added
    auto buildRows = [&]() -> bool {
        rows.clear();
        std::vector<int> missing;
        for (int g : order) {
            auto& status = I.groups[g].st.status;
            std::fill(status.begin(), status.end(), RowStatus::Inactive);
        }
        for (int g : order) {
            const Group& G = I.groups[g];
            if (!G.st.active) continue;
            for (size_t r = 0; r < G.desc.rows.size(); ++r) {
                SolveRow sr;
                sr.group = g;
                sr.row = static_cast<int>(r);
                sr.id = rowBase[g] + static_cast<int>(r);
                sr.bu = G.desc.rows[r].b;
                for (const ConstraintTerm& t : G.desc.rows[r].terms) {
                    sr.bu -= t.a.dot(X0[t.node]);
                    if (m_fixed[t.node] || t.a.squaredNorm() == 0) continue;
                    sr.nodeTerms.emplace_back(t.node, t.a);
                    if (I.slotOf[t.node] < 0 && std::find(missing.begin(), missing.end(), t.node) == missing.end())
                        missing.push_back(t.node);
                }
                rows.push_back(std::move(sr));
            }
        }
        if (!missing.empty()) {
            if (!I.cacheNodes(missing, st.error)) return false;
            st.newCachedNodes += static_cast<int>(missing.size());
            st.substitutions += 3 * static_cast<int>(missing.size());
        }
        for (SolveRow& sr : rows)
            for (auto& [node, a] : sr.nodeTerms) {
                const int slot = I.slotOf[node];
                I.lastUsed[slot] = I.step;
                sr.terms.emplace_back(slot, a);
            }
        return true;
    };

    // Dense Schur system on the rows: returns false on failure. Fills lam (per row; 0 if rejected).
    std::vector<uint8_t> rejected;
    RowMatrix L;
    std::vector<int> acc, prevIds; // accepted rows and row ids of the previous active-set iteration
    // Rows only removed since the previous active-set iteration (groups released): the factor loses
    // their rows by rank-one updates instead of being computed again from the first of them. The
    // rows kept stay enforced (a row's pivot only grows when rows before it leave); a rejected row
    // that now passes the pivot test is where the factorization resumes. Returns the first row the
    // factorization must still compute (acc, rejected and L describe the rows before it).
    Eigen::VectorXd dropWork;
    auto dropReleasedRows = [&](int p) -> int {
        const int mrows = static_cast<int>(rows.size()), old = static_cast<int>(prevIds.size());
        std::vector<int> newPos(old, -1); // per previous row: its position now (-1: removed)
        for (int r = 0, o = 0; r < mrows; ++r, ++o) {
            while (o < old && prevIds[o] != rows[r].id)
                ++o;
            if (o == old) return p; // a row came in: factor from p as usual
            newPos[o] = r;
        }
        const auto Mv = [&](int r, int c) { return mCache(rows[r].id, rows[c].id); };
        int k = static_cast<int>(acc.size());
        for (int i = k - 1; i >= 0; --i)
            if (newPos[acc[i]] < 0) {
                deleteFactorRow(L, k, i, dropWork);
                acc.erase(acc.begin() + i);
                --k;
            }
        std::vector<uint8_t> wasRejected(mrows, 0);
        for (int o = 0; o < old; ++o)
            if (newPos[o] >= 0) wasRejected[newPos[o]] = rejected[o];
        for (int& a : acc)
            a = newPos[a];
        rejected.assign(wasRejected.begin(), wasRejected.end());
        for (int r = p, before = 0; r < mrows; ++r) {
            while (before < k && acc[before] < r)
                ++before;
            if (!rejected[r]) continue;
            Eigen::VectorXd col(before);
            for (int i = 0; i < before; ++i)
                col[i] = Mv(acc[i], r);
            L.topLeftCorner(before, before).triangularView<Eigen::Lower>().solveInPlace(col);
            const double d = Mv(r, r) - col.squaredNorm();
            if (Mv(r, r) > 0 && d > I.s.rankTolerance * Mv(r, r)) return r; // resume here
        }
        return mrows;
    };
    auto solveSchur = [&]() {
        const int mrows = static_cast<int>(rows.size());
        Eigen::VectorXd q(mrows);
        for (int r = 0; r < mrows; ++r) {
            double cu0 = 0;
            for (const auto& [node, a] : rows[r].nodeTerms)
                cu0 += a.dot(I.cur.u0.segment<3>(3 * node));
            q[r] = cu0 - rows[r].bu;
        }
        // A row id met for the first time in this solve gets its M entries with every known id (the
        // rows of a group do not change within a solve; an inactive group's entries wait for its return).
        for (int r = 0; r < mrows; ++r) {
            const int id = rows[r].id;
            if (mKnown[id]) continue;
            mKnown[id] = 1;
            mIds.push_back(id);
            mTerms[id] = rows[r].terms;
            // K⁻¹c_rᵀ at the cached slots: one product per term over contiguous columns of the blocks.
            const Eigen::Index slots3 = 3 * static_cast<Eigen::Index>(I.nodeOf.size());
            w.setZero(slots3);
            for (const auto& [slot, a] : rows[r].terms)
                w.noalias() += I.kinv.block(0, 3 * slot, slots3, 3) * a;
            for (int c : mIds) {
                double v = 0; // Σ_terms a_cᵀ (K⁻¹ c_rᵀ)[slot_c] = Σ_terms a_rᵀ K⁻¹[slot_r, slot_c] a_c
                for (const auto& [sc, ac] : mTerms[c])
                    v += ac.dot(w.segment<3>(3 * sc));
                mCache(id, c) = mCache(c, id) = v;
            }
        }
        auto M = [&](int r, int c) { return mCache(rows[r].id, rows[c].id); };
        // Pivoted incremental Cholesky in row order; a row whose pivot is too small is rejected. The
        // rows that lead as in the previous active-set iteration keep their part of the factor (a
        // released or activated group changes only what follows it).
        int p = 0;
        while (p < mrows && p < static_cast<int>(prevIds.size()) && prevIds[p] == rows[p].id)
            ++p;
        if (I.s.incrementalSchur && (p < mrows || p < static_cast<int>(prevIds.size()))) p = dropReleasedRows(p);
        int k0 = 0;
        while (k0 < static_cast<int>(acc.size()) && acc[k0] < p)
            ++k0;
        acc.resize(k0);
        rejected.resize(mrows);
        std::fill(rejected.begin() + p, rejected.end(), 0);
        if (L.rows() < mrows) {
            RowMatrix grown(mrows, mrows);
            grown.topLeftCorner(k0, k0) = L.topLeftCorner(k0, k0);
            L.swap(grown);
        }
        prevIds.resize(mrows);
        for (int r = 0; r < mrows; ++r)
            prevIds[r] = rows[r].id;
        Eigen::VectorXd l(mrows);
        for (int r = p; r < mrows; ++r) {
            const int k = static_cast<int>(acc.size());
            for (int i = 0; i < k; ++i)
                l[i] = (M(acc[i], r) - L.row(i).head(i).dot(l.head(i))) / L(i, i);
            const double d = M(r, r) - l.head(k).squaredNorm();
            if (!(M(r, r) > 0) || !(d > I.s.rankTolerance * M(r, r))) {
                rejected[r] = 1;
                continue;
            }
            L.row(k).head(k) = l.head(k).transpose();
            L(k, k) = std::sqrt(d);
            acc.push_back(r);
        }
        const int k = static_cast<int>(acc.size());
        Eigen::VectorXd qa(k);
        for (int i = 0; i < k; ++i)
            qa[i] = q[acc[i]];
        const auto Lk = L.topLeftCorner(k, k).triangularView<Eigen::Lower>();
        Eigen::VectorXd y = Lk.solve(qa);
        Eigen::VectorXd la = Lk.transpose().solve(y);
        lam = Eigen::VectorXd::Zero(mrows);
        for (int i = 0; i < k; ++i)
            lam[acc[i]] = la[i];
        // Classify rejected rows by the residual they would keep.
        for (int r = 0; r < mrows; ++r) {
            auto& status = I.groups[rows[r].group].st.status[rows[r].row];
            if (!rejected[r]) {
                status = RowStatus::Enforced;
                continue;
            }
            double res = q[r];
            for (int i = 0; i < k; ++i)
                res -= M(r, acc[i]) * la[i];
            double cn = 0;
            for (const auto& [node, a] : rows[r].nodeTerms)
                cn += a.squaredNorm();
            const bool consistent = std::abs(res) <= I.s.activationTolerance * std::max(1.0, std::sqrt(cn));
            status = consistent ? RowStatus::Redundant : RowStatus::Incompatible;
        }
    };

    bool ok = true;
    std::vector<std::pair<int, Vec3>> gsum;
    Eigen::VectorXd gDense; // (Cᵀλ) per cached slot (3·slots), for the activation test
    for (int outer = 0; outer < I.s.maxActiveSetIterations && ok; ++outer) {
        bool changed = false;
        for (int inner = 0; inner < I.s.maxActiveSetIterations; ++inner) {
            ++st.activeSetIterations;
            if (!buildRows()) {
                ok = false;
                break;
            }
            solveSchur();
            // Release unilateral groups that pull.
            bool released = false;
            for (int g : order) {
                Group& G = I.groups[g];
                if (G.desc.kind != ConstraintKind::Unilateral || !G.st.active) continue;
                double s = 0;
                for (size_t r = 0; r < rows.size(); ++r)
                    if (rows[r].group == g) s += G.desc.weights[rows[r].row] * lam[r];
                if (s > I.s.releaseTolerance) {
                    G.st.active = false;
                    released = true;
                }
            }
            if (!released) break;
        }
        if (!ok) break;
        // u = K⁻¹ (f − Cᵀλ) = u0 − Σ_nodes K⁻¹[:, node] (Cᵀλ)_node. The activation test needs u only
        // at the nodes of inactive groups: rows of the cached columns, no full product.
        gsum.clear(); // (slot, (Cᵀλ)_node)
        for (size_t r = 0; r < rows.size(); ++r)
            if (lam[r] != 0)
                for (const auto& term : rows[r].terms) {
                    const auto& [slot, a] = term;
                    const auto key = term.first; // a lambda cannot capture a binding before clang 16
                    auto it = std::find_if(gsum.begin(), gsum.end(), [&](const auto& e) { return e.first == key; });
                    if (it == gsum.end())
                        gsum.emplace_back(slot, lam[r] * a);
                    else
                        it->second += lam[r] * a;
                }
        // At a cached node, K⁻¹[node, ·] (Cᵀλ) is the node's three columns of the cached blocks (K⁻¹ is
        // symmetric) against (Cᵀλ) over the slots: one contiguous product, instead of a 3 × 3 block
        // per slot gathered from rows far apart in the full columns. Each node once per iteration.
        const Eigen::Index slots3 = 3 * static_cast<Eigen::Index>(I.nodeOf.size());
        bool haveDense = false;
        ++I.uEpoch;
        auto uAt = [&](int32_t node) -> Vec3 {
            if (m_fixed[node]) return Vec3::Zero();
            if (I.uStamp[node] == I.uEpoch) return I.uMemo[node];
            Vec3 v = I.cur.u0.segment<3>(3 * node);
            const int own = I.slotOf[node];
            if (own >= 0) {
                if (!haveDense) {
                    gDense.setZero(slots3);
                    for (const auto& [slot, gv] : gsum)
                        gDense.segment<3>(3 * slot) = gv;
                    haveDense = true;
                }
                v.noalias() -= I.kinv.block(0, 3 * own, slots3, 3).transpose() * gDense;
            } else {
                for (const auto& [slot, gv] : gsum)
                    v.noalias() -= I.cols.block<3, 3>(3 * node, 3 * slot) * gv;
            }
            I.uStamp[node] = I.uEpoch;
            I.uMemo[node] = v;
            return v;
        };
        // Activate violated unilateral groups.
        for (int g : order) {
            Group& G = I.groups[g];
            if (G.desc.kind != ConstraintKind::Unilateral || G.st.active) continue;
            double viol = 0;
            for (size_t r = 0; r < G.desc.rows.size(); ++r) {
                double v = -G.desc.rows[r].b;
                for (const ConstraintTerm& t : G.desc.rows[r].terms)
                    v += t.a.dot(X0[t.node] + uAt(t.node));
                viol += G.desc.weights[r] * v;
            }
            if (viol < -I.s.activationTolerance && outer + 1 < I.s.maxActiveSetIterations) {
                G.st.active = true;
                changed = true;
            }
        }
        if (!changed) break;
    }
    if (ok) {
        // The full u once: the dense product over the constrained nodes, or one substitution of
        // f − Cᵀλ when that is cheaper (many constrained nodes; ≈ 4 nnz(L) flops against 6 #V·|g|).
        const double product = 6.0 * static_cast<double>(m_x.size()) * static_cast<double>(gsum.size());
        if (product > 4.0 * static_cast<double>(I.cur.factorNonZeros)) {
            u = I.cur.f;
            for (const auto& [slot, gv] : gsum)
                u.segment<3>(3 * I.nodeOf[slot]) -= gv;
            if (!I.cur.chol->solveInPlace(u.data(), 1, st.error)) ok = false;
            ++st.substitutions;
        } else {
            u = I.cur.u0;
            for (const auto& [slot, gv] : gsum)
                u.noalias() -= I.cols.middleCols(3 * slot, 3) * gv;
        }
    }
    st.finite = ok && u.allFinite() && (lam.size() == 0 || lam.allFinite());
    if (!st.finite) {
        if (st.error.empty()) st.error = "the solve produced a non-finite value; the previous state is kept";
        for (int g : order) {
            auto& gs = I.groups[g].st;
            std::fill(gs.lambda.begin(), gs.lambda.end(), 0.0);
        }
        return st;
    }
    for (size_t r = 0; r < rows.size(); ++r) {
        I.groups[rows[r].group].st.lambda[rows[r].row] = lam[r];
        if (rejected.size() > r && rejected[r]) {
            const RowStatus s2 = I.groups[rows[r].group].st.status[rows[r].row];
            st.redundant += s2 == RowStatus::Redundant;
            st.incompatible += s2 == RowStatus::Incompatible;
        } else {
            ++st.rows;
        }
    }
    I.lastRows = rows;
    I.lastLambda = lam;
    for (size_t v = 0; v < m_x.size(); ++v)
        m_x[v] = X0[v] + u.segment<3>(3 * v);
    // Rotations go stale when edges turn, not with translation or stretch: the largest change of an
    // edge vector normal to itself since the factorization.
    if (I.edges.empty()) {
        std::vector<std::array<int32_t, 2>> e;
        for (const Tet& t : I.tets)
            for (int a = 0; a < 4; ++a)
                for (int b = a + 1; b < 4; ++b)
                    e.push_back({std::min(t[a], t[b]), std::max(t[a], t[b])});
        std::sort(e.begin(), e.end());
        e.erase(std::unique(e.begin(), e.end()), e.end());
        I.edges = std::move(e);
    }
    double maxMove = 0;
    if (I.s.corotational)
        for (const auto& e : I.edges) {
            // Turn of the edge (its change normal to the edge; a stretch along it does not count).
            const Vec3 was = I.cur.xAt[e[1]] - I.cur.xAt[e[0]];
            const Vec3 d = (m_x[e[1]] - m_x[e[0]]) - was;
            const double w2 = was.squaredNorm();
            const double along = w2 > 0 ? d.dot(was) / w2 : 0.0;
            maxMove = std::max(maxMove, (d - along * was).squaredNorm());
        }
    maxMove = std::sqrt(maxMove);
    // Rotations are stale: refactor (now, or on the worker).
    if (I.s.corotational && !I.job && maxMove > I.s.refactorDisplacement * m_meanEdge) {
        if (I.s.refactorMode == RefactorMode::Synchronous) {
            std::string err;
            if (refactorNow(&err))
                st.refactored = true;
            else
                st.error = err;
        } else {
            I.startJob(m_x);
            st.refactorStarted = true;
        }
    }
    return st;
}

double CorotationalFem::elasticEnergy() const {
    double e = 0;
    for (size_t t = 0; t < m->tets.size(); ++t) {
        const Tet& T = m->tets[t];
        const Mat3& R = m->cur.rotations[t];
        Vec12 d;
        for (int a = 0; a < 4; ++a)
            d.segment<3>(3 * a) = R.transpose() * m_x[T[a]] - m_x0[T[a]];
        e += 0.5 * d.dot(m->elems[t].stiffness * d);
    }
    return e;
}

namespace {

/// Corotational element force R K (Rᵀx − x0) (12) and energy ½ dᵀKd at element positions xe.
double elementForce(const LinearTet& e, const std::array<Vec3, 4>& xe, const std::array<Vec3, 4>& x0, Vec12* force) {
    const Mat3 R = elementRotation(deformationGradient(e, xe));
    Vec12 d;
    for (int a = 0; a < 4; ++a)
        d.segment<3>(3 * a) = R.transpose() * xe[a] - x0[a];
    const Vec12 kd = e.stiffness * d;
    if (force)
        for (int a = 0; a < 4; ++a)
            force->segment<3>(3 * a) = R * kd.segment<3>(3 * a);
    return 0.5 * d.dot(kd);
}

} // namespace

double CorotationalFem::corotationalEnergy(const std::vector<Vec3>& x) const {
    double e = 0;
    for (size_t t = 0; t < m->tets.size(); ++t) {
        const Tet& T = m->tets[t];
        e += elementForce(m->elems[t], {x[T[0]], x[T[1]], x[T[2]], x[T[3]]},
                          {m_x0[T[0]], m_x0[T[1]], m_x0[T[2]], m_x0[T[3]]}, nullptr);
    }
    for (size_t v = 0; v < x.size(); ++v)
        e -= m->fext.segment<3>(3 * v).dot(x[v] - m_x0[v]);
    return e;
}

StaticReference CorotationalFem::convergedStatic(const StaticReferenceSettings& rs) const {
    const auto t0 = std::chrono::steady_clock::now();
    const Impl& I = *m;
    StaticReference out;
    const int n = I.n3();
    Eigen::MatrixXd C;
    Eigen::VectorXd bu, lam;
    lastSystem(C, bu, lam);
    const int mrows = static_cast<int>(C.rows());
    std::vector<Vec3> x = m_x;
    std::vector<double> values, exact; // projected and exact Hessian, pattern order
    Eigen::VectorXd grad(n);
    std::string error;
    SparseCholesky chol(I.pattern, I.s.cholesky);
    const double h = rs.fdStep * m_meanEdge;
    Eigen::MatrixXd Z;                  // H⁻¹Cᵀ
    Eigen::LDLT<Eigen::MatrixXd> schur; // C H⁻¹ Cᵀ
    double r0 = -1;
    double E = corotationalEnergy(x);
    int hessianAge = -1; // iterations since the Hessian was assembled (-1: none yet)
    for (int it = 0;; ++it) {
        // Gradient every iteration; the projected Hessian at the first iteration and again every
        // `hessianRefresh` iterations or when the line search fails with an old one (modified Newton:
        // the FD Hessian costs 24 polar decompositions per tet, the gradient one).
        const bool assembleHessian = hessianAge < 0 || hessianAge >= rs.hessianRefresh;
        if (assembleHessian) {
            values.assign(I.pattern.rowIdx.size(), 0.0);
            for (int d : I.fixedDiag)
                values[d] = 1.0;
            exact = values;
        }
        grad = -I.fext;
        for (size_t t = 0; t < I.tets.size(); ++t) {
            const Tet& T = I.tets[t];
            std::array<Vec3, 4> xe = {x[T[0]], x[T[1]], x[T[2]], x[T[3]]};
            const std::array<Vec3, 4> x0 = {m_x0[T[0]], m_x0[T[1]], m_x0[T[2]], m_x0[T[3]]};
            Vec12 f, fp, fm;
            elementForce(I.elems[t], xe, x0, &f);
            for (int a = 0; a < 4; ++a)
                grad.segment<3>(3 * T[a]) += f.segment<3>(3 * a);
            if (!assembleHessian) continue;
            Mat12 H;
            for (int j = 0; j < 12; ++j) {
                const double keep = xe[j / 3][j % 3];
                xe[j / 3][j % 3] = keep + h;
                elementForce(I.elems[t], xe, x0, &fp);
                xe[j / 3][j % 3] = keep - h;
                elementForce(I.elems[t], xe, x0, &fm);
                xe[j / 3][j % 3] = keep;
                H.col(j) = (fp - fm) / (2 * h);
            }
            H = 0.5 * (H + H.transpose()).eval();
            Eigen::SelfAdjointEigenSolver<Mat12> eig(H);
            const Mat12 Hp =
                eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
            const int* map = &I.scatter[t * 144];
            for (int i = 0; i < 144; ++i)
                if (map[i] >= 0) {
                    values[map[i]] += Hp(i / 12, i % 12);
                    exact[map[i]] += H(i / 12, i % 12);
                }
        }
        for (size_t v = 0; v < m_fixed.size(); ++v)
            if (m_fixed[v]) grad.segment<3>(3 * v).setZero();
        if (assembleHessian) {
            // The exact Hessian when it is positive definite (quadratic convergence), else the
            // projected one (a descent direction; linear convergence).
            hessianAge = 0;
            if (!chol.factorize(exact, error) && !chol.factorize(values, error)) {
                out.message = error;
                break;
            }
            Z = C.transpose();
            if (mrows > 0 && !chol.solveInPlace(Z.data(), mrows, error)) {
                out.message = error;
                break;
            }
            schur = (C * Z).ldlt();
        }
        ++hessianAge;
        // KKT step: Δ = −H⁻¹(∇E + Cᵀμ) with CΔ = 0.
        Eigen::VectorXd y = grad;
        if (!chol.solveInPlace(y.data(), 1, error)) {
            out.message = error;
            break;
        }
        Eigen::VectorXd mu = Eigen::VectorXd::Zero(mrows);
        if (mrows > 0) mu = schur.solve(-(C * y));
        const Eigen::VectorXd r = grad + C.transpose() * mu;
        out.residual = r.lpNorm<Eigen::Infinity>();
        if (r0 < 0) r0 = std::max(out.residual, 1e-6);
        out.iterations = it;
        if (!std::isfinite(out.residual)) {
            out.message = "non-finite residual";
            break;
        }
        if (out.residual <= rs.tolerance * r0) {
            out.converged = true;
            break;
        }
        if (it >= rs.maxIterations) {
            out.message = "max iterations";
            break;
        }
        const Eigen::VectorXd delta = -(y + Z * mu);
        if (delta.lpNorm<Eigen::Infinity>() <= rs.stepTolerance * m_meanEdge) { // at the rounding floor
            out.converged = true;
            break;
        }
        const double slope = grad.dot(delta);
        double step = 1;
        std::vector<Vec3> trial(x.size());
        double Et = E;
        bool accepted = false;
        for (int b = 0; b < 40; ++b, step *= 0.5) {
            for (size_t v = 0; v < x.size(); ++v)
                trial[v] = x[v] + step * delta.segment<3>(3 * v);
            Et = corotationalEnergy(trial);
            // Armijo, with the rounding noise of E (a sum over the tets) as slack near x*.
            if (Et <= E + 1e-4 * step * slope + 64 * std::numeric_limits<double>::epsilon() * std::abs(E)) {
                accepted = true;
                break;
            }
        }
        if (!accepted && hessianAge > 1) { // an old Hessian: refresh it and try again
            hessianAge = rs.hessianRefresh;
            continue;
        }
        if (!accepted) { // at the rounding floor of E: the residual says how far from x* it is
            out.converged = out.residual <= 1e3 * rs.tolerance * r0;
            out.message = "line search stalled";
            break;
        }
        x.swap(trial);
        E = Et;
    }
    out.x = std::move(x);
    out.energy = corotationalEnergy(out.x);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

Eigen::SparseMatrix<double> CorotationalFem::stiffnessMatrix() const {
    std::vector<double> values;
    Eigen::VectorXd f;
    m->assemble(m->cur.rotations, values, f);
    const int n = m->n3();
    std::vector<Eigen::Triplet<double>> trip;
    for (int c = 0; c < n; ++c)
        for (int k = m->pattern.colPtr[c]; k < m->pattern.colPtr[c + 1]; ++k) {
            const int r = m->pattern.rowIdx[k];
            trip.emplace_back(r, c, values[k]);
            if (r != c) trip.emplace_back(c, r, values[k]);
        }
    Eigen::SparseMatrix<double> K(n, n);
    K.setFromTriplets(trip.begin(), trip.end());
    return K;
}

Eigen::VectorXd CorotationalFem::forceVector() const {
    return m->cur.f;
}

void CorotationalFem::lastSystem(Eigen::MatrixXd& C, Eigen::VectorXd& bu, Eigen::VectorXd& lambda) const {
    const auto& rows = m->lastRows;
    std::vector<int> keep;
    for (size_t r = 0; r < rows.size(); ++r)
        if (m->groups[rows[r].group].alive && m->groups[rows[r].group].st.status[rows[r].row] == RowStatus::Enforced)
            keep.push_back(static_cast<int>(r));
    C = Eigen::MatrixXd::Zero(keep.size(), m->n3());
    bu.resize(keep.size());
    lambda.resize(keep.size());
    for (size_t i = 0; i < keep.size(); ++i) {
        const SolveRow& sr = rows[keep[i]];
        for (const auto& [node, a] : sr.nodeTerms)
            C.row(i).segment<3>(3 * node) += a.transpose();
        bu[i] = sr.bu;
        lambda[i] = m->lastLambda[keep[i]];
    }
}

} // namespace viscera::sim
