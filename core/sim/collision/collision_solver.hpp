#pragma once
/// Tool–tissue collision detection and response for XPBD [A §5.2].
///
/// Coupling to XPBD: makeCollisionHook (below) puts the contact constraints into the XPBD
/// iterations (after every elastic sweep, multipliers per substep, inelastic velocity pass);
/// stepWithCollision is the older after-the-substep coupling.
///
/// Pipeline per substep (beginStep): the triangles that can reach the tool (the reach list, kept
/// over the steps of a frame and beyond while surface and tool stay within its margins; see
/// CollisionSettings::reachListMargin), then the surface triangles' boxes (sphere methods: the sphere's;
/// circumsphere with the safe cone: the part of the sphere inside the cone) are tested against
/// the tool's box (Aabb of spatial_hash.hpp; one query per step, so no hash is built), which selects
/// the candidates in triangle order; for the circumsphere method the
/// candidates whose area changed by |S/S_ref − 1| >= δ since their last refresh get new curvature
/// and energy factors [A §5.2.4]. Then every iterate() is one Gauss–Seidel sweep over the
/// candidates × tool parts: narrow phase at the current positions, projection of each violated
/// contact constraint with XPBD multipliers (accumulated over the sweeps of a step, reset by
/// beginStep) and compliance α / h².
///
/// Narrow phases (CollisionMethod):
///   - Circumsphere [A §5.2.1–5.2.3]: the triangle's adaptive circumsphere (circumsphere.hpp,
///     centre recomputed every sweep from the current vertices with the cached factors) against
///     the tool's capsules. A contact translates the sphere out along the line from the closest
///     axis point to the sphere centre; the triangle's targets are x'_i = x_i + t, and the
///     unified triangle constraint C = √(Σ |x_i − x'_i|²) (the root of [A eq. 5.8], same zero
///     set and gradient direction, but one projection with α = 0 reaches the targets exactly;
///     settings.squaredForm uses Σ |x_i − x'_i|² itself, whose Gauss–Newton step only halves the
///     distance) moves the three vertices together. Only the sphere's converging surface (the
///     cap over the triangle, inside the safe cone of [A §5.2.1]) stands for the tissue surface;
///     the rest of the sphere lies under the neighbouring triangles. A tool that meets the
///     sphere outside the safe cone (settings.safeConeOnly, default on) is therefore not a
///     contact of this triangle: without that test the spheres of the triangles around a dent
///     reach under it and push the tissue away from the tool, the stretched triangles' spheres
///     grow, and a held tool sets the surface chattering (bench_collision: 0.5 mm per frame at
///     δ = 0.7 with the test off, 4e-8 m with it on).
///   - BoundingSphere [MO06]: the same with the triangle's bounding sphere (centroid, largest
///     vertex distance).
///   - Polygon [Eri04]: the closest points of the capsule axis and the triangle (vertex, edge or
///     face feature); a contact when closer than radius + margin, resolved by the point–triangle
///     constraint C = n·(Σ b_i x_i − q) − (r + margin) >= 0 with the barycentric weights b_i
///     (n from the axis point q to the triangle point; −N when the axis pierces the triangle).
///     One smooth constraint per triangle–capsule pair, whichever feature is closest.
///   - PolygonFeatures [Eri04] as [A §5.2.6] describes it: the vertex, edge and face primitives
///     of the candidate triangles tested separately, each type with its own constraint: every
///     candidate vertex against the capsule axis (C = |x_v − q| − reach, moves the vertex),
///     every candidate edge against the axis (closest points of the two segments, weights 1 − s
///     and s), and every candidate face whose closest point to the axis lies inside it
///     (barycentric weights). Shared vertices and edges are tested once per sweep. This is the
///     polygon baseline of the thesis' comparison; the switching between feature types is what
///     [A §5.2.6] names as the polygon method's source of instability at few iterations.
///
/// Only the tissue moves (the tool is kinematic, infinite mass). Fixed nodes (inverse mass 0) are
/// never moved. Results are deterministic (candidates in ascending order). Nothing here
/// allocates after the first steps of a run, prints or throws once created.
#include "sim/collision/circumsphere.hpp"
#include "sim/collision/spatial_hash.hpp"
#include "sim/collision/tool_shape.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

enum class CollisionMethod { Circumsphere, BoundingSphere, Polygon, PolygonFeatures };
const char* toString(CollisionMethod m);
/// The method named name (its toString); false for an unknown name.
bool parseCollisionMethod(const std::string& name, CollisionMethod& out);
constexpr const char* kCollisionMethodNames = "circumsphere, bounding_sphere, polygon, polygon_features";

struct CollisionSettings {
    CollisionMethod method = CollisionMethod::Circumsphere;
    CircumsphereParams circumsphere;
    double polygonMargin = 1e-3; ///< m, polygon method: contact distance beyond the tool surface
    double compliance = 0;       ///< m/N per contact constraint (0 = hard), divided by h²
    bool squaredForm = false;    ///< use [A eq. 5.8] literally (see above)
    bool safeConeOnly = true;    ///< circumsphere: contacts only through the safe cone (above)
    /// m: no vertex is moved farther than this by the sweeps of one step (a tool that starts
    /// deep inside the tissue pushes it out over several substeps instead of in one jump).
    double maxCorrectionPerStep = 0.002;
    /// m: the broad phase keeps a list of the triangles that could reach the tool as long as the
    /// vertices of the others move no more than this along any axis (far triangles: up to 16 ×
    /// this, see reachList) and the tool's box stays within reachListToolMargin of where it was
    /// when the list was made; while both hold, a step tests only the listed triangles, otherwise
    /// it tests every triangle and makes the list anew. The candidates (and
    /// so every result) are the same as without the list; 0 tests every triangle every step.
    /// The bound on a sphere's reach widens fast with the margin once it nears the triangles'
    /// size, so keep it well below their edges (0.1 mm for 2 mm triangles: the list is made
    /// about once per frame and per tool in the rectum case).
    double reachListMargin = 1e-4;
    /// m: how far the tool's box may move before the reach list is made anew (the tool is
    /// kinematic, one pose per frame; a wider margin lists a few more triangles).
    double reachListToolMargin = 0.002;
};

/// Empty when valid, otherwise the rule that failed.
std::string validate(const CollisionSettings& s);

struct CollisionSurfaceDesc {
    std::vector<Tri> triangles;      ///< outward counter-clockwise, indices into the body's nodes
    std::vector<Vec3> restPositions; ///< #V body nodes, m (rest shape for the energy factor)
    std::vector<double> inverseMass; ///< #V, 1/kg; 0 = fixed (never moved)

    /// The boundary of a tet mesh (level 3 must be built: mesh.requireLevel(3)), in the mesh's
    /// vertex numbering, with the given inverse masses (#V).
    static CollisionSurfaceDesc fromTetMesh(const TetMesh& mesh, std::vector<double> inverseMass);
};

struct CollisionStats {
    int candidates = 0;       ///< broad-phase candidate triangles of the step
    int contacts = 0;         ///< constraint projections in the last sweep
    int factorUpdates = 0;    ///< triangles whose curvature/energy factors were refreshed (δ test)
    double maxCorrection = 0; ///< m, largest vertex move of the last sweep
    int trianglesTested =
        0; ///< broad-phase tests of the step (a step that makes the reach list: #triangles + its length)
    bool reachListMade = false; ///< the step made the reach list anew (tested every triangle)
    int reachListGrown = 0;     ///< triangles the step added to the list (their vertices moved on)
};

/// The unified triangle constraint of [A eq. 5.8] for vertices x and targets x' (fixed):
/// squared: C = Σ |x_i − x'_i|², ∇_i C = 2 (x_i − x'_i); otherwise its root
/// C = √(Σ |x_i − x'_i|²), ∇_i C = (x_i − x'_i) / C (zero gradient at C = 0). grad may be null.
double unifiedTriangleConstraint(const std::array<Vec3, 3>& x, const std::array<Vec3, 3>& target, bool squared,
                                 std::array<Vec3, 3>* grad);
/// The polygon method's point–triangle constraint for fixed barycentric weights b and axis point
/// q: C = |Σ b_i x_i − q| − reach, ∇_i C = b_i n with n the unit direction from q (zero gradient
/// when the point is on q). grad may be null.
double pointTriangleConstraint(const std::array<Vec3, 3>& x, const Vec3& bary, const Vec3& q, double reach,
                               std::array<Vec3, 3>* grad);

class CollisionSolver {
public:
    /// Throws std::invalid_argument ("sim::CollisionSolver::create(): triangle 4 references
    /// vertex 99 (surface has 50 vertices)") on invalid settings, sizes, indices, non-finite or
    /// negative inverse masses.
    static std::unique_ptr<CollisionSolver> create(CollisionSurfaceDesc desc, const CollisionSettings& settings);
    CollisionSolver(const CollisionSolver&) = delete;
    CollisionSolver& operator=(const CollisionSolver&) = delete;
    ~CollisionSolver();

    /// Starts a substep of length h (s, > 0) at positions x (#V): broad phase against the tool at
    /// its current pose, δ update of the candidates' factors, multipliers reset.
    void beginStep(const std::vector<Vec3>& x, const ToolShape& tool, double h);
    /// One sweep over the candidates (positions in/out). Returns the number of projections.
    int iterate(std::vector<Vec3>& x, const ToolShape& tool);

    /// The same inside an XPBD iteration (XpbdIterationHook): the surface's vertex v is particle
    /// `offset + v` of `particles`. beginStep copies the #V positions once (broad phase, δ
    /// update); iterate reads and writes only the vertices of the candidate triangles, and never
    /// moves a particle whose inverse mass in `particles` is 0. A view too small for offset + #V
    /// gives an empty step (nothing moves). Allocation-free after the first steps.
    void beginStep(const XpbdParticles& particles, size_t offset, const ToolShape& tool, double h);
    int iterate(XpbdParticles& particles, size_t offset, const ToolShape& tool);
    /// Velocity pass of the step (XpbdIterationInfo::velocityPass): an inelastic contact with
    /// the kinematic tool [A §5.2.5, "update the velocity ... linear impulse and momentum"]. For
    /// every vertex the contacts moved in this step, the velocity component along its total
    /// contact push is removed where it points along the push (the push itself then adds no
    /// velocity; motion along the surface and towards the tool is kept). The tool counts as at
    /// rest within a step (its pose is a device sample). Returns the vertices changed.
    int endStep(XpbdParticles& particles, size_t offset);

    const CollisionStats& stats() const { return m_stats; }
    /// N: the force the contacts of the current step put on the tissue, Σ_v m_v Δx_v / h² over
    /// the vertices they moved (Δx_v: the vertex's total contact push of the step, m_v = 1/w_v;
    /// fixed vertices excluded). The tool feels its negative. Zero before the first step.
    Vec3 contactForce() const;
    /// Vertices of the triangles in contact during the current step (any sweep), ascending.
    const std::vector<int32_t>& contactVertices() const;
    const CollisionSettings& settings() const { return m_settings; }
    size_t triangleCount() const { return m_tris.size(); }
    const std::vector<Tri>& triangles() const { return m_tris; }

    /// The sphere a sphere method uses for triangle t at positions x with the cached factors
    /// (circumsphere or bounding sphere; for Polygon, the bounding sphere).
    Sphere triangleSphere(int32_t t, const std::vector<Vec3>& x) const;
    /// Cached curvature factor H3(K) and energy factor ε of triangle t (circumsphere method).
    double curvatureFactor(int32_t t) const { return m_h3[t]; }
    double energyFactor(int32_t t) const { return m_energy[t]; }
    /// Refreshes H3(K), ε and the reference area of every triangle now (e.g. after teleporting).
    void refreshAllFactors(const std::vector<Vec3>& x);

private:
    CollisionSolver() = default;
    void refreshFactors(int32_t t, const std::vector<Vec3>& x, double area);
    /// Broad phase of one triangle at x against the tool's box (the candidate test).
    bool broadPhaseHit(int32_t t, const std::vector<Vec3>& x, const Aabb& toolBox) const;
    /// How far beyond its vertex box the circumsphere method's sphere of triangle t (its safe-cone
    /// part where safeConeOnly) can reach at x, or at any x' within `margin` of x along each axis,
    /// with the cached factors. m.
    double circumsphereReach(int32_t t, const std::vector<Vec3>& x, double margin) const;
    /// Whether triangle t at m_reachX, its vertices moved by at most `margin` along each axis and
    /// its factors as cached, could pass broadPhaseHit against a tool box inside `grownTool`.
    bool mayReach(int32_t t, const std::vector<Vec3>& x0, double margin, const Aabb& grownTool) const;
    /// The triangles to test this step at x (ascending): the reach list, made anew when x or the
    /// tool left its margin; nullptr when every triangle must be tested (margin 0).
    const std::vector<int32_t>* reachList(const std::vector<Vec3>& x, const Aabb& toolBox);
    /// Lists the unlisted triangles of every vertex that left its allowance (kept ascending).
    void growReachList(const std::vector<Vec3>& x);
    bool projectSphere(int32_t t, const Sphere& s, const Capsule& c, double& lambda, std::vector<Vec3>& x);
    bool projectPolygon(int32_t t, const Capsule& c, double& lambda, std::vector<Vec3>& x);
    /// Distance constraint C = |Σ b_k x_{v_k} − q| − reach on n (1–3) vertices; false when not
    /// violated. `fallback` is the push direction when the point lies on the axis.
    bool projectDistance(const int32_t* v, const double* b, int n, const Vec3& q, double reach, const Vec3& fallback,
                         double& lambda, std::vector<Vec3>& x);
    int iterateFeatures(std::vector<Vec3>& x, const std::vector<Capsule>& parts);
    /// Contact constraints of the step per tool part: the candidate triangles (PolygonFeatures:
    /// and their unique edges and vertices). Sizes the multipliers.
    size_t constraintsPerPart() const;
    void capCorrection(int32_t v, std::vector<Vec3>& x) const;
    /// x[v] += delta within the per-step cap; records the push, the largest move and the contact.
    void applyCorrection(int32_t v, const Vec3& delta, std::vector<Vec3>& x);

    CollisionSettings m_settings;
    std::vector<Tri> m_tris;
    std::vector<Vec3> m_rest;
    std::vector<double> m_w;
    SurfaceCurvature m_curv;
    CubicHermite m_h3Spline;
    double m_offsetPerRadius = 0;                  ///< φ cot θ
    std::vector<double> m_h3, m_energy, m_refArea; ///< per triangle; m_refArea < 0: never set
    std::vector<int32_t> m_candidates;
    // Reach list (CollisionSettings::reachListMargin): triangles that could reach the tool while
    // the surface stays within the margin of m_reachX and the tool's box inside m_reachTool.
    // Triangles off the list are never candidates meanwhile, so their cached factors stay as the
    // list was made with them; refreshAllFactors drops the list.
    std::vector<int32_t> m_reach;
    std::vector<Vec3> m_reachX;
    std::vector<double> m_reachAllow;       ///< per vertex: how far it may move, per axis, while the list holds
    std::vector<uint8_t> m_inReach;         ///< per triangle: on the list
    size_t m_reachMadeSize = 0;             ///< the list's length when it was made
    std::vector<uint32_t> m_vertexTriStart; ///< #V + 1: triangles of each vertex in m_vertexTris
    std::vector<int32_t> m_vertexTris;
    Aabb m_reachTool;
    bool m_reachValid = false;
    std::vector<double> m_lambda; ///< #candidates × #parts (PolygonFeatures: faces, edges, vertices)
    std::vector<std::array<int32_t, 2>> m_candEdges; ///< PolygonFeatures: edges of the candidates
    std::vector<int32_t> m_featVerts;                ///< PolygonFeatures: vertices of the candidates
    std::vector<char> m_touched;                     ///< per vertex, this step
    std::vector<Vec3> m_start;                       ///< positions at beginStep
    std::vector<Vec3> m_push;                        ///< per vertex, sum of the contact moves of this step
    std::vector<Vec3> m_x;                           ///< particle-view steps: the surface's positions
    std::vector<int32_t> m_candVerts;                ///< vertices of the candidates of the step, ascending
    std::vector<char> m_mark;                        ///< per vertex, scratch
    bool m_viewValid = false;                        ///< particle-view step begun with a large enough view
    mutable std::vector<int32_t> m_contactVerts;
    mutable bool m_contactDirty = false;
    double m_alphaTilde = 0;
    double m_h = 0; ///< s, length of the current step
    CollisionStats m_stats;
};

/// The collision constraints as part of the XPBD iteration [A §5.2.5]: a hook for
/// XpbdSolver::setIterationHook / XpbdSystem::setIterationHook that, at the first sweep of every
/// substep, runs collision.beginStep at the tool's current pose (broad phase, δ update, contact
/// multipliers reset) and after every sweep one collision.iterate, so the contact multipliers
/// accumulate over the iterations of a substep like the elastic ones; in the substep's velocity
/// pass collision.endStep makes the contacts inelastic (a push adds no velocity). The surface's vertex v is particle
/// `particleOffset + v` (0 for an XpbdSolver; XpbdSystem::tetParticleOffset(b) for tet body b).
/// collision and tool are held by reference and must outlive the hook; set the tool's pose
/// between frames (device rate: the pose then holds for all substeps of the frame).
XpbdIterationHook makeCollisionHook(CollisionSolver& collision, const ToolShape& tool, size_t particleOffset = 0);

/// One frame of an XpbdSolver body with tool collision coupled per substep: the solver must run
/// one substep per step() (settings().substeps == 1, settings().dt == frame dt / substeps). For
/// each of `substeps` substeps the tool moves to the pose interpolated between `from` and `to`,
/// the solver takes its step (its own iterations over the elastic constraints), then
/// `iterations` collision sweeps project the contacts, and the moves they made are written back
/// with v += Δx / h (XpbdSolver::setState). The collision constraints are therefore solved after
/// the elastic ones in every substep, not interleaved with their sweeps; makeCollisionHook is
/// the in-iteration coupling of [A §5.2.5] (bench/bench_collision.cpp compares both). Never
/// throws; a non-finite collision result is dropped.
/// Velocity update after a collision projection moved positions from `before` to `after`
/// (#V each): the velocity component against each vertex's correction is removed (an inelastic
/// contact; a separating push adds no velocity, so a tool that starts inside the tissue or a
/// deep overlap cannot inject kinetic energy). Returns false when a value is not finite.
bool collisionVelocityUpdate(const std::vector<Vec3>& before, const std::vector<Vec3>& after, std::vector<Vec3>& v);

struct CollisionFrameResult {
    bool finite = true;
    double maxDisplacement = 0; ///< m, largest node move over the frame (XPBD's own stats)
    CollisionStats last;        ///< stats of the last substep
};
class XpbdSolver;
CollisionFrameResult stepWithCollision(XpbdSolver& solver, CollisionSolver& collision, ToolShape& tool,
                                       const ToolShape::Pose& from, const ToolShape::Pose& to, int substeps,
                                       int iterations);

} // namespace viscera::sim
