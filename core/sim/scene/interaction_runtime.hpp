#pragma once
/// The scene's "interaction" section at run time (interaction.hpp): scripted instruments on their
/// recorded tracks acting on a layered XPBD system [A ch. 5].
///
/// Per frame (World::step): beforeStep(t, dt) samples every track at the frame's end time, poses
/// the tools, starts or ends grasps, fires clips, runs the energized dissection (heat grid, edge
/// temperatures, cuts, shrinkage) and arms the XPBD iteration hook; the solver then runs the tool
/// contacts and the grasp holds inside its iterations; afterStep() moves the clips with their
/// vessels and records the figures.
///   - Collision [A §5.2]: every grasper and every energy hook while its energy is off collides
///     with the contact surfaces, each through its own CollisionSolver per surface; a live energy
///     hook cuts instead of pushing. The contact surfaces: the first surface layer and, with
///     collision.bare_body, the boundary of the body it is attached to where it does not cover
///     it (a peritoneum over part of an organ: the tools meet the layer there and the bare organ
///     elsewhere); without a layer the boundary of the first tet body.
///   - Grasp: when a grasper's jaw closes below 0.5 the contact-surface vertices within
///     jaw_length / 3 of its tip (and those touching its jaws) are held rigidly in the
///     instrument's frame (set inside every XPBD iteration) until the jaw opens above 0.5.
///   - Dissection [A §5.3]: sim/dissection (feature "dissection").
///   - Clip [A §5.4]: sim/clip, fired at a clip applier's first key with act = 1 (feature "clip").
/// Deterministic: repeat runs are bit-identical.
#include "sim/clip/clip_attachment.hpp"
#include "sim/collision/collision_solver.hpp"
#include "sim/dissection/dissection.hpp"
#include "sim/scene/interaction.hpp"
#include "sim/scene/scene.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {

struct InstrumentState {
    std::string name;
    const char* kind = "";
    Vec3 tip = Vec3::Zero();
    Vec3 direction = -Vec3::UnitZ();
    double jaw = 1;
    bool act = false;
    /// m: where the scissors cut this frame, the mean midpoint of the edges they cut; none when
    /// they cut nothing (and for the hook, whose cut is at its tip).
    std::optional<Vec3> cutAt;
    /// m: scissors, the wedge their blades swept as they cut this frame (DissectionFrameStats::swept).
    std::optional<std::array<Vec3, 3>> swept;
    int contacts = 0;          ///< collision projections in the last sweep of the frame
    int grasped = 0;           ///< vertices held
    Vec3 force = Vec3::Zero(); ///< N, on the instrument from the tissue, mean over the frame's substeps
    bool driven = false;       ///< a device drove it this frame (else its track)
    /// With a port (InstrumentDesc::port): port to tip (m), and whether the tip was held back
    /// at the port's insertion or angle limit this frame.
    double insertion = 0;
    bool atPortLimit = false;
    /// The shaft of the collision shape as posed this frame (its frame's origin and +x axis,
    /// towards the tip); the tip and direction for an instrument without a shape.
    Vec3 shaftPoint = Vec3::Zero();
    Vec3 shaftAxis = -Vec3::UnitZ();
};

struct ClipState {
    std::string instrument, target;
    double firedAt = 0;         ///< s
    Vec3 centre = Vec3::Zero(); ///< m, current
    /// m, the vessel's rest pose: where on the anatomy the clip holds (the centre of its region at
    /// rest), whatever the tissue's sag or retraction when it fired.
    Vec3 restCentre = Vec3::Zero();
    double rotationDeg = 0; ///< since application
    double travel = 0;      ///< m, centre moved since application
    /// m: largest distance between a contact point carried by the clip and the vessel vertex it
    /// was on at application (how well the clip follows the vessel material).
    double maxContactDrift = 0;
    int regionVertices = 0, auxiliaryNodes = 0;
    /// m, current: the end points of the clip's two legs (leg 0: [0]–[1], leg 1: [2]–[3]).
    std::array<Vec3, 4> legs{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

struct InteractionSummary {
    std::vector<InstrumentState> instruments; ///< at the last frame
    int maxContacts = 0;
    int grasps = 0;
    int fasciaEdgesCut = 0, fasciaTrianglesCut = 0, fatEdgesCut = 0, fatTetsCut = 0;
    size_t fasciaVertices = 0, fasciaVerticesAtStart = 0;
    double maxEdgeHeat = 0; ///< °C
    double gridMaxC = 0;    ///< °C, hottest heat-grid value seen
    std::vector<ClipState> clips;
    double dissectionMs = 0, clipMs = 0; ///< wall time summed over frames (collision runs inside the XPBD step)
};

class InteractionRuntime {
public:
    /// Throws viscera::InputError naming `origin` on a bad track, a tissue layer or clip target
    /// the system does not have, or a collision surface that cannot be built.
    /// bodies[i] / surfaces[s]: the rest meshes of scene.bodies[i] / scene.surfaces[s], as given
    /// to the system (non-owning; must outlive the runtime).
    static std::unique_ptr<InteractionRuntime> create(const SceneDesc& scene, XpbdSystem& system,
                                                      const std::vector<const TetMesh*>& bodies,
                                                      const std::vector<const TriMesh*>& surfaces,
                                                      const std::string& origin);
    ~InteractionRuntime();
    InteractionRuntime(const InteractionRuntime&) = delete;
    InteractionRuntime& operator=(const InteractionRuntime&) = delete;

    /// Before XpbdSystem::step() of the frame that ends at time t (s). Never throws.
    void beforeStep(double t, double dt);
    /// After the step. Never throws.
    void afterStep();

    const InteractionSummary& summary() const { return m_summary; }

    // ---- instruments driven by a device (InstrumentDesc::device) --------------------------------
    size_t instrumentCount() const { return m_instruments.size(); }
    const InstrumentDesc& instrumentDesc(size_t i) const;
    /// The first key of instrument i's track: where a driven instrument's master has its
    /// workspace centre, and where an instrument waits while no arm drives it.
    InstrumentKey restKey(size_t i) const;
    /// From the next beforeStep on, instrument i takes `key` (position, direction, jaw, act; t is
    /// ignored) instead of its track, until release(i). A key with a non-finite value is
    /// ignored; the tip moves at most kMaxDrivenMovePerFrame per frame towards it (no tunnelling
    /// through the fascia on a jump of the master).
    void drive(size_t i, const InstrumentKey& key);
    void release(size_t i);
    /// N: force on instrument i from the tissue over the last frame (mean over its substeps of the
    /// contact pushes and the grasp hold, InstrumentState::force).
    Vec3 instrumentForce(size_t i) const;
    static constexpr double kMaxDrivenMovePerFrame = 0.003; ///< m
    /// Render mask of surface s: 1 per intact triangle (empty: no dissection on that surface).
    void surfaceFaceMaskInto(size_t s, std::vector<uint8_t>& out) const;
    /// Heat of surface s per vertex in [0, 1] (Dissection::fasciaVertexHeatInto; empty: no
    /// dissection on that surface).
    void surfaceHeatInto(size_t s, std::vector<float>& out) const;
    bool dissects() const { return m_dissection != nullptr; }
    /// Body b is the tet layer the energy hook cuts (its render shows the cut surface).
    bool dissectsBody(size_t b) const;
    /// Body b's tets: 1 intact, 0 cut (empty: b is not dissected).
    void bodyTetMaskInto(size_t b, std::vector<uint8_t>& out) const;
    /// Heat of body b per node in [0, 1] (Dissection::fatVertexHeatInto; empty: not dissected).
    void bodyHeatInto(size_t b, std::vector<float>& out) const;

private:
    struct Instrument;
    struct Clip;
    InteractionRuntime() = default;
    void runHook(XpbdParticles& particles, const XpbdIterationInfo& info);
    /// The dissection of the tissues the hook and the scissors cut (InputError naming the field).
    void makeDissection(const SceneDesc& scene, XpbdSystem& system, const std::vector<const TetMesh*>& bodies,
                        const std::vector<const TriMesh*>& surfaces, const std::string& origin);
    /// A cut's totals (hook or scissors) into the summary.
    /// Takes the frame's cut figures; returns where it cut (the mean midpoint of the edges cut),
    /// none when nothing was cut.
    std::optional<Vec3> recordCut(const DissectionFrameStats& st);
    void fireClip(Instrument& in, double t);
    /// A holder's jaws: closing takes the surface vertices they hold, opening lets them go.
    void updateGrasp(Instrument& in);

    XpbdSystem* m_sys = nullptr;
    std::vector<const TetMesh*> m_bodies;
    std::vector<std::unique_ptr<Instrument>> m_instruments;
    std::vector<std::unique_ptr<Clip>> m_clips;
    std::unique_ptr<Dissection> m_dissection;
    size_t m_dissectSurface = SIZE_MAX;
    size_t m_dissectBody = SIZE_MAX;
    /// What the tools touch (see the file comment): a surface layer or a tet body's boundary.
    struct ContactSurface {
        bool layer = false;
        size_t index = 0;               ///< scene.surfaces / scene.bodies index
        size_t particleOffset = 0;      ///< its first particle in the XPBD system
        CollisionSurfaceDesc desc;      ///< the triangles the tools meet
        std::vector<uint8_t> graspable; ///< per vertex: a closing grasper may hold it
    };
    /// The contact surfaces of the scene (InputError naming `origin` when one cannot be built).
    static std::vector<ContactSurface> contactSurfaces(const SceneDesc& scene, XpbdSystem& system,
                                                       const std::vector<const TetMesh*>& bodies,
                                                       const std::vector<const TriMesh*>& surfaces);
    const std::vector<Vec3>& contactPositions(const ContactSurface& c) const;

    std::vector<ContactSurface> m_contact;
    InteractionSummary m_summary;
};

} // namespace viscera::sim
