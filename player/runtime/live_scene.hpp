#pragma once
/// The trainee's 3D scene of a running session: the case's meshes (caseView) with the
/// instruments' meshes, refreshed from copies of the session's LiveGeometry. One rule for what a
/// session looks like, used by the player's trainee window and the studio's rehearsal.
/// GUI thread only (the physics thread writes LiveView; the caller copies it under its lock).
#include "render/scene_view.hpp"
#include "render/tool_meshes.hpp"
#include "runtime/session.hpp"

#include <vector>

namespace viscera::player {

class LiveScene {
public:
    LiveScene() = default;
    /// The case's view at rest (no tools yet: a camera framed on view() sees the tissue only).
    explicit LiveScene(const LoadedCase& loaded);
    /// Adds the tools' meshes from the first snapshot (render::toolPoses of the world at load).
    void addTools(const render::ToolPoses& first);
    render::SceneView& view() { return m_view; }
    const render::SceneView& view() const { return m_view; }
    /// Nodes of every body together (LiveGeometry::nodes' length for this case).
    size_t nodeCount() const { return m_offset; }
    /// The copied geometry into the render meshes: positions, normals, the fat's and the fascia's
    /// cuts with their heat, the tools. False (nothing changed) when `g` is not of this case (its
    /// node count differs, e.g. before the first frame).
    bool apply(const LiveGeometry& g);

private:
    render::SceneView m_view;
    render::ToolMeshes m_tools;
    std::vector<size_t> m_bodyOffset;
    size_t m_offset = 0;
};

} // namespace viscera::player
