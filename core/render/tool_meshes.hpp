#pragma once
/// What the trainee acts with, drawn with the tissue: the instruments (shaft and jaws of a
/// grasper and a clip applier, the energy hook's rod and hook), the haptic probes, the placed
/// clips, the suturing needle and its thread.
///
/// ToolPoses is the per-frame snapshot (toolPoses(world) reads it after a step, on the physics
/// thread; the window copies it to the GUI thread). ToolMeshes adds one render mesh per
/// instrument, probe, clip the case can fire, needle and thread to a SceneView when it is made
/// and, every frame, rewrites their positions from the snapshot: the topology never changes (a
/// clip not yet fired and a thread not yet through the tissue are hidden; the thread has a fixed
/// number of points, the unused ones gathered at its end). The meshes are Source::Static, so
/// SceneView::updateFromWorld leaves them alone. Local frame of an instrument: the tip at the
/// origin, the shaft along −direction. An energized hook and a grasper holding tissue switch to
/// a highlighted material, so the state shows on screen as on the HUD.
#include "render/scene_view.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace viscera::sim {
class World;
}

namespace viscera::render {

struct ToolPoses {
    struct Instrument {
        std::string name, kind; ///< kind: grasper, energy_hook, clip_applier
        Eigen::Vector3d tip = Eigen::Vector3d::Zero();
        Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ(); ///< unit, shaft towards the tip
        double jaw = 1;                                        ///< 0 closed … 1 open
        bool act = false;                                      ///< energized / firing
        int grasped = 0;                                       ///< vertices held
        double radius = 0.0025, jawLength = 0.012;             ///< m
        /// m drawn behind the jaws: through the port and a little beyond when it has one.
        double shaftLength = 0.16;
    };
    struct Probe {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        double radius = 0.005;
        bool hasPort = false;                           ///< a shaft from the centre out through it
        Eigen::Vector3d port = Eigen::Vector3d::Zero(); ///< m
    };
    /// The laparoscope (sim/scene/laparoscope.hpp): what the camera of the view is.
    struct Scope {
        bool present = false;
        Eigen::Vector3d tip = Eigen::Vector3d::Zero();
        Eigen::Vector3d view = -Eigen::Vector3d::UnitZ(); ///< unit
        Eigen::Vector3d up = Eigen::Vector3d::UnitY();    ///< unit
        double fovDeg = 70;
        bool steering = false; ///< the Cam pedal is held
    };
    std::vector<Instrument> instruments;
    std::vector<Probe> probes;
    std::vector<std::array<Eigen::Vector3d, 4>> clips; ///< legs' end points (ClipState::legs)
    size_t maxClips = 0;                               ///< clips the case can fire (one per applier)
    std::vector<Eigen::Vector3d> needle;               ///< points along the needle, end to tip; empty: none
    std::vector<Eigen::Vector3d> thread;               ///< puncture points then the needle's end
    Scope scope;
    bool empty() const { return instruments.empty() && probes.empty() && needle.empty(); }
};

/// The snapshot of `world` now (instruments of the interaction, probes, clips, needle, thread;
/// with the needle, the needle holder that carries it).
ToolPoses toolPoses(const sim::World& world);

/// The needle holder of a suturing needle (`points`: the needle end to tip, at least two): closed
/// jaws on the needle a third of its length from the end (where a surgeon grips it), the shaft
/// leaving away from the arc's centre and out of its plane so that it does not lie along the
/// needle. Kind "needle_holder".
ToolPoses::Instrument needleHolderPose(const std::vector<Eigen::Vector3d>& points);

class ToolMeshes {
public:
    ToolMeshes() = default;
    /// Adds the meshes for what `first` has to `view` (and their materials). Nothing is added
    /// for an empty snapshot.
    ToolMeshes(SceneView& view, const ToolPoses& first);
    /// Rewrites the positions and normals of the tool meshes from `poses`, which must describe the
    /// same tools as the first snapshot (a changed count is ignored: those meshes keep their
    /// last pose). Allocation-free after the first frame.
    void update(SceneView& view, const ToolPoses& poses);
    size_t meshCount() const { return m_meshes.size(); }
    static constexpr size_t kThreadPoints = 96; ///< thread polyline points drawn

private:
    struct Part {
        enum class Kind { Instrument, Probe, Clip, Needle, Thread } kind;
        size_t index = 0; ///< instrument, probe or clip index
        size_t mesh = 0;  ///< in the view
    };
    /// Appends part's primitives for `poses` to the builder (the same calls for every snapshot,
    /// so the counts never change), sets its material and visibility; false when the snapshot
    /// does not have the part. Defined in the .cpp, with its builder.
    template <class Builder>
    bool build(Builder& b, const Part& part, const ToolPoses& poses, RenderMesh& m,
               std::vector<Eigen::Vector3d>& pts) const;
    std::vector<Part> m_meshes;
    uint32_t m_steel = 0, m_active = 0, m_clip = 0, m_thread = 0, m_probe = 0;
    std::vector<float> m_scratch;
    std::vector<uint32_t> m_indexScratch;
};

} // namespace viscera::render
