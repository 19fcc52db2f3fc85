// A case's painted light-sample maps in the player [A §6.3.2]: loaded with the case when it
// renders with painted sampling, put on the body and on the fascia over it (player::caseView),
// refused when the case would not use them or when the file is malformed.
#include "case/case_writer.hpp"
#include "render/sample_map.hpp"
#include "runtime/session.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

using namespace viscera;

namespace {

std::unique_ptr<sim::TetMesh> slab() {
    sim::BoxSpec spec;
    spec.size = sim::Vec3(0.08, 0.02, 0.04);
    spec.cells = {8, 2, 4};
    return sim::makeBoxTetMesh(spec);
}

/// A one-body case; `map` is the .vsamples text (empty: none), `sampling` the render mode.
std::filesystem::path writeCase(const std::string& name, const std::string& sampling, const std::string& map) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("viscera_case_view_" + std::to_string(::getpid()) + "_" + name + ".vcase");
    auto mesh = slab();
    nlohmann::json scene = {
        {"solver", {{"type", "xpbd"}, {"dt", 1.0 / 60}, {"substeps", 20}, {"iterations", 1}}},
        {"render", {{"sampling", sampling}}},
        {"bodies",
         {{{"name", "slab"},
           {"mesh", "meshes/slab.vtet"},
           {"material",
            {{"model", "stable_neo_hookean"}, {"youngs_modulus", 5000}, {"poisson_ratio", 0.4}, {"density", 1000}}},
           {"fixed_nodes", {0, 1, 2}}}}}};
    if (!map.empty()) scene["bodies"][0]["sample_map_file"] = "maps/slab.vsamples";
    vcase::Manifest m;
    m.caseId = "view";
    m.caseVersion = "1.0.0";
    m.minPlayerVersion = "0.1.0";
    m.features = {"xpbd"};
    vcase::CaseWriter w(m);
    w.addFile("scene.json", scene.dump());
    w.addFile("meshes/slab.vtet", sim::formatVtet(*mesh));
    if (!map.empty()) w.addFile("maps/slab.vsamples", map);
    w.write(path);
    return path;
}

std::string loadError(const std::filesystem::path& p) {
    try {
        player::loadCase(p);
    } catch (const InputError& e) {
        return e.what();
    }
    return "loaded";
}

} // namespace

TEST(CaseView, PaintedSampleMapReachesTheRenderedBody) {
    auto mesh = slab();
    render::RenderMesh surface = render::bodySurfaceMesh(*mesh, "slab");
    render::paintSampleBrush(surface, {{0.0, 0.0, 0.04}}, 0.02, 8);
    render::paintSampleBrush(surface, {{0.08, 0.02, 0.0}}, 0.02, 4);
    const std::vector<uint8_t> nodes = render::nodeSampleClasses(surface, mesh->vertexCount());
    const auto path = writeCase("painted", "painted", render::formatSampleMap(nodes));
    const player::LoadedCase loaded = player::loadCase(path);
    ASSERT_EQ(loaded.sampleMaps.size(), 1u);
    EXPECT_EQ(loaded.sampleMaps[0], nodes);
    const render::SceneView view = player::caseView(loaded);
    ASSERT_EQ(view.meshes().size(), 1u);
    EXPECT_EQ(view.meshes()[0].sampleMap, surface.sampleMap);
    std::filesystem::remove(path);
}

TEST(CaseView, AMapTheCaseWouldNotUseOrAMalformedOneIsRefusedAtLoad) {
    auto mesh = slab();
    const std::vector<uint8_t> zeros(mesh->vertexCount(), 0);
    auto unused = writeCase("unused", "distance", render::formatSampleMap(zeros));
    EXPECT_EQ(loadError(unused), unused.string() + ": scene.json: bodies[0].sample_map_file: the case's "
                                                   "render.sampling is not 'painted', so the map would not be used");
    std::string bad = render::formatSampleMap(zeros);
    bad.replace(bad.rfind("0\n"), 2, "2\n");
    auto malformed = writeCase("malformed", "painted", bad);
    EXPECT_EQ(loadError(malformed), malformed.string() + ":maps/slab.vsamples: line " +
                                        std::to_string(zeros.size() + 2) + ": class of node " +
                                        std::to_string(zeros.size() - 1) + " is 2 (must be 0, 1, 4 or 8)");
    auto shortMap = writeCase("short", "painted", render::formatSampleMap({0, 8}));
    EXPECT_EQ(loadError(shortMap), shortMap.string() + ":maps/slab.vsamples: line 2: file has 2 nodes, the mesh has " +
                                       std::to_string(zeros.size()));
    // painted sampling without a map: every vertex unpainted (the uniform count)
    auto none = writeCase("none", "painted", "");
    const player::LoadedCase loaded = player::loadCase(none);
    EXPECT_TRUE(loaded.sampleMaps[0].empty());
    const render::SceneView view = player::caseView(loaded);
    for (float c : view.meshes()[0].sampleMap)
        EXPECT_EQ(c, 0.0f);
    for (const auto& p : {unused, malformed, shortMap, none})
        std::filesystem::remove(p);
}
