// A case's painted light-sample maps in the player [A §6.3.2]: loaded with the case when it
// renders with painted sampling, put on the body and on the fascia over it (player::caseView),
// refused when the case would not use them or when the file is malformed.
#include "case/case_writer.hpp"
#include "render/case_settings.hpp"
#include "render/corner_uv.hpp"
#include "render/image.hpp"
#include "render/sample_map.hpp"
#include "runtime/session.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>

#include <unistd.h>

using namespace viscera;

namespace {

/// The test cases are made here unsigned; the signature rules have tests of their own.
vcase::TrustPolicy unsignedAllowed() {
    vcase::TrustPolicy p;
    p.allowUnsigned = true;
    return p;
}

std::unique_ptr<sim::TetMesh> slab() {
    sim::BoxSpec spec;
    spec.size = sim::Vec3(0.08, 0.02, 0.04);
    spec.cells = {8, 2, 4};
    return sim::makeBoxTetMesh(spec);
}

/// A one-body case whose render block is `render`, with `edit` applied to the body's scene entry,
/// packaging `files` (entry, bytes) besides its scene and mesh.
std::filesystem::path writeMappedCase(const std::string& name, const nlohmann::json& render,
                                      const std::vector<std::pair<std::string, std::string>>& files,
                                      const std::function<void(nlohmann::json&)>& edit = {}) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("viscera_case_view_" + std::to_string(::getpid()) + "_" + name + ".vcase");
    auto mesh = slab();
    nlohmann::json scene = {
        {"solver", {{"type", "xpbd"}, {"dt", 1.0 / 60}, {"substeps", 20}, {"iterations", 1}}},
        {"render", render},
        {"bodies",
         {{{"name", "slab"},
           {"mesh", "meshes/slab.vtet"},
           {"material",
            {{"model", "stable_neo_hookean"}, {"youngs_modulus", 5000}, {"poisson_ratio", 0.4}, {"density", 1000}}},
           {"fixed_nodes", {0, 1, 2}}}}}};
    if (edit) edit(scene["bodies"][0]);
    vcase::Manifest m;
    m.caseId = "view";
    m.caseVersion = "1.0.0";
    m.minPlayerVersion = "0.1.0";
    m.features = {"xpbd"};
    vcase::CaseWriter w(m);
    w.addFile("scene.json", scene.dump());
    w.addFile("meshes/slab.vtet", sim::formatVtet(*mesh));
    for (const auto& [entry, bytes] : files)
        w.addFile(entry, bytes);
    w.write(path);
    return path;
}

/// A one-body case; `map` is the .vsamples text (empty: none), `sampling` the render mode.
std::filesystem::path writeCase(const std::string& name, const std::string& sampling, const std::string& map) {
    if (map.empty()) return writeMappedCase(name, {{"sampling", sampling}}, {});
    return writeMappedCase(name, {{"sampling", sampling}}, {{"maps/slab.vsamples", map}},
                           [](nlohmann::json& body) { body["sample_map_file"] = "maps/slab.vsamples"; });
}

/// A w × h checker of two colours, 8 × 8 pixel squares.
render::Image checker(int w, int h, uint8_t a, uint8_t b) {
    render::Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(size_t(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const uint8_t v = ((x / 8 + y / 8) & 1) ? a : b;
            uint8_t* p = &img.rgba[(size_t(y) * w + x) * 4];
            p[0] = v;
            p[1] = uint8_t(255 - v);
            p[2] = 40;
            p[3] = 255;
        }
    return img;
}

std::string loadError(const std::filesystem::path& p) {
    try {
        player::loadCase(p, unsignedAllowed());
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
    const player::LoadedCase loaded = player::loadCase(path, unsignedAllowed());
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
    const player::LoadedCase loaded = player::loadCase(none, unsignedAllowed());
    EXPECT_TRUE(loaded.sampleMaps[0].empty());
    const render::SceneView view = player::caseView(loaded);
    for (float c : view.meshes()[0].sampleMap)
        EXPECT_EQ(c, 0.0f);
    for (const auto& p : {unused, malformed, shortMap, none})
        std::filesystem::remove(p);
}

TEST(CaseView, MaterialMapsOfTheCaseAreDecodedAndPutOnTheNamedMesh) {
    const render::Image diffuse = checker(32, 32, 200, 30), rough = checker(32, 32, 90, 160);
    const nlohmann::json render = {{"materials",
                                    {{"slab",
                                      {{"diffuse", "textures/slab_diffuse.png"},
                                       {"roughness", "textures/slab_roughness.png"},
                                       {"tiles_per_metre", 40}}}}}};
    const auto path = writeMappedCase("maps", render,
                                      {{"textures/slab_diffuse.png", render::encodePng(diffuse)},
                                       {"textures/slab_roughness.png", render::encodePng(rough)}});
    const player::LoadedCase c = player::loadCase(path, unsignedAllowed());
    ASSERT_EQ(c.materialMaps.size(), 1u);
    EXPECT_EQ(c.materialMaps[0].first, "slab");
    const render::MaterialMaps& maps = *c.materialMaps[0].second;
    EXPECT_EQ(maps.diffuse.rgba, diffuse.rgba) << "decoded exactly";
    EXPECT_EQ(maps.roughness.rgba, rough.rgba);
    EXPECT_TRUE(maps.metallic.empty());
    EXPECT_TRUE(maps.normal.empty());
    EXPECT_FLOAT_EQ(maps.tilesPerMetre, 40.0f);
    const render::SceneView view = player::caseView(c);
    ASSERT_EQ(view.meshes().size(), 1u);
    EXPECT_EQ(view.materials().at(view.meshes()[0].material).maps.get(), &maps) << "the body draws with them";
    std::filesystem::remove(path);
}

TEST(CaseView, BadMaterialMapsAreRefusedAtLoadNamingTheFieldAndTheRule) {
    const std::string png = render::encodePng(checker(16, 16, 10, 250));
    const std::string big = render::encodePng(checker(32, 16, 10, 250));
    auto error = [&](const std::string& name, const nlohmann::json& materials,
                     const std::vector<std::pair<std::string, std::string>>& files) {
        const auto path = writeMappedCase(name, {{"materials", materials}}, files);
        const std::string e = loadError(path);
        std::filesystem::remove(path);
        return e;
    };
    const std::string where = ".vcase: scene.json: render.materials.";
    EXPECT_NE(error("missing", {{"slab", {{"diffuse", "textures/d.png"}}}}, {})
                  .find(where + "slab: 'textures/d.png' is not in the package"),
              std::string::npos);
    EXPECT_NE(error("target", {{"liver", {{"diffuse", "textures/d.png"}}}}, {{"textures/d.png", png}})
                  .find(where + "liver: 'liver' is not a body, surface or scenery of the scene"),
              std::string::npos);
    EXPECT_NE(error("none", {{"slab", {{"tiles_per_metre", 10}}}}, {}).find("render.materials.slab: names no map"),
              std::string::npos);
    EXPECT_NE(error("key", {{"slab", {{"diffuse", "textures/d.png"}, {"albedo", "x.png"}}}}, {{"textures/d.png", png}})
                  .find("render.materials.slab.albedo: unknown field"),
              std::string::npos);
    EXPECT_NE(error("escape", {{"slab", {{"diffuse", "../d.png"}}}}, {}).find("render.materials.slab.diffuse"),
              std::string::npos);
    EXPECT_NE(
        error("tiles", {{"slab", {{"diffuse", "textures/d.png"}, {"tiles_per_metre", 0}}}}, {{"textures/d.png", png}})
            .find("render.materials.slab.tiles_per_metre: must be in (0, 10000]"),
        std::string::npos);
    EXPECT_NE(error("notpng", {{"slab", {{"diffuse", "textures/d.png"}}}}, {{"textures/d.png", "not a png at all"}})
                  .find("textures/d.png: not a PNG image"),
              std::string::npos);
    const std::string sizes = error("sizes", {{"slab", {{"diffuse", "textures/d.png"}, {"normal", "textures/n.png"}}}},
                                    {{"textures/d.png", png}, {"textures/n.png", big}});
    EXPECT_NE(
        sizes.find("'textures/n.png' is 32 x 16, 'textures/d.png' is 16 x 16 (a material's maps must have one size)"),
        std::string::npos)
        << sizes;
}

namespace {

/// A PNG whose header says width × height (8-bit RGBA) with no pixel data behind it: what a
/// decompression bomb looks like to a reader that trusts the header.
std::string pngHeaderOnly(uint32_t width, uint32_t height) {
    auto crc = [](const std::string& bytes) {
        uint32_t c = 0xFFFFFFFFu;
        for (unsigned char b : bytes) {
            c ^= b;
            for (int k = 0; k < 8; ++k)
                c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        }
        return c ^ 0xFFFFFFFFu;
    };
    auto be32 = [](uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; };
    auto chunk = [&](const std::string& type, const std::string& data) {
        return be32(uint32_t(data.size())) + type + data + be32(crc(type + data));
    };
    const std::string ihdr = be32(width) + be32(height) + std::string{8, 6, 0, 0, 0};
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", "") + chunk("IEND", "");
}

} // namespace

// Maps that would decode to more than the case budget (128 MiB) together are refused from their
// headers before anything is decoded, with one line naming the total and the budget; each one
// alone is within the 4096-pixel side.
TEST(CaseView, MapsOverTheDecodedImageBudgetAreRefusedBeforeDecoding) {
    const std::string bomb = pngHeaderOnly(4096, 4096); // 64 MiB decoded, 57 bytes here
    ASSERT_LT(bomb.size(), 100u);
    EXPECT_EQ(render::pngSize(bomb, "bomb"), (std::pair<uint32_t, uint32_t>{4096, 4096}));
    const auto path = writeMappedCase(
        "budget",
        {{"materials",
          {{"slab", {{"diffuse", "textures/d.png"}, {"roughness", "textures/r.png"}, {"normal", "textures/n.png"}}}}}},
        {{"textures/d.png", bomb}, {"textures/r.png", bomb}, {"textures/n.png", bomb}});
    const std::string e = loadError(path);
    std::filesystem::remove(path);
    EXPECT_NE(e.find(".vcase: scene.json: render.materials: the maps decode to 192 MiB (3 maps), more than the 128 "
                     "MiB budget of a case's images"),
              std::string::npos)
        << e;
    EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 0) << "one line";
    // Two of them fit the budget: then the decoder itself finds there are no pixels.
    const auto two = writeMappedCase(
        "budget2", {{"materials", {{"slab", {{"diffuse", "textures/d.png"}, {"roughness", "textures/r.png"}}}}}},
        {{"textures/d.png", bomb}, {"textures/r.png", bomb}});
    const std::string e2 = loadError(two);
    std::filesystem::remove(two);
    EXPECT_NE(e2.find("textures/d.png: cannot decode PNG"), std::string::npos) << e2;
}

TEST(CaseView, MaterialEntriesComeSortedByNameWithTheirFiles) {
    // entries sorted by name, each with its files in the order diffuse, roughness, metallic, normal
    const auto entries = render::caseMaterialMaps(
        R"({"materials": {"b": {"normal": "t/b_n.png"}, "a": {"diffuse": "t/a.png", "metallic": "t/a_m.png"}}})",
        "scene.json");
    ASSERT_EQ(entries.size(), 2u);
    EXPECT_EQ(entries[0].target, "a");
    EXPECT_EQ(entries[0].files(), (std::vector<std::string>{"t/a.png", "t/a_m.png"}));
    EXPECT_EQ(entries[1].files(), (std::vector<std::string>{"t/b_n.png"}));
    EXPECT_TRUE(render::caseMaterialMaps("", "scene.json").empty());
    EXPECT_TRUE(render::caseMaterialMaps(R"({"sss": true})", "scene.json").empty());
}

namespace {

/// Corner UVs for the slab's boundary: u from x (0..1 over the slab), the triangles with their
/// centroid at x > 4 cm in a second island (u + 2): a seam across the slab at x = 4 cm.
std::vector<render::CornerUvF> slabCornerUv(size_t* seamVertices = nullptr) {
    auto mesh = slab();
    mesh->requireLevel(3);
    const sim::TriMesh& b = mesh->boundary();
    std::vector<render::CornerUvF> uv;
    std::set<int32_t> onSeam;
    for (const sim::Tri& t : b.triangles()) {
        const sim::Vec3 c = (b.positions()[t[0]] + b.positions()[t[1]] + b.positions()[t[2]]) / 3.0;
        render::CornerUvF corner;
        for (int k = 0; k < 3; ++k) {
            const sim::Vec3& p = b.positions()[t[k]];
            corner[size_t(k)] = Eigen::Vector2f(float(p.x() / 0.08 + (c.x() > 0.04 ? 2 : 0)), float(p.z() / 0.04));
            if (std::abs(p.x() - 0.04) < 1e-9) onSeam.insert(t[k]);
        }
        uv.push_back(corner);
    }
    if (seamVertices) *seamVertices = onSeam.size();
    return uv;
}

} // namespace

TEST(CaseView, CornerUvsLayTheMapsAndSplitTheBodyAtItsSeams) {
    size_t seam = 0;
    const std::vector<render::CornerUvF> uv = slabCornerUv(&seam);
    ASSERT_GT(seam, 0u);
    const nlohmann::json render = {
        {"materials", {{"slab", {{"diffuse", "textures/slab_diffuse.png"}, {"uv", "meshes/slab.vuv"}}}}}};
    const auto path = writeMappedCase("uv", render,
                                      {{"textures/slab_diffuse.png", render::encodePng(checker(16, 16, 10, 250))},
                                       {"meshes/slab.vuv", render::cornerUvBytes(uv)}});
    const player::LoadedCase c = player::loadCase(path, unsignedAllowed());
    ASSERT_EQ(c.cornerUvs.size(), 1u);
    EXPECT_EQ(c.cornerUvs[0].first, "slab");
    ASSERT_EQ(c.cornerUvs[0].second.size(), uv.size());
    render::SceneView view = player::caseView(c);
    ASSERT_EQ(view.meshes().size(), 1u);
    const render::RenderMesh& m = view.meshes()[0];
    auto mesh = slab();
    mesh->requireLevel(3);
    // One render vertex per (node, UV): the seam's nodes appear twice, every other node once.
    EXPECT_EQ(m.vertexCount(), mesh->boundaryVertexMap().size() + seam);
    ASSERT_EQ(m.uv.size(), 2 * m.vertexCount());
    ASSERT_EQ(m.weld.size(), m.vertexCount());
    for (size_t t = 0; t < uv.size(); ++t)
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t v = m.indices[3 * t + k];
            EXPECT_EQ(m.uv[2 * v], uv[t][k].x());
            EXPECT_EQ(m.uv[2 * v + 1], uv[t][k].y());
        }
    // The copies of a node move with it and share one normal.
    view.recomputeNormals(0);
    for (size_t v = 0; v < m.vertexCount(); ++v) {
        const uint32_t w = m.weld[v];
        EXPECT_EQ(m.sourceVertex[v], m.sourceVertex[w]);
        for (int k = 0; k < 3; ++k)
            EXPECT_FLOAT_EQ(m.normals[3 * v + size_t(k)], m.normals[3 * w + size_t(k)]);
    }
    std::filesystem::remove(path);
}

TEST(CaseView, BadCornerUvsAreRefusedAtLoadNamingTheEntryAndTheRule) {
    std::vector<render::CornerUvF> uv = slabCornerUv();
    const std::string png = render::encodePng(checker(16, 16, 10, 250));
    const nlohmann::json render = {
        {"materials", {{"slab", {{"diffuse", "textures/slab_diffuse.png"}, {"uv", "meshes/slab.vuv"}}}}}};
    auto refused = [&](const std::string& bytes, const std::string& rule) {
        const auto path =
            writeMappedCase("baduv", render, {{"textures/slab_diffuse.png", png}, {"meshes/slab.vuv", bytes}});
        try {
            player::loadCase(path, unsignedAllowed());
            ADD_FAILURE() << "accepted: " << rule;
        } catch (const InputError& e) {
            EXPECT_THAT(e.what(), ::testing::HasSubstr("meshes/slab.vuv: " + rule));
        }
        std::filesystem::remove(path);
    };
    std::vector<render::CornerUvF> fewer(uv.begin(), uv.end() - 1);
    refused(render::cornerUvBytes(fewer),
            std::to_string(fewer.size()) + " triangles, the body's boundary has " + std::to_string(uv.size()));
    refused("JPEG....", "not a corner-UV file");
    std::string cut = render::cornerUvBytes(uv);
    cut.pop_back();
    refused(cut, std::to_string(cut.size()) + " bytes");
    std::string nan = render::cornerUvBytes(uv);
    const float bad = std::nanf("");
    std::memcpy(&nan[8 + 24 * 5 + 8], &bad, 4); // triangle 5, corner 1, u
    refused(nan, "triangle 5 corner 1: the UV is not finite");
    EXPECT_THROW(render::cornerUvBytes({{Eigen::Vector2f(1e9f, 0), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()}}),
                 std::invalid_argument);
}
