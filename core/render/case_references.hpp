#pragma once
/// The one table of the files a case's scene refers to: what the studio's export writes into the
/// package and what the player's load requires in it (and nothing else).
#include "render/case_settings.hpp"
#include "sim/scene/scene.hpp"

#include <string>
#include <vector>

namespace viscera::render {

/// One file a scene names: the scene field that names it ("bodies[0].mesh",
/// "render.materials.fat") and the file's path inside the case package.
struct CaseFileRef {
    std::string field;
    std::string path;
};

/// Every file `scene` refers to, in scene order: bodies[i].mesh, .node_weights_file,
/// .sample_map_file; surfaces[s].mesh, .node_weights_file; render.materials.<target> (the maps of
/// `materials`, the scene's render block as caseMaterialMaps reads it); suture.trajectory;
/// interaction.instruments[i].track. A path named twice is listed once (its first field).
std::vector<CaseFileRef> caseFileReferences(const sim::SceneDesc& scene,
                                            const std::vector<CaseMaterialMaps>& materials);

} // namespace viscera::render
