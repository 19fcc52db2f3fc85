#include "sim/scene/interaction_runtime.hpp"

#include "sim/scene/tool_probe.hpp"
#include "sim/util/error.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

namespace viscera::sim {
namespace {

constexpr double kGraspClose = 0.5;    ///< jaw below this holds, above releases
constexpr double kGraspTouch = 0.0015; ///< m beyond a jaw's surface: tissue touching it is held
constexpr double kMaxJawOpening = 0.6; ///< rad, grasper jaws fully open (jaw = 1)

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// Rigid frame of an instrument: +x along the shaft towards the tip, origin at `origin`, turned
/// by `roll` (rad) about the shaft.
ToolShape::Pose framePose(const Vec3& origin, const Vec3& direction, double roll) {
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.linear() = Eigen::AngleAxisd(std::isfinite(roll) ? roll : 0.0, direction).toRotationMatrix() *
                 Eigen::Quaterniond::FromTwoVectors(Vec3::UnitX(), direction).toRotationMatrix();
    p.translation() = origin;
    return p;
}

/// Lumped inverse masses of a surface layer (areal density · area / 3 per vertex, fixed: 0).
std::vector<double> surfaceInverseMass(const TriMesh& mesh, double arealDensity, const std::vector<int32_t>& fixed) {
    std::vector<double> m(mesh.vertexCount(), 0.0);
    const auto& x = mesh.positions();
    for (const Tri& t : mesh.triangles()) {
        const double a = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm();
        for (int k = 0; k < 3; ++k)
            m[t[k]] += arealDensity * a / 3;
    }
    std::vector<double> w(m.size(), 0.0);
    for (size_t i = 0; i < m.size(); ++i)
        w[i] = m[i] > 0 ? 1.0 / m[i] : 0.0;
    for (int32_t f : fixed)
        w[f] = 0;
    return w;
}

} // namespace

struct InteractionRuntime::Instrument {
    InstrumentDesc desc;
    InstrumentTrack track;
    InstrumentKey key;
    std::optional<PortFrame> port;                           ///< desc.port, declared
    PortPose portPose;                                       ///< this frame, with a port
    std::unique_ptr<ToolShape> shape;                        ///< null: no collision (clip applier)
    std::vector<std::unique_ptr<CollisionSolver>> collision; ///< one per contact surface
    std::vector<XpbdIterationHook> hooks;
    bool colliding = false; ///< this frame
    // grasp
    bool holding = false;
    std::vector<size_t> held;    ///< particles of the contact surfaces
    std::vector<Vec3> heldLocal; ///< in the instrument frame at the grasp
    ToolShape::Pose pose = ToolShape::Pose::Identity();
    // scissors
    bool open = true;                         ///< the jaws were open (armed for the next snip)
    bool snip = false;                        ///< they closed this frame: the blade cuts
    std::optional<Vec3> cutAt;                ///< where it cut this frame (InstrumentState::cutAt)
    std::optional<std::array<Vec3, 3>> swept; ///< InstrumentState::swept
    /// scissors: the jaw the last frame they were open (the blades' sweep); holders: last frame's jaw
    double openJaw = 1;
    // clip applier
    size_t target = 0;  ///< tet body it clips
    bool fired = false; ///< fired during this squeeze (act held)
    int contacts = 0;
    // device drive
    bool driven = false;
    InstrumentKey drive;
    Vec3 holdImpulse = Vec3::Zero(); ///< kg·m: Σ m Δx of the grasp hold in the current substep
    Vec3 forceSum = Vec3::Zero();    ///< N, on the tissue, summed over the frame's substeps
    int forceSubsteps = 0;
    Vec3 force = Vec3::Zero(); ///< N, on the instrument, last frame
};

struct InteractionRuntime::Clip {
    size_t body = 0;
    std::unique_ptr<ClipAttachment> attachment;
    std::vector<int32_t> contactVertices; ///< vessel vertices the contact points sat on
    ClipState state;
};

InteractionRuntime::~InteractionRuntime() = default;

const std::vector<Vec3>& InteractionRuntime::contactPositions(const ContactSurface& c) const {
    return c.layer ? m_sys->surfacePositions(c.index) : m_sys->tetPositions(c.index);
}

namespace {

/// Per triangle of `body`'s boundary (its collision numbering): a triangle of `layer` was cut
/// from it (the layer is the body's boundary in a region, maybe midpoint-subdivided: a
/// triangle's middle child keeps its centroid, up to a bend applied after the subdivision), at
/// rest. A layer centroid within a sixth of the triangle's shortest edge of its centroid.
std::vector<uint8_t> coveredTriangles(const CollisionSurfaceDesc& body, const TriMesh& layer) {
    std::vector<Vec3> centres;
    for (const Tri& t : layer.triangles())
        centres.push_back((layer.positions()[t[0]] + layer.positions()[t[1]] + layer.positions()[t[2]]) / 3);
    std::sort(centres.begin(), centres.end(), [](const Vec3& a, const Vec3& b) { return a.x() < b.x(); });
    std::vector<uint8_t> covered(body.triangles.size(), 0);
    for (size_t f = 0; f < body.triangles.size(); ++f) {
        const Tri& t = body.triangles[f];
        const Vec3 &a = body.restPositions[t[0]], &b = body.restPositions[t[1]], &d = body.restPositions[t[2]];
        const Vec3 c = (a + b + d) / 3;
        const double tolerance = std::min({(b - a).norm(), (d - b).norm(), (a - d).norm()}) / 6;
        auto it = std::lower_bound(centres.begin(), centres.end(), c.x() - tolerance,
                                   [](const Vec3& a, double x) { return a.x() < x; });
        for (; it != centres.end() && it->x() <= c.x() + tolerance && !covered[f]; ++it)
            covered[f] = (*it - c).norm() <= tolerance;
    }
    return covered;
}

} // namespace

std::vector<InteractionRuntime::ContactSurface>
InteractionRuntime::contactSurfaces(const SceneDesc& scene, XpbdSystem& system,
                                    const std::vector<const TetMesh*>& bodies,
                                    const std::vector<const TriMesh*>& surfaces) {
    std::vector<ContactSurface> out;
    // a body's boundary, the nodes' lumped inverse masses (fixed: 0): the contact force on an
    // instrument is the tissue's momentum it changes (with unit masses it came out 10^4 too large)
    auto bodySurface = [&](size_t b) {
        ContactSurface c;
        c.index = b;
        c.particleOffset = static_cast<size_t>(system.tetParticleOffset(b));
        const TetMesh& m = *bodies.at(b);
        std::vector<double> w = lumpedMasses(m, scene.bodies[b].material.density, scene.bodies[b].fixedNodes);
        for (double& x : w)
            x = x > 0 ? 1.0 / x : 0.0;
        c.desc = CollisionSurfaceDesc::fromTetMesh(m, std::move(w));
        c.graspable.assign(m.vertexCount(), 1);
        return c;
    };
    if (surfaces.empty()) {
        out.push_back(bodySurface(0));
        return out;
    }
    ContactSurface layer;
    layer.layer = true;
    layer.particleOffset = static_cast<size_t>(system.surfaceParticleOffset(0));
    layer.desc.triangles = surfaces[0]->triangles();
    layer.desc.restPositions = surfaces[0]->positions();
    layer.desc.inverseMass =
        surfaceInverseMass(*surfaces[0], scene.surfaces[0].arealDensity, scene.surfaces[0].fixedNodes);
    layer.graspable.assign(surfaces[0]->vertexCount(), 1);
    out.push_back(std::move(layer));
    size_t under = 0;
    while (under < scene.bodies.size() && scene.bodies[under].name != scene.surfaces[0].attachTo)
        ++under;
    if (!scene.interaction->bareBody || under == scene.bodies.size())
        return out; // the tools meet the layer alone (or a free layer)
    // the body where the layer leaves it bare: its boundary triangles the layer was not cut from
    ContactSurface bare = bodySurface(under);
    const std::vector<uint8_t> covered = coveredTriangles(bare.desc, *surfaces[0]);
    std::vector<Tri> open;
    std::vector<uint8_t> onOpen(bare.graspable.size(), 0);
    for (size_t f = 0; f < covered.size(); ++f)
        if (!covered[f]) {
            open.push_back(bare.desc.triangles[f]);
            for (int32_t v : bare.desc.triangles[f])
                onOpen[static_cast<size_t>(v)] = 1;
        }
    if (open.empty()) return out;
    // under the layer the grasper holds the layer (its attachments carry the body), elsewhere the
    // body's bare surface: not the nodes inside it (under the layer they would be held through it)
    bare.graspable = std::move(onOpen);
    bare.desc.triangles = std::move(open);
    out.push_back(std::move(bare));
    return out;
}

void InteractionRuntime::makeDissection(const SceneDesc& scene, XpbdSystem& system,
                                        const std::vector<const TetMesh*>& bodies,
                                        const std::vector<const TriMesh*>& surfaces, const std::string& origin) {
    const InteractionDesc& desc = *scene.interaction;
    auto fail = [&](const std::string& field, const std::string& rule) {
        throw InputError(origin + ": interaction." + field + ": " + rule);
    };
    DissectionDesc dd;
    dd.system = &system;
    for (const DissectionTissueDesc& t : desc.tissues) {
        TissueDissectionParams p;
        p.ignition = t.ignitionC;
        p.conductivity = t.conductivity;
        p.shrink = t.shrink;
        bool found = false;
        for (size_t s = 0; s < scene.surfaces.size() && !found; ++s)
            if (scene.surfaces[s].name == t.layer) {
                if (dd.fascia) fail("tissues", "only one surface layer can be dissected");
                dd.fascia = surfaces[s];
                dd.surface = s;
                dd.fasciaTissue = p;
                m_dissectSurface = s;
                found = true;
            }
        for (size_t b = 0; b < scene.bodies.size() && !found; ++b)
            if (scene.bodies[b].name == t.layer) {
                if (dd.fat) fail("tissues", "only one tet body can be dissected");
                dd.fat = bodies[b];
                dd.tetBody = b;
                dd.fatTissue = p;
                m_dissectBody = b;
                found = true;
            }
        if (!found) fail("tissues", "'" + t.layer + "' is not a body or surface of the scene");
    }
    try {
        m_dissection = Dissection::create(dd);
    } catch (const std::invalid_argument& e) {
        fail("tissues", e.what());
    }
    if (dd.fascia) m_summary.fasciaVertices = m_summary.fasciaVerticesAtStart = dd.fascia->vertexCount();
}

std::unique_ptr<InteractionRuntime> InteractionRuntime::create(const SceneDesc& scene, XpbdSystem& system,
                                                               const std::vector<const TetMesh*>& bodies,
                                                               const std::vector<const TriMesh*>& surfaces,
                                                               const std::string& origin) {
    if (!scene.interaction)
        throw std::invalid_argument("sim::InteractionRuntime::create(): the scene has no interaction");
    const InteractionDesc& desc = *scene.interaction;
    auto fail = [&](const std::string& field, const std::string& rule) {
        throw InputError(origin + ": interaction." + field + ": " + rule);
    };
    std::unique_ptr<InteractionRuntime> r(new InteractionRuntime());
    r->m_sys = &system;
    r->m_bodies = bodies;

    r->m_contact = contactSurfaces(scene, system, bodies, surfaces);
    CollisionSettings cs;
    if (!parseCollisionMethod(desc.collisionMethod, cs.method))
        fail("collision", "unknown method '" + desc.collisionMethod + "'");
    cs.circumsphere.updateThreshold = desc.delta;
    if (auto why = validate(cs); !why.empty()) fail("collision", why);

    for (size_t i = 0; i < desc.instruments.size(); ++i) {
        auto in = std::make_unique<Instrument>();
        in->desc = desc.instruments[i];
        in->track = InstrumentTrack::parse(in->desc.trackText, origin + ": " + in->desc.trackPath);
        in->key = in->track.sample(0);
        if (in->desc.port.declared) {
            const PortDesc& pd = in->desc.port;
            if (const std::string why = restTipError(pd, in->key.position); !why.empty())
                fail("instruments[" + std::to_string(i) + "].port", "the track's first tip " + why);
            in->port = makePortFrame(pd, in->key.position, in->desc.device.motionScale);
            in->portPose = constrainToPort(*in->port, in->key.position);
            in->key.direction = in->portPose.direction;
        }
        switch (in->desc.kind) {
        case InstrumentDesc::Kind::Grasper:
        case InstrumentDesc::Kind::Scissors:
        case InstrumentDesc::Kind::NeedleDriver:
            in->shape =
                std::make_unique<ToolShape>(ToolShape::jaws(in->desc.jawLength, in->desc.radius, kMaxJawOpening));
            break;
        case InstrumentDesc::Kind::EnergyHook:
            in->shape = std::make_unique<ToolShape>(ToolShape::capsule(0.5 * in->desc.jawLength, in->desc.radius));
            break;
        case InstrumentDesc::Kind::ClipApplier: {
            size_t b = 0;
            while (b < scene.bodies.size() && scene.bodies[b].name != in->desc.target)
                ++b;
            if (b == scene.bodies.size())
                fail("instruments[" + std::to_string(i) + "].target", "'" + in->desc.target + "' is not a body");
            in->target = b;
            break;
        }
        }
        if (in->shape)
            for (const ContactSurface& c : r->m_contact) {
                try {
                    in->collision.push_back(CollisionSolver::create(c.desc, cs));
                } catch (const std::invalid_argument& e) {
                    fail("instruments[" + std::to_string(i) + "]", std::string("collision surface: ") + e.what());
                }
                in->hooks.push_back(makeCollisionHook(*in->collision.back(), *in->shape, c.particleOffset));
            }
        r->m_instruments.push_back(std::move(in));
    }

    if (desc.has(InstrumentDesc::Kind::EnergyHook) || desc.has(InstrumentDesc::Kind::Scissors))
        r->makeDissection(scene, system, bodies, surfaces, origin);
    InteractionRuntime* self = r.get();
    system.setIterationHook([self](XpbdParticles& p, const XpbdIterationInfo& info) { self->runHook(p, info); });
    // The hook touches the contact surfaces' particles only (contacts, grasped vertices), and
    // cuts never add particles.
    size_t first = SIZE_MAX, end = 0;
    for (const ContactSurface& c : r->m_contact) {
        first = std::min(first, c.particleOffset);
        end = std::max(end, c.particleOffset + r->contactPositions(c).size());
    }
    system.setIterationHookParticles(first, end - first);
    return r;
}

// The clip applier fires at the tip: a clip across the target vessel's local axis, on its nodes
// inside the jaws (none there, or a region it cannot hold: no clip, the session goes on).
void InteractionRuntime::fireClip(Instrument& in, double t) {
    const Vec3 dir = in.key.direction;
    in.fired = true;
    auto c = std::make_unique<Clip>();
    c->body = in.target;
    const std::vector<Vec3>& x = m_sys->tetPositions(c->body);
    // Clip frame: the vessel's local axis (principal direction of its nodes near the
    // tip), the jaw normal across it and the shaft, the closing direction between them.
    const double r = in.desc.jawLength;
    Vec3 mean = Vec3::Zero();
    int n = 0;
    for (const Vec3& p : x)
        if ((p - in.key.position).norm() < r) mean += p, ++n;
    if (n < 4) return; // nothing to clip here: the applier fires into empty space
    mean /= n;
    Mat3 cov = Mat3::Zero();
    for (const Vec3& p : x)
        if ((p - in.key.position).norm() < r) cov += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
    const Vec3 axis = eig.eigenvectors().col(2).normalized();
    Vec3 normal = axis.cross(dir);
    if (normal.norm() < 1e-6) normal = axis.unitOrthogonal();
    normal.normalize();
    const Vec3 third = axis.cross(normal).normalized();
    Mat3 axes;
    axes.col(0) = axis;
    axes.col(1) = normal;
    axes.col(2) = third;
    ClipDesc cd;
    cd.bounds = ClipBounds::box(in.key.position, axes, Vec3(0.001, 0.5 * r, 0.5 * r));
    cd.jawNormal = normal;
    for (int side : {-1, 1}) // the two legs of the clip, as segments' end points
        for (int end : {-1, 1})
            cd.vertices.push_back(in.key.position + side * 0.5 * r * normal + end * 0.5 * r * third);
    for (size_t v = 0; v < x.size(); ++v)
        if (cd.bounds.contains(x[v])) {
            cd.contactPoints.push_back(x[v]);
            c->contactVertices.push_back(static_cast<int32_t>(v));
        }
    try {
        c->attachment = ClipAttachment::apply(*m_bodies[c->body], x, cd);
    } catch (const std::invalid_argument&) {
        return; // a region the clip cannot hold (logged as no clip); the session goes on
    }
    c->state.instrument = in.desc.name;
    c->state.target = in.desc.target;
    c->state.firedAt = t;
    c->state.centre = c->attachment->centre();
    c->state.restCentre = c->attachment->restCentre();
    c->state.regionVertices = static_cast<int>(c->attachment->regionVertices().size());
    c->state.auxiliaryNodes = static_cast<int>(c->attachment->auxiliaryNodes().size());
    m_clips.push_back(std::move(c));
}

// Jaws that close take the surface vertices within a third of their length of the tip, and those
// touching their distal half as the jaws stood the frame before (a fold pressed between or
// against them: the capsule jaws, as thick as the shaft, leave too narrow a gap for the tissue to
// enter between them, so touching is what holds).
void InteractionRuntime::updateGrasp(Instrument& in) {
    const double jawBefore = std::exchange(in.openJaw, in.key.jaw);
    if (in.holding && in.key.jaw > kGraspClose) {
        in.holding = false;
        in.held.clear();
        in.heldLocal.clear();
    }
    if (in.holding || !(in.key.jaw < kGraspClose)) return;
    in.holding = true;
    in.held.clear();
    in.heldLocal.clear();
    const double reach = in.desc.jawLength / 3, L = in.desc.jawLength;
    const double touch = in.desc.radius + kGraspTouch;
    const double half = 0.5 * kMaxJawOpening * std::clamp(jawBefore, 0.0, 1.0);
    const Vec3 tips[2] = {L * Vec3(std::cos(half), 0, -std::sin(half)), L * Vec3(std::cos(half), 0, std::sin(half))};
    const ToolShape::Pose toJaws = in.pose.inverse();
    for (const ContactSurface& c : m_contact) {
        const std::vector<Vec3>& sx = contactPositions(c);
        for (size_t v = 0; v < sx.size(); ++v) {
            if (v < c.graspable.size() && !c.graspable[v]) continue;
            const Vec3 p = toJaws * sx[v];
            bool held = (sx[v] - in.key.position).norm() <= reach;
            for (const Vec3& tip : tips) {
                const double s = std::clamp(p.dot(tip) / tip.squaredNorm(), 0.5, 1.0); // the distal half
                held = held || (p - s * tip).norm() <= touch;
            }
            if (!held) continue;
            in.held.push_back(c.particleOffset + v);
            in.heldLocal.push_back(p);
        }
    }
    if (!in.held.empty()) ++m_summary.grasps;
}

void InteractionRuntime::beforeStep(double t, double dt) {
    auto t0 = std::chrono::steady_clock::now();
    // The contact surfaces' box, grown by what they can move in a frame: a tool outside it runs no
    // broad phase at all this frame (the hash rebuild per substep is the main collision cost).
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    for (const ContactSurface& c : m_contact)
        for (const Vec3& p : contactPositions(c))
            lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double grow = 0.005;
    lo.array() -= grow;
    hi.array() += grow;
    for (auto& inp : m_instruments) {
        Instrument& in = *inp;
        if (in.driven) {
            // The master's pose, the tip's move capped per frame.
            InstrumentKey k = in.drive;
            const Vec3 step = k.position - in.key.position;
            if (step.norm() > kMaxDrivenMovePerFrame)
                k.position = in.key.position + kMaxDrivenMovePerFrame * step.normalized();
            k.t = t;
            in.key = k;
        } else
            in.key = in.track.sample(t);
        if (in.port) {
            // Through the port: the shaft from the port towards the tip, the tip within its limits.
            in.portPose = constrainToPort(*in.port, in.key.position);
            in.key.position = in.portPose.tip;
            in.key.direction = in.portPose.direction;
        }
        in.forceSum = Vec3::Zero();
        in.forceSubsteps = 0;
        in.holdImpulse = Vec3::Zero();
        const Vec3 dir = in.key.direction;
        if (in.shape) {
            // Jaws and the hook's shaft end at the track's tip: the frame origin sits one jaw
            // length (grasper) or half the shaft piece (hook capsule centre) behind it.
            const double back = in.desc.hasJaws() ? in.desc.jawLength : 0.5 * in.desc.jawLength;
            in.pose = framePose(in.key.position - back * dir, dir, in.key.roll);
            in.shape->setPose(in.pose);
            in.shape->setOpening(kMaxJawOpening * in.key.jaw);
            const auto box = in.shape->bounds();
            const bool near = (box[0].array() <= hi.array()).all() && (box[1].array() >= lo.array()).all();
            // The energized hook passes through what it burns, the scissors' blades through what
            // they close on and cut (their push is not modelled: closed on the cut tissue, a
            // contact would throw it out of the blades in one substep).
            in.colliding = near && !(in.desc.kind == InstrumentDesc::Kind::EnergyHook && in.key.act) &&
                           in.desc.kind != InstrumentDesc::Kind::Scissors;
        }
        if (in.desc.kind == InstrumentDesc::Kind::Scissors) {
            // a snip as the jaws close (from open to below the grasp threshold): cut once, re-armed
            // when they open again
            in.snip = in.open && in.key.jaw < kGraspClose;
            in.open = in.key.jaw > kGraspClose;
            if (in.open) in.openJaw = in.key.jaw;
        }
        if (in.desc.holds()) updateGrasp(in);
        if (in.desc.kind == InstrumentDesc::Kind::ClipApplier) { // one clip per squeeze; re-armed on release
            if (!in.fired && in.key.act) fireClip(in, t);
            if (!in.key.act) in.fired = false;
        }
    }
    m_summary.clipMs += msSince(t0);
    // A frame with no tool near the tissue and nothing held has no hook work: it runs the
    // schedule without hooks (the force on every tool is then zero, as the hook would sum).
    bool hooks = false;
    for (const auto& inp : m_instruments)
        hooks = hooks || (!inp->collision.empty() && inp->colliding) || (inp->holding && !inp->held.empty());
    m_sys->setIterationHookActive(hooks);
    if (m_dissection) {
        t0 = std::chrono::steady_clock::now();
        for (auto& inp : m_instruments) {
            if (inp->desc.kind == InstrumentDesc::Kind::Scissors && inp->snip) {
                try { // the wedge the blades sweep: from the clevis to where their tips were open
                    const double half = 0.5 * kMaxJawOpening * inp->openJaw, len = inp->desc.jawLength;
                    const ToolShape::Pose& pose = inp->pose; // frame origin at the clevis, x along the jaws
                    const DissectionFrameStats st = m_dissection->shear(
                        pose.translation(), pose * Vec3(len * std::cos(half), 0, -len * std::sin(half)),
                        pose * Vec3(len * std::cos(half), 0, len * std::sin(half)), inp->desc.radius);
                    inp->cutAt = recordCut(st);
                    inp->swept = st.swept;
                } catch (const std::invalid_argument&) { // a non-finite pose: no cut this frame
                }
            }
            if (inp->desc.kind != InstrumentDesc::Kind::EnergyHook) continue;
            EnergyTool tool;
            tool.centre = inp->key.position;
            tool.radius = inp->desc.radius;
            tool.temperature = inp->desc.temperatureC;
            tool.energized = inp->key.act;
            try {
                recordCut(m_dissection->update(tool, dt)); // the hook's cut: where its tip is
            } catch (const std::invalid_argument&) {       // a non-finite tool pose: no heat this frame
            }
        }
        m_summary.dissectionMs += msSince(t0);
    }
}

std::optional<Vec3> InteractionRuntime::recordCut(const DissectionFrameStats& st) {
    m_summary.fasciaEdgesCut = static_cast<int>(st.fascia.totalEdgesCut);
    m_summary.fasciaTrianglesCut = static_cast<int>(st.fascia.totalPrimitivesCut);
    m_summary.fatEdgesCut = static_cast<int>(st.fat.totalEdgesCut);
    m_summary.fatTetsCut = static_cast<int>(st.fat.totalPrimitivesCut);
    if (m_dissection->hasFascia()) m_summary.fasciaVertices = st.fascia.vertexCount;
    m_summary.maxEdgeHeat = std::max({m_summary.maxEdgeHeat, st.fascia.maxEdgeHeat, st.fat.maxEdgeHeat});
    m_summary.gridMaxC = std::max(m_summary.gridMaxC, st.gridMax);
    const size_t n = st.fascia.edgesCut + st.fat.edgesCut;
    if (n == 0) return std::nullopt;
    return Vec3((static_cast<double>(st.fascia.edgesCut) * st.fascia.cutCentre +
                 static_cast<double>(st.fat.edgesCut) * st.fat.cutCentre) /
                static_cast<double>(n));
}

void InteractionRuntime::runHook(XpbdParticles& particles, const XpbdIterationInfo& info) {
    for (auto& inp : m_instruments) {
        Instrument& in = *inp;
        if (in.colliding)
            for (XpbdIterationHook& h : in.hooks)
                h(particles, info);
        if (info.velocityPass) { // the substep's force on the tissue: contacts and grasp hold
            Vec3 f = Vec3::Zero();
            if (in.colliding)
                for (const auto& c : in.collision)
                    f += c->contactForce();
            if (info.h > 0) f += in.holdImpulse / (info.h * info.h);
            in.holdImpulse = Vec3::Zero();
            in.forceSum += f;
            ++in.forceSubsteps;
            continue;
        }
        if (in.holding)
            for (size_t k = 0; k < in.held.size(); ++k) {
                const size_t p = in.held[k];
                if (p >= particles.size()) continue;
                const double w = particles.inverseMass(p);
                if (!(w > 0)) continue;
                const Vec3 target = in.pose * in.heldLocal[k];
                in.holdImpulse += (target - particles.position(p)) / w;
                particles.setPosition(p, target);
            }
    }
}

void InteractionRuntime::afterStep() {
    const auto t0 = std::chrono::steady_clock::now();
    m_summary.instruments.clear();
    int contacts = 0;
    for (auto& inp : m_instruments) {
        Instrument& in = *inp;
        in.force = in.forceSubsteps > 0 ? Vec3(-in.forceSum / in.forceSubsteps) : Vec3::Zero();
        if (!in.force.allFinite()) in.force = Vec3::Zero();
        InstrumentState s;
        s.name = in.desc.name;
        s.kind = kindName(in.desc.kind);
        s.tip = in.key.position;
        s.direction = in.key.direction;
        s.jaw = in.key.jaw;
        s.act = in.desc.kind == InstrumentDesc::Kind::Scissors ? in.snip : in.key.act; // scissors: cut this frame
        s.cutAt = std::exchange(in.cutAt, std::nullopt);
        s.swept = std::exchange(in.swept, std::nullopt);
        s.contacts = 0;
        if (in.colliding)
            for (const auto& c : in.collision)
                s.contacts += c->stats().contacts;
        s.grasped = static_cast<int>(in.held.size());
        s.force = in.force;
        s.driven = in.driven;
        s.shaftPoint = in.shape ? Vec3(in.pose.translation()) : in.key.position;
        s.shaftAxis = in.shape ? Vec3(in.pose.linear().col(0)) : in.key.direction;
        if (in.port) {
            s.insertion = in.portPose.insertion;
            s.atPortLimit = in.portPose.insertionLimited || in.portPose.angleLimited;
        }
        contacts += s.contacts;
        m_summary.instruments.push_back(s);
    }
    m_summary.maxContacts = std::max(m_summary.maxContacts, contacts);
    m_summary.clips.clear();
    for (auto& c : m_clips) {
        const std::vector<Vec3>& x = m_sys->tetPositions(c->body);
        c->attachment->update(x); // keeps the previous pose on non-finite input
        const Mat3 q = c->attachment->relativeRotation();
        c->state.centre = c->attachment->centre();
        c->state.rotationDeg = Eigen::AngleAxisd(q).angle() * 180.0 / M_PI;
        c->state.travel = (c->attachment->centre() - c->attachment->applicationCentre()).norm();
        const auto& cp = c->attachment->contactPoints();
        for (size_t k = 0; k < cp.size() && k < c->contactVertices.size(); ++k)
            c->state.maxContactDrift = std::max(c->state.maxContactDrift, (cp[k] - x[c->contactVertices[k]]).norm());
        const auto& cv = c->attachment->vertices();
        for (size_t k = 0; k < 4 && k < cv.size(); ++k)
            c->state.legs[k] = cv[k];
        m_summary.clips.push_back(c->state);
    }
    m_summary.clipMs += msSince(t0);
}

const InstrumentDesc& InteractionRuntime::instrumentDesc(size_t i) const {
    return m_instruments.at(i)->desc;
}

InstrumentKey InteractionRuntime::restKey(size_t i) const {
    const InstrumentTrack& tr = m_instruments.at(i)->track;
    return tr.keys().empty() ? InstrumentKey{} : tr.keys().front();
}

void InteractionRuntime::drive(size_t i, const InstrumentKey& key) {
    if (i >= m_instruments.size()) return;
    if (!key.position.allFinite() || !key.direction.allFinite() || !(key.direction.norm() > 1e-9) ||
        !std::isfinite(key.jaw))
        return;
    Instrument& in = *m_instruments[i];
    in.driven = true;
    in.drive = key;
    in.drive.direction.normalize();
    in.drive.jaw = std::clamp(key.jaw, 0.0, 1.0);
}

void InteractionRuntime::release(size_t i) {
    if (i < m_instruments.size()) m_instruments[i]->driven = false;
}

Vec3 InteractionRuntime::instrumentForce(size_t i) const {
    return i < m_instruments.size() ? m_instruments[i]->force : Vec3::Zero();
}

void InteractionRuntime::surfaceHeatInto(size_t s, std::vector<float>& out) const {
    out.clear();
    if (m_dissection && m_dissection->hasFascia() && s == m_dissectSurface) m_dissection->fasciaVertexHeatInto(out);
}

void InteractionRuntime::surfaceFaceMaskInto(size_t s, std::vector<uint8_t>& out) const {
    out.clear();
    if (m_dissection && m_dissection->hasFascia() && s == m_dissectSurface) m_dissection->fasciaFaceMaskInto(out);
}

bool InteractionRuntime::dissectsBody(size_t b) const {
    return m_dissection && m_dissection->hasFat() && b == m_dissectBody;
}

void InteractionRuntime::bodyTetMaskInto(size_t b, std::vector<uint8_t>& out) const {
    out.clear();
    if (dissectsBody(b)) m_dissection->fatTetMaskInto(out);
}

void InteractionRuntime::bodyHeatInto(size_t b, std::vector<float>& out) const {
    out.clear();
    if (dissectsBody(b)) m_dissection->fatVertexHeatInto(out);
}

} // namespace viscera::sim
