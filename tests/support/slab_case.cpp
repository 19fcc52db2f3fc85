// Fixture, not a test: builds the cantilever slab case the player end-to-end tests run and assert on
// (slab_case.hpp); the assertions are in test_player_cli.cpp and test_package_trust.cpp.
#include "support/slab_case.hpp"

#include "case/case_writer.hpp"
#include "case/signing.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/scene.hpp"

namespace viscera::test {

std::vector<vcase::test::RawEntry> slabCaseFiles(const SlabCase& slab) {
    auto mesh = sim::makeBoxTetMesh({sim::Vec3::Zero(), sim::Vec3(0.08, 0.02, 0.02), {8, 2, 2}});
    sim::SceneDesc scene;
    scene.xpbd.gravity = slab.gravity;
    scene.xpbd.substeps = 50; // what the load-time stability check asks for
    scene.render = slab.render;
    sim::BodyDesc body;
    body.name = "slab";
    body.meshPath = "meshes/slab.vtet";
    body.material.youngsModulus = 20000;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].x() < 1e-9) body.fixedNodes.push_back(v);
    scene.bodies.push_back(body);
    return {{"meshes/slab.vtet", sim::formatVtet(*mesh)}, {"scene.json", sim::formatScene(scene)}};
}

vcase::Manifest slabCaseHeader(const SlabCase& slab) {
    vcase::Manifest header;
    header.caseId = slab.caseId;
    header.caseVersion = slab.caseVersion;
    header.minPlayerVersion = "0.1.0";
    header.features = slab.features;
    header.expires = slab.expires;
    return header;
}

std::filesystem::path writeSlabCase(const std::filesystem::path& file, const SlabCase& slab) {
    vcase::CaseWriter w(slabCaseHeader(slab));
    for (vcase::test::RawEntry& e : slabCaseFiles(slab))
        w.addFile(e.name, std::move(e.bytes));
    std::optional<vcase::SigningKey> key;
    if (!slab.signingKey.empty()) {
        key = vcase::SigningKey::load(slab.signingKey);
        w.sign(*key, "Viscera samples (test key)");
    }
    w.write(file);
    return file;
}

} // namespace viscera::test
