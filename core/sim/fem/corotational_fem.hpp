#pragma once
/// Quasi-static corotational linear FEM on a TetMesh with algebraic constraints Cx = b solved
/// through the Schur complement of the stiffness matrix [B §2.2.3–2.2.6].
///
/// Each solve finds the displacement u (#V × 3, metres, from the rest state) of
///     minimize ½ uᵀK_R u − f_Rᵀu   subject to  C u = b_u,
/// with K_R = Σ_e R_e K_e R_eᵀ (element rotations R_e frozen at the last factorization) and
/// f_R = f_ext + Σ_e R_e K_e (x0_e − R_eᵀ x0_e). Fixed nodes are identity rows of K_R [B eq. 2.56–2.59];
/// constraint terms on fixed nodes move to the right-hand side.
///
/// Cost model (what makes a step cheap):
///  - K_R is factorized (CHOLMOD LLᵀ, pattern analysed once) only when some edge vector has turned
///    by more than `refactorDisplacement` mean edge lengths (its change normal to itself) since the
///    last factorization (translation and stretch do not count); in
///    RefactorMode::Background the rotations, assembly and factorization run on a worker thread
///    joined exactly `refactorLatencySteps` solves later (a late worker's factor is
///    computed by that solve instead, from the same positions: same bits, bounded wait), then the K⁻¹ columns of the
///    carried nodes (pinned or in use) are computed with the new factor, `refactorNodesPerSolve` nodes per solve, while
///    the old factor keeps serving; the swap happens when all are done. Every step of it counts solves and nodes, never
///    time, so a run is repeatable. u0 = K_R⁻¹ f_R is cached with the factor.
///  - K_R⁻¹ restricted to the constrained nodes is cached (three substitutions per node, once, when
///    a node first appears in a constraint; the full columns are kept too). Every constraint row's column K_R⁻¹cᵀ at
///    the constrained nodes is a combination of these blocks, so rows may be added, removed or change their
///    coefficients without any substitution, and M = C K_R⁻¹ Cᵀ [B eq. 2.67] costs a small dense product.
///  - a solve is: build M and q = C u0 − b, a pivoted dense Cholesky that rejects rows whose pivot
///    falls below `rankTolerance` (redundant or incompatible rows, [B §2.2.6]) instead of producing a
///    singular system, the multipliers λ, and u = u0 − Σ_nodes K_R⁻¹[:, node](Cᵀλ)_node from the
///    cached columns (a dense product over the constrained nodes; no substitution).
///  - M's entries are computed once per solve, when a row first takes part (K⁻¹cᵀ at the cached
///    nodes by one product per term); a released group leaves the factor of M by rank-one updates.
/// Unilateral groups (contact, thread pull) are released when their weighted multiplier shows that
/// they pull (Σ w_r λ_r > releaseTolerance) and re-activated when violated; the active set is
/// iterated at most `maxActiveSetIterations` times.
/// Sign convention: K u + Cᵀλ = f, so the constraint force on the nodes is −Cᵀλ.
/// Nothing here throws after create(); failures are reported in FemSolveStats.
#include "sim/fem/element.hpp"
#include "sim/fem/sparse_cholesky.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

enum class RefactorMode { Synchronous, Background };

struct FemSettings {
    double youngsModulus = 50e3; ///< Pa
    double poissonRatio = 0.45;  ///< in [0, 0.5)
    bool corotational = true;    ///< false: linear FEM, one factorization for the whole run
    /// Refactor when some edge vector turned by more than this many mean edge lengths (change normal
    /// to the edge) since the last factorization (the rotations are then re-extracted).
    double refactorDisplacement = 0.25;
    RefactorMode refactorMode = RefactorMode::Background;
    int refactorLatencySteps = 3;      ///< Background: solves between the request and the worker's join, >= 1
    double rankTolerance = 1e-9;       ///< relative pivot below which a row is rejected
    double releaseTolerance = 0;       ///< N; unilateral group released when Σ w λ exceeds it
    double activationTolerance = 1e-7; ///< m; inactive unilateral group activated when violated by more
    int maxActiveSetIterations = 6;
    /// Groups released in an active-set iteration leave the Schur factor by rank-one updates
    /// (O(rows²) each) instead of a factorization of every row after the first of them (O(rows³)).
    /// false: the reference path (same system, results equal to rounding).
    bool incrementalSchur = true;
    int cacheEvictSteps = 400; ///< constrained-node cache entries unused this long are freed (not pinned ones)
    /// Background: carried nodes whose K⁻¹ columns are computed with the new factor per solve (3
    /// substitutions each) between the worker's join and the swap (see beginStep()).
    int refactorNodesPerSolve = 4;
    int prefetchNodesPerSolve = 4; ///< queued nodes (prefetchNodes()) cached per solve, >= 0
    /// With steps (beginStep()/endStep()): the work a step may take, in substitutions (an active-set
    /// iteration past a solve's first counts as one: a burst of contacts costs about that much). The
    /// amortized work (carried columns, then prefetched nodes, three substitutions a node) fills what
    /// the step's solves left of it at endStep(), so a burst of new constraints is not made worse by
    /// work that can wait; a refactorization's carried columns still advance by one node a step.
    int stepSubstitutions = 18;
    /// Simplicial: cheapest for the few-column substitutions of the constrained-node cache.
    CholeskyMethod cholesky = CholeskyMethod::Simplicial;
};

/// Empty when valid, else the rule that failed ("poisson_ratio 0.5 must be in [0, 0.5)").
std::string validate(const FemSettings& s);

enum class ConstraintKind { Equality, Unilateral };

struct ConstraintTerm {
    int32_t node = 0;
    Vec3 a = Vec3::Zero(); ///< coefficient of the node's position
};

/// Σ_terms a · x_node = b, positions in metres (b in metres times the coefficient's unit).
struct ConstraintRow {
    std::vector<ConstraintTerm> terms;
    double b = 0;
};

struct ConstraintDesc {
    ConstraintKind kind = ConstraintKind::Equality;
    std::vector<ConstraintRow> rows;
    /// Unilateral only: per-row weights w of the release test Σ w_r λ_r > releaseTolerance and of
    /// the violation measure Σ w_r (c_r x − b_r) < −activationTolerance; empty = all 1.
    std::vector<double> weights;
    int priority = 0;        ///< rows are kept in (priority, id) order when they conflict
    bool startActive = true; ///< Unilateral: enforced from the first solve
};

enum class RowStatus { Inactive, Enforced, Redundant, Incompatible };

struct ConstraintState {
    bool active = false;           ///< Unilateral: currently enforced
    std::vector<double> lambda;    ///< per row, N (per unit coefficient); 0 when not enforced
    std::vector<RowStatus> status; ///< per row
};

struct FemSolveStats {
    int rows = 0;         ///< rows enforced
    int redundant = 0;    ///< rows rejected: dependent and consistent
    int incompatible = 0; ///< rows rejected: dependent and inconsistent
    int activeSetIterations = 0;
    int substitutions = 0; ///< forward/backward substitutions (columns) this solve
    int newCachedNodes = 0;
    bool refactored = false;      ///< a new factor was taken into use
    bool refactorStarted = false; ///< Background: this solve found the rotations stale and started the worker
    bool refactorWaited = false;  ///< Background: the worker was late; this solve computed its factor (timing only)
    bool finite = true;           ///< false: the result was not finite and was discarded
    std::string error;            ///< the last failure (empty when none)
};

/// Converged nonlinear static solution of a solve's problem (the measuring reference of the FEM's
/// error against run time): the minimizer of the corotational energy with the rotations taken from
/// the positions themselves, E(x) = Σ_e ½ d_eᵀ K_e d_e − f_extᵀ(x − x0), d_e = R_e(x)ᵀx_e − x0_e
/// (R_e the polar rotation of F_e; its gradient is Σ R_e K_e d_e exactly), under the rows the
/// solve enforced, as equalities. Newton from the solve's result: element Hessians by central
/// differences of that gradient, assembled exactly when that is positive definite, else projected
/// per element to positive semi-definite (reassembled every
/// `hessianRefresh` iterations), a KKT step through the Schur complement, Armijo backtracking on E. x* is the fixed
/// point that refactorizing every solve until the rotations stop changing would reach.
struct StaticReferenceSettings {
    double tolerance = 1e-9; ///< converged when ‖∇E + Cᵀμ‖∞ ≤ tolerance · max(‖·‖∞ at the start, 1e-6 N) …
    double stepTolerance = 1e-9; ///< … or the Newton step is below this many mean edge lengths
    int maxIterations = 60;
    double fdStep = 1e-6;   ///< central-difference step, relative to the mean edge length
    int hessianRefresh = 8; ///< iterations between two Hessian assemblies (modified Newton in between)
};
struct StaticReference {
    bool converged = false;
    int iterations = 0;
    std::vector<Vec3> x; ///< x*, metres
    double energy = 0;   ///< E(x*), J
    double residual = 0; ///< ‖∇E + Cᵀμ‖∞ at x*, N
    double seconds = 0;  ///< wall time of the reference solve
    std::string message; ///< why it stopped when not converged
};

class CorotationalFem {
public:
    /// Throws std::invalid_argument naming the rule: bad settings, fixed node out of range, an
    /// element with non-positive rest volume, external forces of the wrong size, or a stiffness
    /// matrix that is not positive definite (too few fixed nodes).
    static std::unique_ptr<CorotationalFem> create(const TetMesh& mesh, const std::vector<int32_t>& fixedNodes,
                                                   const FemSettings& settings, std::vector<Vec3> externalForces = {});
    ~CorotationalFem();
    CorotationalFem(const CorotationalFem&) = delete;
    CorotationalFem& operator=(const CorotationalFem&) = delete;

    // ---- constraints ------------------------------------------------------------------------
    /// Returns the group id (>= 0). Throws std::invalid_argument on a node out of range or a
    /// non-finite coefficient (this is set-up, not per-frame; per-frame users validate first).
    int addConstraint(ConstraintDesc desc);
    /// Replaces the rows (same count or not); keeps the id and the active flag.
    void setRows(int id, std::vector<ConstraintRow> rows);
    void setRhs(int id, int row, double b);
    void removeConstraint(int id);
    bool hasConstraint(int id) const;
    const ConstraintState& state(int id) const;
    const ConstraintDesc& constraint(int id) const;
    size_t constraintCount() const;

    // ---- solve ------------------------------------------------------------------------------
    /// One quasi-static solve with the current constraints. Never throws.
    FemSolveStats solve();
    /// Marks the start of a step (a frame) of one or more solves. Once called, the amortized work
    /// waits for endStep(), which gives it what the step's solves left of `stepSubstitutions`: a
    /// refactorization's carried columns first (between one and `refactorNodesPerSolve` nodes, so the
    /// new rotations still take effect within a bounded number of steps), then prefetched nodes (at
    /// most `prefetchNodesPerSolve`). A step with a burst of new constraints then does none of it.
    /// Never called: every solve does its full share. Counts only, never time: a run stays repeatable.
    void beginStep();
    /// Ends a step begun with beginStep(): the amortized work above, its substitutions in the
    /// returned stats. Never throws; without beginStep() it does nothing.
    FemSolveStats endStep();
    /// Re-extracts the rotations from the current positions and refactorizes now (synchronous).
    bool refactorNow(std::string* error = nullptr);
    /// The same with the rotations of positions x (nodeCount() entries), e.g. those a background
    /// refactorization was started from. False with `error` on a size mismatch or a failed factorization.
    bool refactorAt(const std::vector<Vec3>& x, std::string* error = nullptr);
    /// Background: a refactorization is in progress (worker or carried columns).
    bool refactorPending() const;
    /// Nodes kept in the constrained-node cache once cached (never evicted) and carried by a
    /// refactorization: the nodes a caller knows it will constrain again (replaces the set).
    void pinNodes(const std::vector<int32_t>& nodes);
    /// Queues nodes to be cached ahead of use, `prefetchNodesPerSolve` per solve (spreads the
    /// substitutions of a burst of new constraints over the steps before it). Fixed, cached or
    /// queued nodes are skipped; out-of-range ones ignored.
    void prefetchNodes(const std::vector<int32_t>& nodes);

    const std::vector<Vec3>& positions() const { return m_x; }
    const std::vector<Vec3>& restPositions() const { return m_x0; }
    size_t nodeCount() const { return m_x0.size(); }
    bool isFixed(int32_t node) const { return m_fixed[node] != 0; }
    /// Elastic energy ½ uᵀ K_R u − (f_R − f_ext)ᵀu of the current state under the current rotations, J.
    double elasticEnergy() const;
    /// E(x) of StaticReference (rotations from x itself), J. x has nodeCount() entries.
    double corotationalEnergy(const std::vector<Vec3>& x) const;
    /// The converged nonlinear static solution of the last solve's problem (its enforced rows as
    /// equalities), from positions(). Cost: per Newton iteration 24 polar decompositions per tet, one
    /// factorization and one substitution per enforced row. A measuring tool; never throws.
    StaticReference convergedStatic(const StaticReferenceSettings& settings = {}) const;
    int factorizations() const { return m_factorizations; }
    int cachedNodes() const;
    double meanEdgeLength() const { return m_meanEdge; }

    // ---- for tests and reports ----------------------------------------------------------------
    /// The assembled K_R (3#V × 3#V, full symmetric, fixed rows identity) and f_R of the current factor.
    Eigen::SparseMatrix<double> stiffnessMatrix() const;
    Eigen::VectorXd forceVector() const;
    /// The enforced rows of the last solve in displacement form (C u = b_u), in solve order, and
    /// their multipliers.
    void lastSystem(Eigen::MatrixXd& C, Eigen::VectorXd& bu, Eigen::VectorXd& lambda) const;

private:
    CorotationalFem() = default;
    struct Impl;
    std::unique_ptr<Impl> m;
    std::vector<Vec3> m_x0, m_x;
    std::vector<uint8_t> m_fixed;
    double m_meanEdge = 0;
    int m_factorizations = 0;
};

} // namespace viscera::sim
