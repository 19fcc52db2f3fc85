#include "haptics/servo_loop.hpp"

#include "sim/util/cpu_relax.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace viscera::haptics {
namespace {

void atomicMax(std::atomic<int64_t>& a, int64_t v) {
    int64_t cur = a.load(std::memory_order_relaxed);
    while (v > cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
    }
}
void atomicMin(std::atomic<int64_t>& a, int64_t v) {
    int64_t cur = a.load(std::memory_order_relaxed);
    while (v < cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
    }
}

bool pinCurrentThread(int cpu) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) return false;
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
}

} // namespace

std::vector<int> allowedCpus() {
    std::vector<int> cpus;
    cpu_set_t set;
    CPU_ZERO(&set);
    if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) != 0) return cpus;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &set)) cpus.push_back(c);
    return cpus;
}

int defaultServoCpu() {
    const std::vector<int> cpus = allowedCpus();
    return cpus.size() >= 2 ? cpus.back() : -1;
}

bool pinCurrentThreadExcept(int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) != 0) return false;
    if (cpu >= 0 && cpu < CPU_SETSIZE) CPU_CLR(cpu, &set);
    return CPU_COUNT(&set) > 0 && pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
}

namespace {

/// True when the kernel limits real-time tasks to a share of each period (the default 95 %).
bool realtimeThrottled() {
    std::FILE* f = std::fopen("/proc/sys/kernel/sched_rt_runtime_us", "r");
    if (!f) return true;
    long v = 0;
    const bool read = std::fscanf(f, "%ld", &v) == 1;
    std::fclose(f);
    return !read || v >= 0;
}

} // namespace

void ServoLoop::Histogram::add(int64_t ns) noexcept {
    const int64_t us = std::max<int64_t>(0, (ns + 500) / 1000);
    const size_t bin = std::min<size_t>(static_cast<size_t>(us), bins.size() - 1);
    bins[bin].fetch_add(1, std::memory_order_relaxed);
    count.fetch_add(1, std::memory_order_relaxed);
    sum_ns.fetch_add(ns, std::memory_order_relaxed);
    atomicMax(max_ns, ns);
    atomicMin(min_ns, ns);
}

Distribution ServoLoop::Histogram::summary() const {
    Distribution d;
    d.count = count.load(std::memory_order_relaxed);
    if (d.count == 0) return d;
    d.mean_us = 1e-3 * double(sum_ns.load(std::memory_order_relaxed)) / double(d.count);
    d.max_us = 1e-3 * double(max_ns.load(std::memory_order_relaxed));
    d.min_us = 1e-3 * double(min_ns.load(std::memory_order_relaxed));
    auto pct = [&](double p) {
        const uint64_t want = static_cast<uint64_t>(std::ceil(p * double(d.count)));
        uint64_t acc = 0;
        for (size_t i = 0; i < bins.size(); ++i) {
            acc += bins[i].load(std::memory_order_relaxed);
            if (acc >= want) return i + 1 == bins.size() ? d.max_us : double(i);
        }
        return d.max_us;
    };
    d.p50_us = pct(0.5);
    d.p99_us = std::min(pct(0.99), d.max_us);
    return d;
}

ServoLoop::ServoLoop(Device& device, const Clock& clock, const ServoConfig& config)
    : m_device(device), m_clock(clock), m_config(config), m_safety(device.capabilities(), config.safety),
      m_history(std::make_unique<SeqLock<ToolPoseState>[]>(kPoseHistory)), m_trace(config.traceCapacity) {
    if (m_config.wait == ServoWait::Busy && m_config.cpu < 0) {
        const std::vector<int> cpus = allowedCpus();
        m_config.cpu = cpus.empty() ? -1 : cpus.back();
    }
}

ServoLoop::~ServoLoop() {
    stop();
}

void ServoLoop::tick(int64_t now, int64_t due) {
    const int64_t t0 = monotonicNs();
    m_device.poll(m_device.capabilities().realtime ? now : due, m_state);
    const int64_t started = m_stepsStarted.load(std::memory_order_acquire);
    const LocalContactModel contact = m_contact.read();
    double age_s = -1;
    if (contact.frame >= 0) {
        const int64_t age = now - contact.timestamp_ns;
        age_s = 1e-9 * double(age);
        m_age.add(age);
        atomicMax(m_maxBehind, started - contact.frame);
        if (contact.frame != m_lastFrame) {
            m_lastFrame = contact.frame;
            m_modelsSeen.fetch_add(1, std::memory_order_relaxed);
        }
    }
    const bool clutch = (m_state.pedals & kPedalClutch) != 0;
    // The Cam pedal gives the masters to the laparoscope: the tools hold as under the clutch.
    const bool camera = m_config.cameraPedalHolds && (m_state.pedals & kPedalCamera) != 0;
    const bool hold = clutch || camera || !m_state.connected;
    m_desired = DeviceCommand{};
    m_desired.timestamp_ns = now;
    m_desired.sequence = ++m_seq;
    m_desired.flags = clutch || camera ? uint32_t(kFlagClutch) : 0u;
    ToolPoseState poses;
    poses.timestamp_ns = due;
    poses.tick = m_seq;
    poses.connected = m_state.connected;
    poses.pedals = m_state.pedals;
    const int arms = std::clamp(m_device.capabilities().arms, 1, kMaxArms);
    std::array<Vec3, kMaxArms> proxy{Vec3::Zero(), Vec3::Zero()};
    for (int a = 0; a < arms; ++a) { // every master, driving a tool or not (the laparoscope reads them)
        poses.device[a] = m_state.arms[a].measured_cp.position;
        poses.orientation[a] = m_state.arms[a].measured_cp.orientation;
    }
    for (int a = 0; a < arms; ++a) {
        const ToolMapping& map = m_config.tools[a];
        if (!map.enabled) continue;
        const ArmState& arm = m_state.arms[a];
        const Vec3 centre = m_device.capabilities().arm[a].workspaceCentre();
        // Control point: the tip, or (laparoscopic port) the handle outside the body.
        const bool handle = map.throughPort && map.port.desc.mode == sim::PortMode::Laparoscopic;
        const Vec3 move = arm.measured_cp.position - centre;
        const Vec3 mapped = handle ? Vec3(map.port.restHandle + sim::handleMove(map.port, move, map.motionScale))
                                   : Vec3(map.sceneStart + map.motionScale * move);
        if (!m_haveTarget[a]) {
            m_target[a] = handle ? map.port.restHandle : map.sceneStart;
            m_offset[a] = m_target[a] - mapped;
            m_haveTarget[a] = m_state.connected;
        }
        // Clutch or no device: the tool stays; the master is re-indexed on release/reconnection.
        if (hold)
            m_offset[a] = m_target[a] - mapped;
        else
            m_target[a] = mapped + m_offset[a];
        sim::PortPose portPose;
        if (map.throughPort) {
            portPose = handle ? sim::fulcrumTip(map.port, m_target[a]) : sim::constrainToPort(map.port, m_target[a]);
            // At a limit the master is re-indexed as under the clutch: moving back moves the tool
            // back at once (no motion stored past the limit).
            if (portPose.insertionLimited || portPose.angleLimited) {
                m_target[a] = handle ? sim::fulcrumHandle(map.port, portPose.tip) : portPose.tip;
                m_offset[a] = m_target[a] - mapped;
            }
        }
        const Vec3 x = map.throughPort ? portPose.tip : m_target[a];
        // The tip's velocity for the coupling's damping: through a laparoscopic port the lever
        // reverses and scales it across the shaft (handForce is that same linear map).
        const Vec3 tipVelocity =
            handle
                ? sim::handForce(map.port, portPose, sim::handleMove(map.port, arm.measured_cv.linear, map.motionScale))
                : Vec3(map.motionScale * arm.measured_cv.linear);
        const ToolContactModel& tm = contact.tools[a];
        Vec3 p = x;
        double fn = 0;
        if (tm.active && !hold) {
            const double fTarget = tm.forceAt(x);
            if (fTarget > 0) {
                // Proxy in series with the local model: kc (s_p − s_t) = f0 − k (s_p + gap).
                const double kc = map.couplingStiffness, k = tm.k;
                const double st = (x - tm.p0).dot(tm.n);
                const double sp = (tm.f0 - k * tm.gap + kc * st) / (kc + k);
                fn = kc * (sp - st);
                fn -= map.couplingDamping * tipVelocity.dot(tm.n);
                fn = std::max(0.0, fn);
                p = x + (sp - st) * tm.n;
            }
        }
        proxy[a] = p;
        const Vec3 tipForce = fn * tm.n;
        m_desired.arms[a].servo_cf.force =
            map.forceScale * (map.throughPort ? sim::handForce(map.port, portPose, tipForce) : tipForce);
        poses.proxy[a] = p;
        poses.target[a] = x;
        poses.orientation[a] = arm.measured_cp.orientation;
        poses.grip[a] = arm.jaw_measured_js;
        poses.buttons[a] = arm.buttons;
    }
    SafetyInput in;
    in.now_ns = now;
    in.simTimestamp_ns = contact.frame >= 0 ? contact.timestamp_ns : INT64_MIN / 2;
    in.deviceConnected = m_state.connected;
    in.pedals = m_state.pedals;
    const uint32_t rules = m_safety.apply(in, m_desired, m_out);
    m_device.send(m_out);
    poses.safetyRules = rules;
    for (int a = 0; a < arms; ++a)
        poses.force[a] = m_out.arms[a].servo_cf.force.norm();
    m_history[poses.tick % kPoseHistory].write(poses); // before the latest: poseBefore reads it so
    m_poses.write(poses);
    if (poses.tick == 1) m_firstDue.store(due, std::memory_order_release);
    for (int a = 0; a < arms; ++a) {
        if (!m_config.tools[a].enabled) continue;
        TraceSample s;
        s.t_ns = now;
        s.arm = static_cast<uint8_t>(a);
        s.connected = m_state.connected;
        s.pedals = m_state.pedals;
        s.rules = rules;
        s.device = m_state.arms[a].measured_cp.position;
        s.tool = proxy[a];
        s.force = m_out.arms[a].servo_cf.force;
        s.desired = m_desired.arms[a].servo_cf.force.norm();
        s.grip = m_state.arms[a].jaw_measured_js;
        s.contactAge_s = age_s;
        s.contactFrame = contact.frame;
        m_trace.push(s);
    }
    m_ticks.fetch_add(1, std::memory_order_relaxed);
    m_cost.add(monotonicNs() - t0);
}

bool ServoLoop::poseAt(uint64_t tick, ToolPoseState& out) const {
    if (tick == 0) return false;
    const ToolPoseState p = m_history[tick % kPoseHistory].read();
    if (p.tick != tick) return false;
    out = p;
    return true;
}

PoseLookup ServoLoop::poseBefore(int64_t t_ns, ToolPoseState& out) const {
    const ToolPoseState latest = m_poses.read();
    if (latest.tick == 0 || latest.timestamp_ns < t_ns) return PoseLookup::NotYet;
    // Binary search over tick numbers (timestamps grow with them): hi's tick is at or after t_ns,
    // lo's before it. The oldest slots are left alone: the servo may be overwriting them.
    constexpr uint64_t kMargin = 64;
    uint64_t hi = latest.tick;
    uint64_t lo = hi > kPoseHistory - kMargin ? hi - (kPoseHistory - kMargin) : 1;
    ToolPoseState p;
    if (!poseAt(lo, p)) return PoseLookup::Dropped;
    if (p.timestamp_ns >= t_ns) { // before the first tick the first one's poses stand
        if (lo != 1) return PoseLookup::Dropped;
        out = p;
        return PoseLookup::Found;
    }
    while (hi - lo > 1) {
        const uint64_t mid = lo + (hi - lo) / 2;
        if (!poseAt(mid, p)) return PoseLookup::Dropped;
        (p.timestamp_ns < t_ns ? lo : hi) = mid;
    }
    return poseAt(lo, out) ? PoseLookup::Found : PoseLookup::Dropped;
}

void ServoLoop::start() {
    if (m_running.exchange(true)) return;
    m_thread = std::thread([this] { run(); });
}

void ServoLoop::stop() {
    if (!m_running.exchange(false)) return;
    if (m_thread.joinable()) m_thread.join();
}

void ServoLoop::run() {
    const bool busy = m_config.wait == ServoWait::Busy;
    const int cpu = m_config.cpu; // resolved at construction for Busy
    if (cpu >= 0 && pinCurrentThread(cpu)) m_cpu.store(cpu, std::memory_order_relaxed);
    if (m_config.realtimePriority) {
        if (busy && realtimeThrottled()) {
            // Highest SCHED_OTHER weight instead (nice -20, where allowed), so that other processes
            // landing on this CPU get short slices only.
            const bool niced = setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), -20) == 0;
            m_priorityNote =
                std::string("busy wait: kernel.sched_rt_runtime_us is not -1, a real-time spinner would be "
                            "throttled (50 ms stalls each second); running SCHED_OTHER") +
                (niced ? " at nice -20" : "") + " on its own CPU";
        } else {
            sched_param sp{};
            sp.sched_priority = std::min(80, sched_get_priority_max(SCHED_FIFO));
            const bool ok = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
            m_rt.store(ok, std::memory_order_relaxed);
            if (!ok) m_priorityNote = "SCHED_FIFO refused by the system (needs CAP_SYS_NICE or an rtprio limit)";
        }
    }
    const int64_t period = periodNs();
    const int64_t clockOffset = m_clock.now_ns() - monotonicNs(); // deadlines on the servo clock
    int64_t next = monotonicNs() + period;
    int64_t prev = -1;
    while (m_running.load(std::memory_order_acquire)) {
        // SleepSpin: sleep, then spin the last spin_ns to the deadline. The default spin (0.94 ms
        // of each 1 ms period) leaves the CPU idle a few tens of µs per period, enough to stay
        // under the real-time runtime limit, while the spin covers the late wake-ups of an idle
        // virtual CPU (p99 ~0.55 ms on the 2-core CI VM). Measured there over 60 s loopback runs:
        // spin 0.70 ms → period jitter p99 180–402 µs; 0.90 → 99; 0.94 → 66–107; 0.97 → 35 µs
        // but 50 ms stalls each second (throttled), as with a whole-period spin at SCHED_FIFO,
        // hence Busy runs SCHED_OTHER there.
        if (!busy && next - monotonicNs() > m_config.spin_ns) sleepUntilNs(next - m_config.spin_ns);
        int64_t now = monotonicNs();
        while (now < next) {
            sim::cpuRelax();
            now = monotonicNs();
        }
        m_wake.add(now - next);
        if (prev >= 0) {
            m_period.add(now - prev);
            m_jitter.add(std::llabs(now - prev - period));
        }
        prev = now;
        tick(m_clock.now_ns(), next + clockOffset);
        next += period;
        const int64_t after = monotonicNs();
        if (after > next) { // overran a whole period: skip to the next deadline in the future
            m_overruns.fetch_add(1, std::memory_order_relaxed);
            next += ((after - next) / period + 1) * period;
        }
    }
}

ServoStats ServoLoop::stats() const {
    ServoStats s;
    s.ticks = m_ticks.load(std::memory_order_relaxed);
    s.overruns = m_overruns.load(std::memory_order_relaxed);
    s.realtimePriority = m_rt.load(std::memory_order_relaxed);
    s.wait = m_config.wait;
    s.spinNs = m_config.spin_ns;
    s.cpu = m_cpu.load(std::memory_order_relaxed);
    if (!m_running.load(std::memory_order_acquire)) s.priorityNote = m_priorityNote;
    s.period = m_period.summary();
    s.jitter = m_jitter.summary();
    s.wakeLatency = m_wake.summary();
    s.tickCost = m_cost.summary();
    s.contactAge = m_age.summary();
    s.contactModelsSeen = m_modelsSeen.load(std::memory_order_relaxed);
    s.maxStepsBehind = m_maxBehind.load(std::memory_order_relaxed);
    s.safety = m_safety.counts();
    s.traceDropped = m_trace.dropped();
    return s;
}

} // namespace viscera::haptics
