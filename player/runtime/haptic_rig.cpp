#include "runtime/haptic_rig.hpp"

#include "runtime/realtime_watch.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <pthread.h>
#include <sched.h>
#include <time.h>

namespace viscera::player {
namespace {

using haptics::kMaxArms;

} // namespace

int HapticRig::armFor(const std::string& hand, bool exclusive, int arms) const {
    if (arms == 2 && hand == "left") return 0;
    if (arms == 2 && hand == "right") return 1;
    for (int a = 0; a < arms; ++a)
        if (m_armTools[a].empty()) return a;
    return exclusive ? -1 : 0;
}

void HapticRig::mapArm(haptics::ServoConfig& cfg, int arm, const sim::Vec3& start, double motion, double force,
                       const sim::PortDesc* port) {
    haptics::ToolMapping& m = cfg.tools[arm];
    m.enabled = true;
    m.sceneStart = start;
    m.motionScale = motion;
    m.forceScale = force;
    m.throughPort = port && port->declared;
    if (m.throughPort) m.port = sim::makePortFrame(*port, start, motion);
}

void HapticRig::rigProbes(haptics::ServoConfig& cfg, int arms) {
    for (size_t t = 0; t < m_world.toolCount(); ++t) { // one arm each
        const sim::ToolDesc& d = m_world.toolDesc(t);
        int arm = armFor(d.hand, true, arms);
        if (arm >= 0 && !m_armTools[arm].empty()) arm = -1;
        m_tools.push_back({d.name, d.hand, arm, "probe", 0});
        RigTool rt;
        rt.kind = RigTool::Kind::Probe;
        rt.index = t;
        rt.arm = arm;
        m_rig.push_back(rt);
        m_caseMaxForce = std::min(m_caseMaxForce, d.maxForceN);
        if (arm < 0) continue;
        m_armTools[arm].push_back(static_cast<int>(m_rig.size() - 1));
        mapArm(cfg, arm, d.start, d.motionScale, d.forceScale, &d.port);
    }
}

void HapticRig::rigInstruments(haptics::ServoConfig& cfg, int arms) {
    sim::InteractionRuntime* in = m_world.interaction();
    if (!in) return;
    for (size_t i = 0; i < in->instrumentCount(); ++i) { // arms may be shared
        const sim::InstrumentDesc& d = in->instrumentDesc(i);
        if (!d.device.declared) continue;
        int arm = armFor(d.device.hand, false, arms);
        // An arm a probe holds is not shared.
        if (arm >= 0 && std::any_of(m_armTools[arm].begin(), m_armTools[arm].end(),
                                    [&](int k) { return m_rig[static_cast<size_t>(k)].kind == RigTool::Kind::Probe; }))
            arm = -1;
        m_tools.push_back({d.name, d.device.hand, arm, sim::kindName(d.kind), 0});
        RigTool rt;
        rt.kind = RigTool::Kind::Instrument;
        rt.index = i;
        rt.arm = arm;
        rt.gripOpen = d.device.gripOpenRad;
        rt.rest = in->restKey(i);
        m_rig.push_back(rt);
        m_caseMaxForce = std::min(m_caseMaxForce, d.device.maxForceN);
        if (arm < 0) continue;
        // The arm's first instrument sets its mapping: workspace centre at its rest tip, and
        // its port (the others on the arm are held to their own ports by the interaction).
        if (m_armTools[arm].empty())
            mapArm(cfg, arm, rt.rest.position, d.device.motionScale, d.device.forceScale, &d.port);
        else if (const sim::PortDesc& first = in->instrumentDesc(m_rig[size_t(m_armTools[arm][0])].index).port;
                 first.declared != d.port.declared || first.position != d.port.position || first.mode != d.port.mode)
            m_notes.push_back("instrument '" + d.name + "' shares its master with '" +
                              in->instrumentDesc(m_rig[size_t(m_armTools[arm][0])].index).name +
                              "' but not its port: the master is mapped through the first one's port");
        m_armTools[arm].push_back(static_cast<int>(m_rig.size() - 1));
    }
}

void HapticRig::rigNeedle(haptics::ServoConfig& cfg, int arms) {
    sim::NeedleDrive* nd = m_world.needleDrive();
    if (!nd || !m_world.scene().suture || !m_world.scene().suture->device.declared) return;
    // The needle holder on its hand; the thread on the other arm (its lift pulls).
    const sim::NeedleDeviceDesc& d = m_world.scene().suture->device;
    int arm = armFor(d.hand, true, arms);
    if (arm >= 0 && !m_armTools[arm].empty()) arm = -1;
    const sim::NeedleFrame rest = nd->restFrame();
    m_tools.push_back({"needle", d.hand, arm, "needle", 0});
    RigTool rt;
    rt.kind = RigTool::Kind::Needle;
    rt.arm = arm;
    rt.needleRest = rest.pose;
    m_rig.push_back(rt);
    m_caseMaxForce = std::min(m_caseMaxForce, d.maxForceN);
    if (arm >= 0) {
        m_armTools[arm].push_back(static_cast<int>(m_rig.size() - 1));
        mapArm(cfg, arm, rest.pose.translation(), d.motionScale, d.forceScale, nullptr);
    }
    int other = -1;
    for (int a = 0; a < arms; ++a)
        if (a != arm && m_armTools[a].empty()) other = a;
    const std::string otherHand = d.hand == "left" ? "right" : d.hand == "right" ? "left" : "any";
    m_tools.push_back({"thread", otherHand, other, "thread", 0});
    RigTool th;
    th.kind = RigTool::Kind::Thread;
    th.arm = other;
    th.pullScale = d.pullScale;
    m_rig.push_back(th);
    if (other >= 0) {
        m_armTools[other].push_back(static_cast<int>(m_rig.size() - 1));
        mapArm(cfg, other, sim::Vec3::Zero(), 1.0, d.forceScale, nullptr); // device metres: the lift itself
    }
}

HapticRig::HapticRig(haptics::Device& device, std::string spec, sim::World& world, bool realtime, bool keepTrace)
    : m_device(device), m_spec(std::move(spec)), m_world(world), m_realtime(realtime), m_keepTrace(keepTrace) {
    const haptics::DeviceCapabilities& caps = device.capabilities();
    const int arms = std::clamp(caps.arms, 1, kMaxArms);
    haptics::ServoConfig cfg;
    m_caseMaxForce = 15.0;
    rigProbes(cfg, arms);
    rigInstruments(cfg, arms);
    rigNeedle(cfg, arms);
    for (int a = 0; a < kMaxArms; ++a)
        if (!m_armTools[a].empty()) {
            RigTool& first = m_rig[static_cast<size_t>(m_armTools[a][0])];
            if (first.kind == RigTool::Kind::Instrument) first.offset = first.rest.position - cfg.tools[a].sceneStart;
        }
    if (const sim::Laparoscope* scope = world.laparoscope()) {
        const std::string& hand = scope->desc().hand;
        m_scopeArm = arms == 2 && hand == "right" ? 1 : 0;
        cfg.cameraPedalHolds = true;
    }
    cfg.safety.maxForce = m_caseMaxForce;
    if (m_realtime) {
        m_clock = std::make_unique<haptics::SteadyClock>();
    } else {
        auto c = std::make_unique<haptics::ManualClock>(0);
        m_manual = c.get();
        m_clock = std::move(c);
    }
    m_servoConfig = cfg;
}

int HapticRig::activeTool(int arm) const {
    if (arm < 0 || arm >= kMaxArms || m_armTools[arm].empty()) return -1;
    return m_armTools[arm][static_cast<size_t>(m_selected[arm]) % m_armTools[arm].size()];
}

std::vector<std::string> HapticRig::undrivenTools() const {
    std::vector<std::string> out;
    for (const auto& t : m_tools)
        if (t.arm < 0) out.push_back(t.name);
    return out;
}

bool HapticRig::drivesAnyTool() const {
    for (const auto& t : m_tools)
        if (t.arm >= 0) return true;
    return false;
}

HapticRig::~HapticRig() {
    if (m_servo) m_servo->stop();
}

void HapticRig::setServoWait(haptics::ServoWait wait, int cpu, int64_t spinNs) {
    m_servoConfig.wait = wait;
    m_servoConfig.cpu = cpu;
    if (spinNs >= 0) m_servoConfig.spin_ns = spinNs;
}

void HapticRig::configure(double dt) {
    m_dt = dt;
    // The simulation output may be three physics steps old (at least 50 ms) before the force goes.
    m_servoConfig.safety.maxSimAge_ns = std::max<int64_t>(50'000'000, int64_t(3 * dt * 1e9));
    m_servo = std::make_unique<haptics::ServoLoop>(m_device, *m_clock, m_servoConfig);
    m_audit = haptics::HandoverAudit(dt);
    m_audit.reserve(1 << 16); // 18 min at 60 Hz before the log grows on the physics thread
}

void HapticRig::publish() {
    const int64_t stamp = m_clock->now_ns();
    m_servo->publishContact(contactModel(stamp));
    // Completion time read after the write is visible (the fence drains the store buffer): a tick
    // that starts later must see this frame.
    std::atomic_thread_fence(std::memory_order_seq_cst);
    m_audit.published(m_frame, stamp, m_clock->now_ns());
}

haptics::LocalContactModel HapticRig::contactModel(int64_t now) const {
    haptics::LocalContactModel m;
    m.timestamp_ns = now;
    m.frame = m_frame;
    m.physicsPeriod_s = m_dt;
    const sim::InteractionRuntime* interaction = m_world.interaction();
    for (int a = 0; a < kMaxArms; ++a) {
        const int t = activeTool(a);
        if (t < 0) continue;
        const RigTool& rt = m_rig[static_cast<size_t>(t)];
        haptics::ToolContactModel& tm = m.tools[a];
        tm.active = true;
        if (rt.kind == RigTool::Kind::Needle || rt.kind == RigTool::Kind::Thread) {
            // Quasi-static FEM: the last step's force is held until the next one (k = 0).
            const sim::NeedleDrive* nd = m_world.needleDrive();
            sim::Vec3 f = sim::Vec3::Zero();
            if (nd) f = rt.kind == RigTool::Kind::Needle ? nd->needleForce() : sim::Vec3(0, 0, -nd->threadTension());
            const double fn = f.allFinite() ? f.norm() : 0.0;
            tm.p0 = m_armProxy[a];
            tm.f0 = fn;
            tm.n = fn > 0 ? sim::Vec3(f / fn) : sim::Vec3::UnitZ();
            tm.gap = fn > 0 ? 0.0 : 1e9;
            tm.k = 0;
        } else if (rt.kind == RigTool::Kind::Probe) {
            const sim::ToolContact& c = m_world.toolContact(rt.index);
            tm.p0 = c.centre;
            tm.n = c.normal;
            tm.f0 = c.force.norm();
            tm.gap = c.gap;
            tm.k = c.stiffness;
        } else if (interaction) {
            // An instrument pushes the tissue kinematically inside the XPBD iterations; its force
            // (contact pushes and grasp hold, InteractionRuntime::instrumentForce) is held until
            // the next physics frame (k = 0), at the servo proxy the step used.
            const sim::Vec3 f = interaction->instrumentForce(rt.index);
            const double fn = f.norm();
            tm.p0 = m_armProxy[a];
            tm.f0 = std::isfinite(fn) ? fn : 0.0;
            tm.n = tm.f0 > 0 ? sim::Vec3(f / fn) : sim::Vec3::UnitZ();
            tm.gap = tm.f0 > 0 ? 0.0 : 1e9;
            tm.k = 0;
        }
    }
    return m;
}

void HapticRig::start() {
    m_t0 = m_clock->now_ns();
    publish();
    if (m_realtime) {
        // With a CPU of its own for the servo, the physics thread gets a real-time priority below
        // the servo thread's, so other processes do not delay its publishes (ignored when the
        // system refuses). Sharing the CPUs, it stays SCHED_OTHER: a real-time physics thread
        // that runs behind real time would use up the kernel's real-time budget on the servo's
        // CPU (sched_rt_runtime_us), and the servo would be stopped with it for the rest of
        // each second (5-25 ms servo stalls measured so).
        if (m_servoConfig.cpu >= 0) {
            sched_param sp{};
            sp.sched_priority = 40;
            m_physicsRt = pthread_getschedparam(pthread_self(), &m_oldPolicy, &m_oldParam) == 0 &&
                          pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
        }
        m_servo->start();
        // The session's time zero is the servo's first tick, as in lockstep (where the first tick
        // runs at 0 and a replay starts at its first poll): frame k is due when the ticks before
        // (k+1)·dt from it have run. A servo that has not ticked within a second leaves the start
        // time (its frames then count as without input).
        const int64_t waitUntil = m_clock->now_ns() + 1'000'000'000;
        while (m_servo->firstTickNs() == INT64_MIN && m_clock->now_ns() < waitUntil)
            haptics::sleepUntilNs(m_clock->now_ns() + 100'000);
        if (m_servo->firstTickNs() != INT64_MIN) m_t0 = m_servo->firstTickNs();
        // The caller has kept this thread off the servo's CPU before the world was built, so the
        // solver's workers are off it too (player main); recorded for the report.
        m_physicsCpus = haptics::allowedCpus();
    }
}

void HapticRig::steerScope(const haptics::ToolPoseState& poses) {
    sim::Laparoscope* scope = m_world.laparoscope();
    if (!scope || m_scopeArm < 0) return;
    const bool cam = poses.tick != 0 && poses.connected && (poses.pedals & haptics::kPedalCamera) != 0;
    const haptics::Vec3& at = poses.device[m_scopeArm];
    const haptics::Quat& q = poses.orientation[m_scopeArm];
    if (cam && !scope->steering()) { // the pedal went down: the master's pose now is the reference
        scope->grab();
        m_scopeGrab = at;
        m_scopeGrabQ = q;
    }
    if (cam) {
        const haptics::Quat r = q * m_scopeGrabQ.inverse();
        scope->steer(at - m_scopeGrab,
                     sim::twistAbout(Eigen::Vector4d(r.w(), r.x(), r.y(), r.z()), sim::Vec3::UnitZ()));
    }
    scope->setSteering(cam);
}

void HapticRig::beforeStep() {
    // Frame k simulates [k dt, (k+1) dt) and takes the tool poses of the last servo tick before
    // (k+1) dt, in lockstep and in real time alike.
    const int64_t end = int64_t(std::llround(double(m_frame + 1) * m_dt * 1e9));
    if (m_manual) {
        const int64_t period = m_servo->periodNs();
        while (m_tick * period < end) {
            m_manual->set(m_tick * period);
            m_servo->tick(m_manual->now_ns());
            ++m_tick;
        }
        m_manual->set(end);
    }
    if (m_realtime) measureLag(m_t0 + end);
    const haptics::ToolPoseState poses = m_realtime ? framePoses(m_t0 + end) : m_servo->toolPoses();
    m_servo->notifyStepStart();
    steerScope(poses);
    sim::InteractionRuntime* interaction = m_world.interaction();
    std::array<int, kMaxArms> active{-1, -1};
    if (poses.tick != 0)
        for (int a = 0; a < kMaxArms; ++a) {
            if (m_armTools[a].empty()) continue;
            // The arm's first button hands it to its next instrument, which starts from where it waits.
            const bool down = (poses.buttons[a] & 1u) != 0;
            if (down && !m_buttonDown[a] && m_armTools[a].size() > 1) {
                m_selected[a] = (m_selected[a] + 1) % static_cast<int>(m_armTools[a].size());
                RigTool& next = m_rig[static_cast<size_t>(activeTool(a))];
                next.offset = next.rest.position - poses.proxy[a];
            }
            m_buttonDown[a] = down;
            active[a] = activeTool(a);
            m_armProxy[a] = poses.proxy[a];
        }
    for (size_t t = 0; t < m_rig.size(); ++t) {
        RigTool& rt = m_rig[t];
        const int a = rt.arm;
        const bool driven = a >= 0 && active[a] == static_cast<int>(t);
        if (rt.kind == RigTool::Kind::Probe) {
            if (driven) m_world.setToolPosition(rt.index, poses.proxy[a]);
            continue;
        }
        if (rt.kind == RigTool::Kind::Thread) {
            if (driven) rt.pull = std::max(rt.pull, rt.pullScale * std::max(0.0, poses.target[a].z()));
            continue;
        }
        if (rt.kind == RigTool::Kind::Needle) {
            sim::NeedleDrive* nd = m_world.needleDrive();
            if (!nd || !driven) continue;
            sim::NeedleFrame f;
            // The master's orientation turns the needle in its own frame: a roll about the master's
            // z is a turn about the needle's axis, which drives it along its curve.
            f.pose.linear() = rt.needleRest.linear() * poses.orientation[a].toRotationMatrix();
            f.pose.translation() = poses.proxy[a];
            for (const RigTool& th : m_rig)
                if (th.kind == RigTool::Kind::Thread) f.pull = th.pull;
            nd->drive(f);
            m_tools[t].drivenTime_s += m_dt;
            continue;
        }
        if (!interaction) continue;
        if (!driven) { // waits at its track's first key while the device is on
            interaction->drive(rt.index, rt.rest);
            continue;
        }
        sim::InstrumentKey k;
        k.position = poses.proxy[a] + rt.offset;
        k.direction = poses.orientation[a] * rt.rest.direction;
        // Through a port the shaft's direction is the port's (InteractionRuntime); the master's
        // twist about the shaft rolls the jaws.
        if (interaction->instrumentDesc(rt.index).port.declared) {
            const haptics::Quat& q = poses.orientation[a];
            k.roll = sim::twistAbout(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()), rt.rest.direction);
        }
        const bool grip = m_device.capabilities().arm[a].grip;
        k.jaw = grip ? std::clamp(poses.grip[a] / rt.gripOpen, 0.0, 1.0) : rt.rest.jaw;
        switch (interaction->instrumentDesc(rt.index).kind) {
        case sim::InstrumentDesc::Kind::EnergyHook:
            k.act = (poses.pedals & (haptics::kPedalEnergyCut | haptics::kPedalEnergyCoag)) != 0;
            break;
        case sim::InstrumentDesc::Kind::ClipApplier:
            k.act = k.jaw < 0.2; // the grip squeezed shut fires the clip
            break;
        case sim::InstrumentDesc::Kind::Grasper:
        case sim::InstrumentDesc::Kind::Scissors: // the jaws closing cut: the grip alone
        case sim::InstrumentDesc::Kind::NeedleDriver:
            k.act = false;
            break;
        }
        interaction->drive(rt.index, k);
        m_tools[t].drivenTime_s += m_dt;
    }
}

void HapticRig::measureLag(int64_t due) {
    m_lagMs = std::max(0.0, 1e-6 * double(m_clock->now_ns() - due));
    m_lagSumMs += m_lagMs;
    m_lagMaxMs = std::max(m_lagMaxMs, m_lagMs);
    if (m_lagMs > m_dt * 1e3) ++m_framesLate;
    if (m_frame == static_cast<int64_t>(RealTimeWatch::kWarmupFrames)) m_lagAtWarmupMs = m_lagMs;
    if (m_frame >= static_cast<int64_t>(RealTimeWatch::kWarmupFrames)) {
        m_lagGrowthMs = m_lagMs - m_lagAtWarmupMs;
        m_lagGrowthMaxMs = std::max(m_lagGrowthMaxMs, m_lagGrowthMs);
    }
}

haptics::ToolPoseState HapticRig::framePoses(int64_t due) {
    if (m_clock->now_ns() < due) haptics::sleepUntilNs(due);
    // Wait for the tick after `due` (at most a period away); a servo stalled for longer than
    // kMaxInputWaitNs, or input no longer kept (the physics over 8 s behind), gives the latest.
    constexpr int64_t kPollNs = 100'000, kMaxInputWaitNs = 50'000'000;
    const int64_t giveUp = m_clock->now_ns() + kMaxInputWaitNs;
    haptics::ToolPoseState p;
    while (true) {
        const haptics::PoseLookup found = m_servo->poseBefore(due, p);
        if (found == haptics::PoseLookup::Found) {
            // A servo that overran skipped the ticks just before `due`: the input is an earlier one.
            if (p.timestamp_ns < due - m_servo->periodNs()) ++m_inputEarlier;
            return p;
        }
        if (found == haptics::PoseLookup::Dropped || m_clock->now_ns() > giveUp) {
            ++m_inputMissed;
            return m_servo->toolPoses();
        }
        haptics::sleepUntilNs(m_clock->now_ns() + kPollNs);
    }
}

void HapticRig::afterStep() {
    ++m_frame;
    publish();
    drain();
}

void HapticRig::drain() {
    haptics::TraceSample s;
    while (m_servo->popTrace(s)) {
        ++m_samples;
        const double f = s.force.norm();
        m_metrics.maxForce_n = std::max(m_metrics.maxForce_n, f);
        m_forceSum += f;
        ++m_forceCount;
        if (s.contactAge_s >= 0 && m_dt > 0) m_maxAgeSteps = std::max(m_maxAgeSteps, s.contactAge_s / m_dt);
        if (s.t_ns != m_lastAuditTick) { // one sample per driven arm and tick, one model per tick
            m_audit.used(s.t_ns, s.contactFrame);
            m_lastAuditTick = s.t_ns;
        }
        if (m_keepTrace) m_trace.push_back(s);
    }
}

void HapticRig::finish() {
    if (m_servo) m_servo->stop();
    if (m_physicsRt) pthread_setschedparam(pthread_self(), m_oldPolicy, &m_oldParam);
    m_hadPhysicsRt = m_hadPhysicsRt || m_physicsRt;
    m_physicsRt = false;
    drain();
    m_metrics.time_s = double(m_frame) * m_dt;
    m_metrics.meanForce_n = m_forceCount ? m_forceSum / double(m_forceCount) : 0;
}

HapticsResult HapticRig::result() const {
    HapticsResult r;
    const haptics::DeviceCapabilities& caps = m_device.capabilities();
    r.spec = m_spec;
    r.backend = m_device.backend();
    r.name = caps.name;
    r.mode = m_realtime ? "realtime" : "lockstep";
    r.arms = caps.arms;
    r.pedals = caps.pedals;
    r.deviceMaxForce_n = caps.arm[0].maxForce;
    r.caseMaxForce_n = m_caseMaxForce;
    r.tools = m_tools;
    r.servo = m_servo->stats();
    r.link = m_device.linkStats();
    r.physicsPeriod_s = m_dt;
    r.maxContactAgeSteps = m_maxAgeSteps;
    r.handover = m_audit.figures();
    r.physicsRealtimePriority = m_physicsRt || m_hadPhysicsRt;
    r.physicsCpus = m_physicsCpus;
    r.lagMeanMs = m_frame > 0 ? m_lagSumMs / double(m_frame) : 0.0;
    r.lagMaxMs = m_lagMaxMs;
    r.framesLate = m_framesLate;
    r.inputMissed = m_inputMissed;
    r.inputEarlier = m_inputEarlier;
    r.lagGrowthMaxMs = m_lagGrowthMaxMs;
    r.traceSamples = m_samples;
    return r;
}

LiveState HapticRig::live() const {
    LiveState s;
    const haptics::ToolPoseState p = m_servo->toolPoses();
    s.time_s = double(m_frame) * m_dt;
    s.frame = static_cast<int>(m_frame);
    s.connected = p.connected;
    s.pedals = p.pedals;
    s.safetyRules = p.safetyRules;
    s.maxForce_n = m_caseMaxForce;
    s.lagMs = m_lagMs;
    s.lagGrowthMs = std::max(0.0, m_lagGrowthMs);
    s.lagGrowthMaxMs = std::max(0.0, m_lagGrowthMaxMs);
    const sim::InteractionRuntime* interaction = m_world.interaction();
    for (int a = 0; a < kMaxArms; ++a) {
        s.force[a] = p.force[a];
        const int t = activeTool(a);
        s.toolActive[a] = t >= 0;
        if (t < 0) continue;
        const RigTool& rt = m_rig[static_cast<size_t>(t)];
        if (rt.kind == RigTool::Kind::Probe)
            s.tool[a] = m_world.toolContact(rt.index).centre;
        else if (rt.kind == RigTool::Kind::Needle || rt.kind == RigTool::Kind::Thread)
            s.tool[a] = m_armProxy[a];
        else if (interaction && rt.index < interaction->summary().instruments.size())
            s.tool[a] = interaction->summary().instruments[rt.index].tip;
        s.toolName[a] = m_tools[static_cast<size_t>(t)].name;
    }
    return s;
}

} // namespace viscera::player
