#include "render/case_references.hpp"

#include <algorithm>

namespace viscera::render {

std::vector<CaseFileRef> caseFileReferences(const sim::SceneDesc& scene,
                                            const std::vector<CaseMaterialMaps>& materials) {
    std::vector<CaseFileRef> refs;
    auto add = [&](std::string field, const std::string& path) {
        if (path.empty()) return;
        if (std::any_of(refs.begin(), refs.end(), [&](const CaseFileRef& r) { return r.path == path; })) return;
        refs.push_back({std::move(field), path});
    };
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const std::string at = "bodies[" + std::to_string(i) + "].";
        add(at + "mesh", scene.bodies[i].meshPath);
        add(at + "node_weights_file", scene.bodies[i].nodeWeightsPath);
        add(at + "sample_map_file", scene.bodies[i].sampleMapPath);
    }
    for (size_t s = 0; s < scene.surfaces.size(); ++s) {
        const std::string at = "surfaces[" + std::to_string(s) + "].";
        add(at + "mesh", scene.surfaces[s].meshPath);
        add(at + "node_weights_file", scene.surfaces[s].nodeWeightsPath);
    }
    for (size_t k = 0; k < scene.scenery.size(); ++k)
        add("scenery[" + std::to_string(k) + "].mesh", scene.scenery[k].meshPath);
    for (const CaseMaterialMaps& m : materials) {
        for (const std::string& f : m.files())
            add("render.materials." + m.target, f);
        add("render.materials." + m.target + ".uv", m.uv);
    }
    if (scene.suture) add("suture.trajectory", scene.suture->trajectoryPath);
    if (scene.interaction)
        for (size_t i = 0; i < scene.interaction->instruments.size(); ++i)
            add("interaction.instruments[" + std::to_string(i) + "].track",
                scene.interaction->instruments[i].trackPath);
    return refs;
}

} // namespace viscera::render
