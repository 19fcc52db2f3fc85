#pragma once
/// Suturing on the quasi-static corotational FEM [B §3.1–3.3]: a rigid needle driven by poses,
/// its motion decomposed into sliding and sticking, the tip and the history of crossed cells
/// tracked through the tissue mesh, boundary puncture by a force threshold with motion playback,
/// slip through projected two-row constraints, transverse (sticking) constraints, a thread that
/// follows the needle's history and is pulled through a slack/engaged complementarity constraint
/// with distance linearization, and VF/EE contact between the boundary surfaces.
///
/// One step (Alg. 3.5): decompose the pose change into σ (sliding) and D (sticking); track the tip
/// over [ℓ, ℓ + σ] (forward) or pop history entries (backward); shift every entry's parameter by σ;
/// impose g[f_i]ξ_i = s(α_i) for the entries on the needle (0 ≤ α_i ≤ ℓ) [eq. 3.28]; when the tip
/// touches a boundary facet, hold the touched point to the tip, project the interior entries'
/// constraints to the plane normal to the needle (two rows, eq. 3.29) and puncture when the axial
/// component of the tip constraint's force exceeds the threshold (§3.2.3), replaying the logged
/// motion from first contact (§3.2.3.1); solve; detect contact and process it in time order.
/// The thread's puncture points (boundary entries behind the needle end, α < 0) carry the pull
/// constraint Σ L_i(r) ≤ ℓ_out [eq. 3.33], linearized per step [eq. 3.36] with the length smoothed
/// below `stabilization` (L = |d|²/(2ε) + ε/2 for |d| < ε, whose gradient d/max(|d|, ε) is the
/// stabilized direction), active only when engaged. Units: SI. Never throws from step().
#include "sim/contact/ccd.hpp"
#include "sim/fem/corotational_fem.hpp"
#include "sim/suture/needle_curve.hpp"
#include "sim/suture/tip_tracking.hpp"

#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace viscera::sim {

struct NeedleSpec {
    enum class Shape { Straight, Semicircle };
    Shape shape = Shape::Semicircle;
    double radius = 0.004;       ///< semicircle radius, m (length = π r)
    double length = 0.02;        ///< straight length, m
    double handle = 0.0;         ///< α of the grasp point used for the decomposition, m
    double punctureForce = 0.05; ///< axial force at which the tip punctures a boundary facet, N
    double length_() const;      ///< axial length ℓ, m
};

struct ThreadSpec {
    double length = 1.0;            ///< η: entries behind the needle end beyond −η are dropped, m
    double slack = 0.002;           ///< outside length above the taut length when the pull starts, m
    double stabilization = 2e-4;    ///< ε of the small-distance linearization, m
    double maxStrainPerStep = 0.05; ///< largest relative shortening κ of a segment per step [eq. 3.37]
};

/// Linearization of one outside thread segment r_a → r_b [B eq. 3.34–3.36], stabilized below ε:
/// length L = |d| for |d| >= ε, else |d|²/(2ε) + ε/2 (C¹ at ε, L(0) = ε/2 > 0); direction
/// d̂ = ∂L/∂r_b = d / max(|d|, ε); offset = L − d̂·d, so L(d') ≈ d̂·d' + offset to first order.
struct ThreadSegmentLinearization {
    double length = 0;             ///< m
    Vec3 direction = Vec3::Zero(); ///< dimensionless, |d̂| <= 1
    double offset = 0;             ///< m, zero for |d| >= ε
};
ThreadSegmentLinearization linearizeThreadSegment(const Vec3& ra, const Vec3& rb, double eps);

struct SutureSettings {
    FemSettings fem;
    NeedleSpec needle;
    ThreadSpec thread;
    bool contact = true;
    double contactThickness = 1e-6; ///< m, proximity of a coplanarity root counted as contact
    int contactRounds = 3;          ///< detect → add (time order) → solve rounds per step
    int contactsPerRound = 48;      ///< earliest collisions taken per round
    int maxContacts = 256;          ///< contact constraints held at most (bounds the dense solve)
    bool selfContact = false;       ///< also contact within one body (default: between bodies only)
    /// Contact ahead of time: the step's motion extrapolated this many steps is run through the
    /// detector and the nodes of the predicted contacts are queued for the FEM's constrained-node
    /// cache (CorotationalFem::prefetchNodes), so a burst of contacts finds its K⁻¹ columns ready.
    /// Changes no constraint, only when the work is done. 0 disables.
    int contactLookaheadSteps = 48;
    int contactLookaheadEvery = 4;          ///< steps between two predictions (the detection's cost, amortized)
    double contactLookaheadDistance = 1e-3; ///< m, cap of a node's extrapolated motion (a playback snap is no trend)
};

/// Empty when valid, else the rule that failed.
std::string validate(const SutureSettings& s);

struct NeedleFrame {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity(); ///< needle frame → world
    double pull = 0; ///< cumulative thread pull requested at the free end, m (>= 0)
};

/// Needle frame convention: semicircle centred at the frame origin in its xy-plane, end (α = 0) at
/// (r, 0, 0), tip (α = πr) at (−r, 0, 0) through (0, r, 0); straight needle from the origin along +x.
NeedleCurve needleCurve(const NeedleSpec& spec, const Eigen::Isometry3d& pose);
/// The pose slid by σ along the needle's own curve (rotation about the centre, or translation).
Eigen::Isometry3d slidePose(const NeedleSpec& spec, const Eigen::Isometry3d& pose, double sigma);
/// Sliding amount σ between two poses [B eq. 3.9, 3.12–3.17], m.
double slidingAmount(const NeedleSpec& spec, const Eigen::Isometry3d& from, const Eigen::Isometry3d& to);

struct HistoryEntry {
    int32_t face = kNone;   ///< half-facet crossed
    Vec3 xi = Vec3::Zero(); ///< barycentric point on `face`
    double alpha = 0;       ///< needle/thread parameter, m (needle: [0, ℓ]; thread: < 0)
    int32_t cell = kNone;   ///< cell entered (kNone = ⊥)
    bool entersMesh = false;
    bool exitsMesh = false;
    bool puncture() const { return entersMesh || exitsMesh; }
};

struct SutureStepStats {
    bool finite = true;
    int solves = 0;
    int activeRows = 0;    ///< constraint rows enforced in the last solve
    int rejectedRows = 0;  ///< redundant or incompatible rows in the last solve
    int needleEntries = 0; ///< history entries coupled to the needle
    int threadEntries = 0;
    int punctures = 0; ///< boundary punctures so far
    int contacts = 0;  ///< contact constraints in force
    int newContacts = 0;
    bool tipInContact = false;
    bool punctured = false;                ///< a puncture happened this step
    double sigma = 0;                      ///< sliding amount, m
    double needleForce = 0;                ///< resultant force of the tissue on the needle, N
    Vec3 needleForceVector = Vec3::Zero(); ///< N: that force as a vector (tissue on needle)
    double tipAxialForce = 0;              ///< axial force at a boundary contact, N
    double threadTension = 0;              ///< from the pull multiplier, N
    bool threadEngaged = false;
    bool refactored = false;
    bool refactorWaited = false; ///< a solve waited for the background factorization (timing only)
    int substitutions = 0;       ///< forward/backward substitutions (columns) of all solves this step
    int newCachedNodes = 0;      ///< constrained nodes whose K⁻¹ columns were computed this step
    int activeSetIterations = 0; ///< Schur solves of all FEM solves this step
    std::string error;
};

class SutureSimulation {
public:
    /// Takes the tissue mesh (all bodies in one mesh; level 3 is built here) and its fixed nodes.
    /// Throws std::invalid_argument naming the rule (settings, fixed nodes, stiffness not definite).
    static std::unique_ptr<SutureSimulation> create(std::unique_ptr<TetMesh> mesh, const std::vector<int32_t>& fixed,
                                                    const SutureSettings& settings,
                                                    const Eigen::Isometry3d& initialPose);
    ~SutureSimulation();
    SutureSimulation(const SutureSimulation&) = delete;
    SutureSimulation& operator=(const SutureSimulation&) = delete;

    /// One frame: the needle moves to frame.pose, the thread is pulled to frame.pull. Never throws;
    /// a non-finite pose or pull is ignored (reported in stats.error).
    SutureStepStats step(const NeedleFrame& frame);

    const TetMesh& mesh() const { return *m_mesh; }
    const std::vector<Vec3>& positions() const { return m_fem->positions(); }
    const CorotationalFem& fem() const { return *m_fem; }
    const std::vector<HistoryEntry>& history() const { return m_history; }
    const Eigen::Isometry3d& needlePose() const { return m_pose; }
    NeedleCurve curve() const { return needleCurve(m_s.needle, m_pose); }
    int punctures() const { return m_punctures; }
    /// Thread puncture points r_1 … r_m (positions now), in thread order.
    std::vector<Vec3> puncturePoints() const;
    Vec3 materialPoint(int32_t face, const Vec3& xi) const;

private:
    SutureSimulation() = default;
    struct Contact {
        int id = -1;
        Collision c;
        int inactiveSteps = 0;
    };
    int32_t topCell() const;
    void trackForward(const NeedleCurve& curve, double sigma, bool stopAtBoundary, SutureStepStats& st,
                      Crossing* boundaryHit);
    void shiftParameters(double sigma);
    void replay(const Eigen::Isometry3d& from, const std::vector<Eigen::Isometry3d>& log, bool allowPuncture,
                SutureStepStats& st);
    void clearNeedleConstraints();
    void addNeedleConstraints(bool slip);
    void updateThreadConstraint(double pull, SutureStepStats& st);
    void updateContacts();
    void processContacts(const std::vector<Vec3>& before, SutureStepStats& st);
    void prefetchAhead(const std::vector<Vec3>& before);
    void pinHistoryNodes();
    bool solve(SutureStepStats& st);
    void readForces(SutureStepStats& st);
    ConstraintRow pointRow(int32_t face, const Vec3& xi, const Vec3& dir, double b) const;
    static bool n_finite(const ConstraintRow& r);

    SutureSettings m_s;
    std::unique_ptr<TetMesh> m_mesh;
    std::unique_ptr<CorotationalFem> m_fem;
    std::unique_ptr<TipTracker> m_tracker;
    std::unique_ptr<ContactDetector> m_detector;
    Eigen::Isometry3d m_pose = Eigen::Isometry3d::Identity();
    std::vector<HistoryEntry> m_history;
    std::vector<int> m_needleIds;
    std::vector<int> m_needleEntryOf; // history index per needle constraint
    int m_punctures = 0;
    long m_steps = 0;
    // tip contact with a boundary facet (puncture in progress)
    struct TipContact {
        bool active = false;
        int32_t face = kNone;
        Vec3 xi = Vec3::Zero();
        int id = -1;
        Eigen::Isometry3d contactPose = Eigen::Isometry3d::Identity();
        std::vector<Eigen::Isometry3d> log;
        std::vector<HistoryEntry> snapshot;
    } m_tip;
    // thread
    std::vector<int> m_pullIds; // one unilateral group per outside segment [eq. 3.37]
    size_t m_pullSegments = 0;
    bool m_pullStarted = false;
    double m_outsideLength0 = 0;
    // contact
    std::vector<Contact> m_contacts;
};

} // namespace viscera::sim
