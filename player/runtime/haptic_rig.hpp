#pragma once
/// The haptic side of a session: the device, the servo loop and the hand-over with the physics
/// thread (World). Created only when the player runs with --device.
///
/// Lockstep (replay, scripted; repeatable): before each physics frame the rig runs the servo
/// ticks that fall in the frame on a ManualClock, then hands the tool poses to the World.
/// Real time (console, keyboard, or --realtime): the servo loop runs on its own thread at 1 kHz;
/// the physics thread steps at the scene's dt, paced to the wall clock, and publishes the local
/// contact model after each step. A slow step delays only the next publish: the servo loop keeps
/// its rate and the safety filter zeroes the force once the model is older than its limit.
#include "haptics/device.hpp"
#include "haptics/handover_audit.hpp"
#include "haptics/servo_loop.hpp"
#include "sim/scene/world.hpp"

#include <sched.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace viscera::player {

/// Task metrics of a session (report "metrics"). Tools: the scene's probes, then the
/// interaction's instruments (scripted on their tracks or driven by the device).
/// The session's counts and the device's forces. The task's figures (paths, the tissue's forces,
/// damage) are the assessment's (assessment.hpp), measured from the timeline.
struct TaskMetrics {
    double time_s = 0;      ///< simulated session time
    double maxForce_n = 0;  ///< device force after the safety filter
    double meanForce_n = 0; ///< over all servo ticks of driven arms
    int punctures = 0;      ///< needle punctures (suturing cases)
    int clips = 0;          ///< clips applied (cases with a clip applier)
    int cutEdges = 0;       ///< edges dissected by energy (cases with an energy hook)
};

struct HapticsResult {
    std::string spec, backend, name, mode; ///< mode: "lockstep" or "realtime"
    int arms = 0, pedals = 0;
    double deviceMaxForce_n = 0, caseMaxForce_n = 0;
    struct Tool {
        std::string name, hand;
        int arm = -1;            ///< -1: no arm of this device drives it
        std::string kind;        ///< "probe" or the instrument kind (grasper, energy_hook, ...)
        double drivenTime_s = 0; ///< time its arm drove it (instruments sharing an arm take turns)
    };
    std::vector<Tool> tools;
    haptics::ServoStats servo;
    haptics::LinkStats link;
    double physicsPeriod_s = 0;
    double maxContactAgeSteps = 0;     ///< max contact-model age / nominal physics period
    haptics::HandoverFigures handover; ///< ticks against the physics thread's own publish log
    bool physicsRealtimePriority = false;
    std::vector<int> physicsCpus; ///< real time: the CPUs the physics thread may run on
    uint64_t traceSamples = 0;
    /// Real time: how late each physics frame started against the wall-clock time its input was
    /// complete (frame k takes the device at the last servo tick before (k+1)·dt after the first
    /// tick, as in lockstep, from the servo's pose history), ms; frames late by more than one frame time. A late frame
    /// still gets its own instant's input; the lag is how far the picture trails the hands.
    /// Lockstep: 0.
    double lagMeanMs = 0, lagMaxMs = 0;
    int64_t framesLate = 0;
    /// Real time: frames whose servo tick was no longer kept (the physics over
    /// ServoLoop::kPoseHistory ticks behind) or did not come (a servo stalled over 50 ms); they
    /// took the latest tick's poses instead, so the input differs from the lockstep run's.
    int64_t inputMissed = 0;
    /// Real time: frames whose input came from a tick before the frame's last one because the
    /// servo overran and skipped ticks (a VM stall): their input is up to the stall earlier.
    int64_t inputEarlier = 0;
    /// Real time: the largest growth of that lag after the warm-up frames (RealTimeWatch), ms: how
    /// far the session fell behind once running (a slow start shifts the whole session instead).
    double lagGrowthMaxMs = 0;
};

/// One row of the force/pose trace (--trace CSV).
using TraceRow = haptics::TraceSample;

/// What the trainee window shows, written by the physics thread every frame.
struct LiveState {
    double time_s = 0;
    int frame = 0;
    bool connected = false;
    uint32_t pedals = 0;
    uint32_t safetyRules = 0;
    std::array<double, haptics::kMaxArms> force{0, 0};
    std::array<sim::Vec3, haptics::kMaxArms> tool{sim::Vec3::Zero(), sim::Vec3::Zero()};
    std::array<bool, haptics::kMaxArms> toolActive{false, false};
    std::array<std::string, haptics::kMaxArms> toolName{}; ///< the tool each arm drives now
    double maxForce_n = 15;
    /// Physics speed over the last frames (session.cpp): mean step wall time, ms, and the
    /// real-time factor, simulated time per physics wall time (≥ 1: keeps up with real time).
    double physicsMs = 0;
    double realTimeFactor = 0;
    /// Real time: how late the frame started against the wall clock, ms (HapticsResult::lagMaxMs).
    double lagMs = 0;
    /// Real time: how much further behind than after the warm-up now, and at most so far
    /// (HapticsResult::lagGrowthMaxMs, what the end verdict takes).
    double lagGrowthMs = 0;
    double lagGrowthMaxMs = 0;
    /// Set by the session once it estimated that this machine cannot keep real time (shown in red).
    std::string realTimeWarning;
};

class HapticRig {
public:
    /// `device` must outlive the rig. realtime: servo thread + wall-clock pacing.
    HapticRig(haptics::Device& device, std::string spec, sim::World& world, bool realtime, bool keepTrace);
    ~HapticRig();
    /// Before configure(): how the servo thread waits and the CPU it pins itself to (-1: Busy →
    /// the highest allowed CPU, SleepSpin → none); spinNs >= 0 sets SleepSpin's spin. Keeping
    /// the physics thread and its workers off that CPU is the caller's part, before the world is
    /// built (player main: pinCurrentThreadExcept).
    void setServoWait(haptics::ServoWait wait, int cpu, int64_t spinNs = -1);
    /// dt: the scene's physics period (s). Creates the servo loop; call once before start().
    void configure(double dt);
    /// Starts the servo thread (real time) and publishes the initial contact model.
    void start();
    /// Before World::step(): lockstep ticks; tool poses → World.
    void beforeStep();
    /// After World::step(): publish the contact model, drain the trace, accumulate metrics, and
    /// in real time sleep until the frame's deadline.
    void afterStep();
    /// Stops the servo thread and drains the rest of the trace.
    void finish();
    HapticsResult result() const;
    const TaskMetrics& metrics() const { return m_metrics; }
    std::vector<TraceRow>& trace() { return m_trace; }
    LiveState live() const;
    bool realtime() const { return m_realtime; }
    /// Tools of the scene that no arm of the device drives (the player warns about them), and
    /// whether any tool is driven at all.
    std::vector<std::string> undrivenTools() const;
    /// Mappings the case's tools cannot have as declared (e.g. two instruments on one master
    /// through different ports); the session reports them as warnings.
    const std::vector<std::string>& mappingNotes() const { return m_notes; }
    bool drivesAnyTool() const;

private:
    /// The arm a hand asks for: left → 0 and right → 1 on a bimanual device; "any" (or a one-arm
    /// device) → the first arm nothing is on yet, else arm 0 (-1 with `exclusive`).
    int armFor(const std::string& hand, bool exclusive, int arms) const;
    /// Maps `arm` onto a tool at `start` (scene), through its port when it declares one.
    static void mapArm(haptics::ServoConfig& cfg, int arm, const sim::Vec3& start, double motion, double force,
                       const sim::PortDesc* port);
    /// The rig's tools, in order: probes (an arm each), instruments with a device (arms may be
    /// shared), the needle and the thread of a suture with a device.
    void rigProbes(haptics::ServoConfig& cfg, int arms);
    void rigInstruments(haptics::ServoConfig& cfg, int arms);
    void rigNeedle(haptics::ServoConfig& cfg, int arms);
    void drain();
    /// Real time: how late the frame that is due at `due` (wall clock) starts (m_lag*).
    void measureLag(int64_t due);
    /// Real time: waits until the frame's input is in (`due`: the frame's end on the servo clock)
    /// and returns the poses of the last servo tick before it (the lockstep run's input).
    haptics::ToolPoseState framePoses(int64_t due);
    haptics::LocalContactModel contactModel(int64_t now) const;
    /// The laparoscope follows its master's motion since the Cam pedal went down, while it is held.
    void steerScope(const haptics::ToolPoseState& poses);
    /// Publishes the contact model of m_frame and logs it for the hand-over audit.
    void publish();
    haptics::Device& m_device;
    std::string m_spec;
    sim::World& m_world;
    bool m_realtime, m_keepTrace;
    std::unique_ptr<haptics::Clock> m_clock;
    haptics::ManualClock* m_manual = nullptr;
    haptics::ServoConfig m_servoConfig;
    std::unique_ptr<haptics::ServoLoop> m_servo;
    /// Tools: probes [0, toolCount), then the instruments that declare a device, then the needle
    /// and the thread of a suturing scene with a suture "device".
    struct RigTool {
        enum class Kind { Probe, Instrument, Needle, Thread };
        Kind kind = Kind::Probe;
        size_t index = 0; ///< probe or instrument index in the World
        int arm = -1;
        sim::Vec3 offset = sim::Vec3::Zero(); ///< instrument: tip − servo proxy while its arm drives it
        double gripOpen = 1.0;
        sim::InstrumentKey rest;
        Eigen::Isometry3d needleRest = Eigen::Isometry3d::Identity();
        double pullScale = 0, pull = 0; ///< thread: scale and the pull so far (m)
    };
    std::vector<RigTool> m_rig;
    std::array<std::vector<int>, haptics::kMaxArms> m_armTools; ///< rig tools per arm, in scene order
    std::array<int, haptics::kMaxArms> m_selected{0, 0};        ///< index into m_armTools[a]
    std::array<bool, haptics::kMaxArms> m_buttonDown{false, false};
    /// Rig tool the arm drives now (-1: none).
    int activeTool(int arm) const;
    std::vector<HapticsResult::Tool> m_tools;
    double m_dt = 0, m_caseMaxForce = 15;
    int64_t m_frame = 0, m_t0 = 0, m_tick = 0;
    double m_lagMs = 0, m_lagSumMs = 0, m_lagMaxMs = 0; ///< real time: frame start against the wall clock
    double m_lagAtWarmupMs = 0, m_lagGrowthMs = 0,
           m_lagGrowthMaxMs = 0; ///< the lag after the warm-up, and its growth since
    int64_t m_framesLate = 0;
    int64_t m_inputMissed = 0, m_inputEarlier = 0;
    std::vector<TraceRow> m_trace;
    uint64_t m_samples = 0;
    TaskMetrics m_metrics;
    std::array<sim::Vec3, haptics::kMaxArms> m_armProxy{sim::Vec3::Zero(), sim::Vec3::Zero()};
    std::vector<std::string> m_notes;
    int m_scopeArm = -1; ///< the master that steers the laparoscope (-1: none)
    sim::Vec3 m_scopeGrab = sim::Vec3::Zero();
    haptics::Quat m_scopeGrabQ = haptics::Quat::Identity();
    double m_forceSum = 0;
    uint64_t m_forceCount = 0;
    double m_maxAgeSteps = 0;
    haptics::HandoverAudit m_audit;
    int64_t m_lastAuditTick = INT64_MIN;
    bool m_physicsRt = false, m_hadPhysicsRt = false;
    std::vector<int> m_physicsCpus;
    int m_oldPolicy = 0;
    sched_param m_oldParam{};
};

} // namespace viscera::player
