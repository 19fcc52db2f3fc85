#include "runtime/session.hpp"

#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"

#include <chrono>

namespace viscera::player {

LoadedCase loadCase(const std::filesystem::path& casePath) {
    LoadedCase out;
    out.package = vcase::CasePackage::open(casePath);
    const vcase::CasePackage& pkg = *out.package;
    const std::string sceneName = "scene.json";
    if (!pkg.contains(sceneName))
        throw InputError(pkg.name() + ": " + sceneName + ": required file is missing from the package");
    out.scene = sim::parseScene(pkg.read(sceneName), pkg.name() + ":" + sceneName);
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    for (const sim::BodyDesc& b : out.scene.bodies) {
        if (!pkg.contains(b.meshPath))
            throw InputError(pkg.name() + ": " + sceneName + ": body '" + b.name + "' uses mesh '" + b.meshPath +
                             "', which is not in the package");
        meshes.push_back(sim::parseVtet(pkg.read(b.meshPath), pkg.name() + ":" + b.meshPath));
    }
    std::vector<sim::TriMesh> surfaces;
    for (const sim::SurfaceDesc& sd : out.scene.surfaces) {
        if (!pkg.contains(sd.meshPath))
            throw InputError(pkg.name() + ": " + sceneName + ": surface '" + sd.name + "' uses mesh '" + sd.meshPath +
                             "', which is not in the package");
        surfaces.push_back(sim::parseVtri(pkg.read(sd.meshPath), pkg.name() + ":" + sd.meshPath));
    }
    out.world = sim::World::assemble(out.scene, std::move(meshes), std::move(surfaces), pkg.manifest().features,
                                     pkg.name() + ": manifest.json");
    return out;
}

SessionResult runSession(LoadedCase& loaded, const RunOptions& options) {
    SessionResult r;
    const vcase::Manifest& m = loaded.package->manifest();
    r.caseId = m.caseId;
    r.caseVersion = m.caseVersion;
    r.title = m.title.value_or("");
    sim::World& world = *loaded.world;
    r.activeSubsystems = world.activeSubsystems();
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        r.nodes += world.restMesh(b).vertexCount();
        r.tets += world.restMesh(b).tetCount();
    }
    r.frames.reserve(static_cast<size_t>(std::max(options.frames, 0)));
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < options.frames; ++f) {
        sim::FrameRecord rec = world.step();
        if (!rec.finite)
            r.errors.push_back("frame " + std::to_string(rec.index) +
                               ": the step produced a non-finite value and was rolled back");
        r.frames.push_back(rec);
        if (options.progress) options.progress(f + 1, options.frames);
    }
    r.wallTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.simTime = world.time();
    r.invariants = world.invariants();
    r.accuracy = world.accuracy();
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        const auto& rest = world.restMesh(b).positions();
        const auto& x = world.positions(b);
        for (size_t v = 0; v < x.size(); ++v)
            r.maxNodeDisplacement = std::max(r.maxNodeDisplacement, (x[v] - rest[v]).norm());
    }
    return r;
}

} // namespace viscera::player
