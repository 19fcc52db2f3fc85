#include "runtime/haptic_rig.hpp"

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

HapticRig::HapticRig(haptics::Device& device, std::string spec, sim::World& world, bool realtime, bool keepTrace)
    : m_device(device), m_spec(std::move(spec)), m_world(world), m_realtime(realtime), m_keepTrace(keepTrace) {
    const haptics::DeviceCapabilities& caps = device.capabilities();
    const int arms = std::clamp(caps.arms, 1, kMaxArms);
    haptics::ServoConfig cfg;
    std::array<bool, kMaxArms> used{false, false};
    m_caseMaxForce = 15.0;
    for (size_t t = 0; t < world.toolCount(); ++t) {
        const sim::ToolDesc& d = world.toolDesc(t);
        int arm = -1;
        if (arms == 2 && d.hand == "left")
            arm = 0;
        else if (arms == 2 && d.hand == "right")
            arm = 1;
        else
            for (int a = 0; a < arms; ++a)
                if (!used[a]) {
                    arm = a;
                    break;
                }
        if (arm >= 0 && used[arm]) arm = -1;
        m_tools.push_back({d.name, d.hand, arm});
        m_caseMaxForce = std::min(m_caseMaxForce, d.maxForceN);
        if (arm < 0) continue;
        used[arm] = true;
        m_toolOfArm[arm] = static_cast<int>(t);
        haptics::ToolMapping& m = cfg.tools[arm];
        m.enabled = true;
        m.sceneStart = d.start;
        m.motionScale = d.motionScale;
        m.forceScale = d.forceScale;
    }
    m_aboveDamage.assign(world.toolCount(), false);
    m_metrics.toolPathLengthPerTool_m.assign(world.toolCount(), 0.0);
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
    for (int a = 0; a < kMaxArms; ++a) {
        const int t = m_toolOfArm[a];
        if (t < 0) continue;
        const sim::ToolContact& c = m_world.toolContact(static_cast<size_t>(t));
        haptics::ToolContactModel& tm = m.tools[a];
        tm.active = true;
        tm.p0 = c.centre;
        tm.n = c.normal;
        tm.f0 = c.force.norm();
        tm.gap = c.gap;
        tm.k = c.stiffness;
    }
    return m;
}

void HapticRig::start() {
    m_t0 = m_clock->now_ns();
    publish();
    if (m_realtime) {
        // The physics thread gets a real-time priority below the servo thread's, so other
        // processes do not delay its publishes (ignored when the system refuses).
        sched_param sp{};
        sp.sched_priority = 40;
        m_physicsRt = pthread_getschedparam(pthread_self(), &m_oldPolicy, &m_oldParam) == 0 &&
                      pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
        m_servo->start();
        // The caller has kept this thread off the servo's CPU before the world was built, so the
        // solver's workers are off it too (player main); recorded for the report.
        m_physicsCpus = haptics::allowedCpus();
    }
}

void HapticRig::beforeStep() {
    if (m_manual) {
        const int64_t end = int64_t(std::llround(double(m_frame + 1) * m_dt * 1e9));
        while (m_tick * 1'000'000 < end) {
            m_manual->set(m_tick * 1'000'000);
            m_servo->tick(m_manual->now_ns());
            ++m_tick;
        }
        m_manual->set(end);
    }
    m_servo->notifyStepStart();
    const haptics::ToolPoseState poses = m_servo->toolPoses();
    if (poses.tick == 0) return;
    for (int a = 0; a < kMaxArms; ++a)
        if (m_toolOfArm[a] >= 0) m_world.setToolPosition(static_cast<size_t>(m_toolOfArm[a]), poses.proxy[a]);
}

void HapticRig::afterStep() {
    ++m_frame;
    publish();
    for (size_t t = 0; t < m_world.toolCount(); ++t) {
        const double f = m_world.toolContact(t).force.norm();
        const double thr = m_world.toolDesc(t).damageForceN;
        m_metrics.maxContactForce_n = std::max(m_metrics.maxContactForce_n, f);
        if (f > thr) {
            m_metrics.tissueDamage_ns += (f - thr) * m_dt;
            if (!m_aboveDamage[t]) ++m_metrics.damageEvents;
        }
        m_aboveDamage[t] = f > thr;
    }
    drain();
    if (m_realtime) {
        const int64_t deadline = m_t0 + int64_t(std::llround(double(m_frame) * m_dt * 1e9));
        if (deadline > m_clock->now_ns()) haptics::sleepUntilNs(deadline);
    }
}

void HapticRig::drain() {
    haptics::TraceSample s;
    while (m_servo->popTrace(s)) {
        ++m_samples;
        const int a = s.arm;
        const double f = s.force.norm();
        m_metrics.maxForce_n = std::max(m_metrics.maxForce_n, f);
        m_forceSum += f;
        ++m_forceCount;
        if (f > 0) m_contactSum += f, ++m_contactCount;
        if (m_haveLast[a] && m_toolOfArm[a] >= 0) {
            const double d = (s.tool - m_last[a]).norm();
            m_metrics.toolPathLength_m += d;
            m_metrics.toolPathLengthPerTool_m[static_cast<size_t>(m_toolOfArm[a])] += d;
        }
        m_last[a] = s.tool;
        m_haveLast[a] = true;
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
    m_metrics.meanContactForce_n = m_contactCount ? m_contactSum / double(m_contactCount) : 0;
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
    for (int a = 0; a < kMaxArms; ++a) {
        s.force[a] = p.force[a];
        s.toolActive[a] = m_toolOfArm[a] >= 0;
        s.tool[a] =
            m_toolOfArm[a] >= 0 ? m_world.toolContact(static_cast<size_t>(m_toolOfArm[a])).centre : sim::Vec3::Zero();
    }
    return s;
}

} // namespace viscera::player
