#pragma once
/// The 1 kHz haptic servo loop. Each tick: poll the device, map each master to its tool
/// (workspace scale and offset; the clutch pedal or a disconnection re-indexes instead of
/// moving the tool), place the tool proxy against the local contact model through a virtual
/// coupling, compute the force, pass it through the safety filter, send it, publish the tool
/// poses for the physics thread and push a trace sample. A tick never allocates, locks or
/// blocks: the contact model and the tool poses travel through SeqLocks, the trace through a
/// bounded SPSC ring.
///
/// start() runs ticks on a thread of its own at `rateHz`, woken by clock_nanosleep(TIMER_ABSTIME)
/// a little early and then spinning to the deadline, or (ServoWait::Busy) spinning the whole
/// period on a pinned CPU; period, wake-up latency and contact-model
/// age go into preallocated histograms (1 µs bins). Without start(), tick(now) can be driven by
/// the caller on a ManualClock (lockstep, repeatable).
#include "haptics/clock.hpp"
#include "haptics/contact_model.hpp"
#include "haptics/device.hpp"
#include "haptics/lockfree.hpp"
#include "haptics/safety_filter.hpp"
#include "sim/scene/port.hpp"

#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace viscera::haptics {

/// How one device arm drives one simulated tool.
struct ToolMapping {
    bool enabled = false;
    Vec3 sceneStart = Vec3::Zero();    ///< m, scene: tool centre when the master is at the workspace centre
    double motionScale = 0.25;         ///< scene metres per device metre
    double forceScale = 1.0;           ///< device newtons per scene newton
    double couplingStiffness = 2000.0; ///< N/m, scene: virtual coupling proxy ↔ master
    double couplingDamping = 2.0;      ///< N·s/m, scene: damps the normal approach while in contact
    /// Through a trocar port (sim/scene/port.hpp): laparoscopic, the master moves the handle
    /// (port.restHandle + port.handScale · device motion) and the tip pivots about the port, the
    /// force going back through the lever; robotic, the master places the tip as without a port
    /// and the tip is held to the port's limits (remote centre of motion).
    bool throughPort = false;
    sim::PortFrame port;
};

/// How the servo thread waits for its deadline.
enum class ServoWait {
    /// clock_nanosleep to spin_ns before the deadline, then spin: shares the CPU, works anywhere.
    SleepSpin,
    /// Spin the whole period on a CPU of its own (`cpu`), for a console PC with a core set aside.
    /// SCHED_FIFO only where the kernel does not throttle real-time tasks
    /// (sched_rt_runtime_us = -1); otherwise the thread stays SCHED_OTHER, because a throttled
    /// real-time spinner is stopped for 50 ms every second.
    Busy,
};

/// The spin of the player's default "shared" real-time mode: the servo thread (SCHED_FIFO) sleeps
/// on the CPUs the physics runs on to its absolute deadline and does not spin: its wake-up on a
/// busy CPU is late by tens of µs (jitter p99 23-49 µs in the rectum), and every µs of spin is
/// taken from the physics (a 100 µs spin cost it about a tenth of one CPU).
inline constexpr int64_t kSharedSpinNs = 0;

struct ServoConfig {
    double rateHz = 1000.0;
    ServoWait wait = ServoWait::SleepSpin;
    int64_t spin_ns = 940'000; ///< SleepSpin: wake this early and spin to the deadline (see servo_loop.cpp)
    int cpu = -1; ///< pin the servo thread to this CPU (-1: Busy → the highest allowed CPU, SleepSpin → none;
                  ///< ServoLoop::config() has it resolved; the player passes defaultServoCpu())
    bool realtimePriority = true; ///< try SCHED_FIFO for the servo thread (ignored when refused)
    SafetyLimits safety;
    /// The Cam pedal gives the masters to the laparoscope (cases that have one): the tools hold
    /// as under the clutch while it is held. Off: the pedal is only reported.
    bool cameraPedalHolds = false;
    std::array<ToolMapping, kMaxArms> tools{};
    size_t traceCapacity = 1 << 16; ///< samples (one per enabled arm per tick)
};

struct TraceSample {
    int64_t t_ns = 0;
    uint8_t arm = 0;
    uint8_t connected = 0;
    uint32_t pedals = 0;
    uint32_t rules = 0;         ///< SafetyRule bits
    Vec3 device = Vec3::Zero(); ///< m, device frame: master position
    Vec3 tool = Vec3::Zero();   ///< m, scene: proxy (simulated tool) centre
    Vec3 force = Vec3::Zero();  ///< N, device frame: after the safety filter
    double desired = 0;         ///< N, magnitude before the safety filter
    double grip = 0;            ///< rad
    double contactAge_s = -1;   ///< age of the contact model at this tick (-1: none yet)
    int64_t contactFrame = -1;  ///< physics frame of that model (-1: none yet)
};

/// ServoLoop::poseBefore's answer.
enum class PoseLookup {
    Found,   ///< the last tick before the time; a later tick has run, so it is final
    NotYet,  ///< no tick at or after the time has run yet
    Dropped, ///< the ticks before the time are no longer kept (or were overwritten while searched)
};

/// Percentiles from a 1 µs histogram.
struct Distribution {
    uint64_t count = 0;
    double mean_us = 0, p50_us = 0, p99_us = 0, max_us = 0, min_us = 0;
};

struct ServoStats {
    uint64_t ticks = 0;
    uint64_t overruns = 0;         ///< ticks that started more than one period late
    bool realtimePriority = false; ///< SCHED_FIFO was granted
    ServoWait wait = ServoWait::SleepSpin;
    int cpu = -1;                  ///< CPU the thread was pinned to (-1: not pinned)
    int64_t spinNs = 0;            ///< SleepSpin: spin before each deadline
    std::string priorityNote;      ///< why SCHED_FIFO was not used, when it was not
    Distribution period;           ///< tick-to-tick interval
    Distribution jitter;           ///< |period − nominal|
    Distribution wakeLatency;      ///< tick start − deadline
    Distribution tickCost;         ///< duration of tick()
    Distribution contactAge;       ///< age of the contact model at each tick (after the first publish)
    int64_t contactModelsSeen = 0; ///< distinct physics frames the ticks used
    int64_t maxStepsBehind = 0;    ///< max over ticks of (physics steps started − model's frame)
    SafetyCounts safety;
    uint64_t traceDropped = 0;
};

/// The CPUs the calling thread may run on (its affinity mask: taskset, cpusets), ascending.
std::vector<int> allowedCpus();

/// The CPU a real-time servo thread should own: the highest CPU the calling thread may run on,
/// where it may run on at least two; else -1 (share the only one).
int defaultServoCpu();

/// Keeps the calling thread off `cpu`: its affinity mask loses that CPU (e.g. the physics thread
/// off the servo's CPU). False when the system refuses or no other allowed CPU is left.
bool pinCurrentThreadExcept(int cpu);

class ServoLoop {
public:
    /// Ticks whose tool poses poseAt() keeps: 8.192 s at 1 kHz (2 MB).
    static constexpr size_t kPoseHistory = 8192;

    /// `device` and `clock` must outlive the loop. Allocates the trace ring and histograms.
    ServoLoop(Device& device, const Clock& clock, const ServoConfig& config);
    ~ServoLoop();
    ServoLoop(const ServoLoop&) = delete;
    ServoLoop& operator=(const ServoLoop&) = delete;

    // ---- physics thread -----------------------------------------------------------------------
    void publishContact(const LocalContactModel& model) { m_contact.write(model); }
    /// Call when a physics step starts: ticks then count how many steps their model lags
    /// (ServoStats::maxStepsBehind: 1 while the step after the model's is running).
    void notifyStepStart() { m_stepsStarted.fetch_add(1, std::memory_order_release); }
    ToolPoseState toolPoses() const { return m_poses.read(); }
    /// The tool poses of the last tick that ran before t_ns (ToolPoseState::timestamp_ns, the
    /// servo clock), from the last kPoseHistory ticks. The physics reads a frame's input at the
    /// frame's own instant with it, however late the frame starts (HapticRig), so a real-time
    /// session sees the input a lockstep session does.
    PoseLookup poseBefore(int64_t t_ns, ToolPoseState& out) const;

    // ---- servo ----------------------------------------------------------------------------------
    /// One tick at time now_ns (lockstep callers: a ManualClock's time is its deadline).
    void tick(int64_t now_ns) { tick(now_ns, now_ns); }
    /// One tick at now_ns for its deadline due_ns (<= now_ns; the servo thread): the tool poses
    /// are stamped at the deadline and a device on recorded time (replay, scripted: not
    /// DeviceCapabilities::realtime) is polled there, so that the input of tick n is the input
    /// lockstep gives it whatever the wake-up latency; a live device is polled at now_ns, and the
    /// contact model's age and the safety filter use now_ns.
    void tick(int64_t now_ns, int64_t due_ns);
    /// The first tick's deadline (its poses' timestamp); INT64_MIN before it ran.
    int64_t firstTickNs() const { return m_firstDue.load(std::memory_order_acquire); }
    /// Runs ticks on a thread at config.rateHz until stop().
    void start();
    void stop();
    bool running() const { return m_running.load(std::memory_order_acquire); }

    // ---- any thread ------------------------------------------------------------------------------
    bool popTrace(TraceSample& out) { return m_trace.pop(out); }
    /// Timing figures; exact after stop(), approximate while running.
    ServoStats stats() const;
    uint64_t ticks() const { return m_ticks.load(std::memory_order_relaxed); }
    const SafetyFilter& safety() const { return m_safety; }
    const ServoConfig& config() const { return m_config; }
    /// The tick period, ns (config().rateHz): ticks are due at whole periods from the first.
    int64_t periodNs() const { return static_cast<int64_t>(std::llround(1e9 / m_config.rateHz)); }

private:
    struct Histogram {
        std::vector<std::atomic<uint32_t>> bins; ///< 1 µs each; the last collects overflow
        std::atomic<uint64_t> count{0};
        std::atomic<int64_t> sum_ns{0}, max_ns{0}, min_ns{INT64_MAX};
        explicit Histogram(size_t n) : bins(n) {}
        void add(int64_t ns) noexcept;
        Distribution summary() const;
    };
    void run();
    /// The poses of tick `tick` (from 1) when it is still kept.
    bool poseAt(uint64_t tick, ToolPoseState& out) const;

    Device& m_device;
    const Clock& m_clock;
    ServoConfig m_config;
    SafetyFilter m_safety;
    SeqLock<LocalContactModel> m_contact;
    SeqLock<ToolPoseState> m_poses;
    std::unique_ptr<SeqLock<ToolPoseState>[]> m_history; ///< kPoseHistory slots, tick % kPoseHistory
    SpscRing<TraceSample> m_trace;
    Histogram m_period{20001}, m_jitter{20001}, m_wake{20001}, m_cost{20001}, m_age{200001};
    std::atomic<uint64_t> m_ticks{0}, m_overruns{0};
    std::atomic<int64_t> m_modelsSeen{0}, m_stepsStarted{0}, m_maxBehind{0};
    std::atomic<bool> m_running{false}, m_rt{false};
    std::atomic<int> m_cpu{-1};
    std::atomic<int64_t> m_firstDue{INT64_MIN};
    std::string m_priorityNote; ///< written by the servo thread before its first tick
    std::thread m_thread;
    // tick state (servo thread only)
    DeviceState m_state;
    DeviceCommand m_desired, m_out;
    std::array<Vec3, kMaxArms> m_offset{Vec3::Zero(), Vec3::Zero()};
    std::array<Vec3, kMaxArms> m_target{Vec3::Zero(), Vec3::Zero()};
    std::array<bool, kMaxArms> m_haveTarget{false, false};
    int64_t m_lastFrame = -1;
    uint64_t m_seq = 0;
};

} // namespace viscera::haptics
