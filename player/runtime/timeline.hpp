#pragma once
/// What happened over a session, frame by frame, for the session plots and the report's
/// "timeline": each tool's position and the tissue's force on it, and the task events (grasps,
/// cuts, clips, punctures) with their time. Recorded on the physics thread after every step.
///
/// The samples stay bounded on a long session: past kMaxSamples the recorder keeps every other
/// sample and doubles its stride (a window session left open for an hour keeps ≤ kMaxSamples
/// samples per tool). Events are never dropped.
#include <Eigen/Core>

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {
class World;
}

namespace viscera::player {

struct SessionTimeline {
    struct Tool {
        std::string name;
        std::string kind;         ///< grasper, energy_hook, clip_applier, probe, needle
        std::string hand = "any"; ///< the master's hand that drives it: left, right or any
        double radius = 0;        ///< m, jaw or probe radius (0: the needle)
        /// N, the tool's own damage threshold (its damage_force_n where the case gives one); 0:
        /// the case's (assessment force_threshold_n).
        double damageForceN = 0;
        std::vector<Eigen::Vector3d> tip; ///< m, scene frame, one per sample
        std::vector<double> force_n;      ///< N, the tissue on the tool, one per sample
        /// Unit, the shaft's direction towards the tip, one per sample (instruments and probes
        /// through a port; empty for tools without a shaft).
        std::vector<Eigen::Vector3d> axis;
    };
    struct Event {
        double t_s = 0;
        int frame = 0;
        std::string kind; ///< grasp, release, cut, clip, puncture
        std::string tool;
        int count = 1; ///< cut: edges cut that frame; puncture: punctures that frame
        /// m, scene: where it happened (cut: the energized hook's tip; clip: the clip's centre when
        /// fired; puncture: the needle's tip; grasp, release: the grasper's tip).
        Eigen::Vector3d at = Eigen::Vector3d::Zero();
        /// m, scene: a cut by scissors, the wedge their blades swept (clevis, tip, tip; `at` is
        /// where the edges they cut lie); empty for a cut at a point (the hook).
        std::vector<Eigen::Vector3d> swept;
        /// m, the body's rest pose: a clip's place on the anatomy (ClipState::restCentre), what the
        /// clip targets (picked on the rest pose) are judged against; unset for other events.
        std::optional<Eigen::Vector3d> rest;
    };
    std::vector<double> t_s; ///< s, the end of each sampled frame
    int stride = 1;          ///< frames per sample
    std::vector<Tool> tools;
    std::vector<Event> events;
    /// The laparoscope (cases that have one): its tip and whether the Cam pedal steered it, one
    /// per sample.
    std::vector<Eigen::Vector3d> cameraTip;
    std::vector<Eigen::Vector3d> cameraView; ///< unit, the optic's viewing direction
    std::vector<char> cameraSteering;
    /// Per sample: an energized hook's tip within the margin of the assessment's vessel to protect
    /// (cases with a targets.vessel).
    std::vector<char> vesselNear;
    double cameraFovDeg = 0; ///< vertical field of view (0: no laparoscope)
    bool empty() const { return tools.empty() && events.empty(); }
};

class TimelineRecorder {
public:
    static constexpr size_t kMaxSamples = 4096;
    /// Names the tools `world` has (instruments of its interaction, probes, the needle).
    /// maxSamples (≥ 2): the bound past which the samples are halved.
    explicit TimelineRecorder(const sim::World& world, size_t maxSamples = kMaxSamples);
    /// After each step.
    void record(const sim::World& world);
    const SessionTimeline& timeline() const { return m_tl; }
    SessionTimeline take() { return std::move(m_tl); }

private:
    void sample(const sim::World& world);
    /// An energized hook's tip within the margin of the vessel to protect (any of its nodes).
    bool hookNearVessel(const sim::World& world) const;
    int m_vesselBody = -1; ///< the assessment's vessel to protect; -1: none
    double m_vesselMargin = 0;
    SessionTimeline m_tl;
    size_t m_maxSamples = kMaxSamples;
    int m_frames = 0;
    std::vector<int> m_grasped; ///< per instrument: vertices held last frame
    int m_cut = 0, m_clips = 0, m_punctures = 0;
};

} // namespace viscera::player
