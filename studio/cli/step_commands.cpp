#include "step_commands.hpp"

#include "project/remesh_cache.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/xpbd_scene_solver.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

using namespace viscera;

void printQuality(const sim::QualityReport& q) {
    std::printf("  quality: min dihedral %.2f deg, max dihedral %.2f deg, mean ratio min %.3f mean %.3f\n"
                "           %zu inverted, %zu degenerate, %zu slivers; volume %.6g m^3\n",
                q.minDihedralDeg, q.maxDihedralDeg, q.minMeanRatio, q.meanMeanRatio, q.inverted.size(),
                q.degenerate.size(), q.slivers.size(), q.totalVolume);
}

studio::BodyFigures bodyFigures(const studio::BodyExport& b) {
    const sim::QualityReport& q = b.quality;
    return {b.name,
            int64_t(b.nodes),
            int64_t(b.tets),
            int64_t(b.fixedNodes),
            q.minDihedralDeg,
            q.maxDihedralDeg,
            q.minMeanRatio,
            q.meanMeanRatio,
            int64_t(q.inverted.size()),
            int64_t(q.degenerate.size()),
            int64_t(q.slivers.size()),
            q.totalVolume};
}

namespace {

struct MeshArgs {
    std::optional<std::string> dir, body, projectFile, out, result;
};

MeshArgs parseMeshArgs(const std::vector<std::string>& args) {
    MeshArgs m;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::optional<std::string>* value = a == "--body"                  ? &m.body
                                            : a == "--project-file"        ? &m.projectFile
                                            : a == "-o" || a == "--output" ? &m.out
                                            : a == "--result"              ? &m.result
                                                                           : nullptr;
        if (value) {
            if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
            *value = args[++i];
        } else if (!a.empty() && a[0] == '-') {
            throw std::invalid_argument("unknown option '" + a + "'");
        } else if (!m.dir) {
            m.dir = a;
        } else {
            throw std::invalid_argument("unexpected argument '" + a + "'");
        }
    }
    if (!m.dir || !m.body) throw std::invalid_argument("mesh needs <project-dir> and --body <name>");
    return m;
}

/// The load-time stability rule for body `desc` alone (no embedding, no layers): the figures the
/// player computes for it, with selective inertia scaling where the project allows it.
sim::StabilityFigures bodyStability(const studio::Project& project, sim::BodyDesc desc, const sim::TetMesh& mesh,
                                    const std::string& origin) {
    sim::SceneDesc scene = project.scene;
    desc.embeddedIn.clear();
    scene.bodies = {std::move(desc)};
    scene.surfaces.clear();
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    meshes.push_back(mesh.clone());
    const std::vector<sim::TriMesh> surfaces;
    return sim::assessSceneStability({scene, meshes, surfaces, origin}).at(0);
}

} // namespace

int cmdMesh(const std::vector<std::string>& args) {
    const MeshArgs a = parseMeshArgs(args);
    const studio::Project project = a.projectFile
                                        ? studio::loadProjectText(readFile(*a.projectFile), *a.dir, *a.projectFile)
                                        : studio::loadProject(*a.dir);
    const std::string origin = (project.dir / "project.json").string();
    size_t index = project.bodies.size();
    for (size_t i = 0; i < project.bodies.size(); ++i)
        if (project.bodies[i].scene.name == *a.body) index = i;
    if (index == project.bodies.size()) throw InputError(origin + ": bodies: no body named '" + *a.body + "'");
    const studio::BodyProject& b = project.bodies[index];
    const std::string field = "bodies[" + std::to_string(index) + "] ('" + b.scene.name + "')";
    for (const auto& file : {a.out, a.result})
        if (file) {
            requireWritableFile(*file, file == a.out ? "the tet mesh" : "the step result");
            requireNotAnInput(*file, "an output", studio::projectInputFiles(project));
        }
    std::fprintf(stderr, "viscera-studio: stage 1/2: meshing body '%s'\n", b.scene.name.c_str());
    const auto t0 = std::chrono::steady_clock::now();
    const uint64_t remeshes = studio::remeshRunCount();
    std::unique_ptr<sim::TetMesh> mesh;
    size_t seeded = 0;
    try {
        mesh = studio::buildBodyMesh(b, origin, nullptr, project.dir, &seeded);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": " + field + ".mesh: " + e.what());
    }
    std::fprintf(stderr, "viscera-studio: stage 2/2: checking body '%s'\n", b.scene.name.c_str());
    sim::BodyDesc desc = b.scene;
    const studio::BodyExport be = studio::checkBodyMesh(b, *mesh, desc, origin, field);
    std::optional<sim::Skeleton> skeleton;
    desc.nodeWeights = studio::bodyNodeWeights(b, *mesh, skeleton, origin, field);
    studio::MeshingStepResult r;
    r.body = bodyFigures(be);
    r.substeps = project.scene.xpbd.substeps;
    r.requiredSubsteps = r.substeps;
    if (project.scene.solverType == "xpbd") {
        const sim::StabilityFigures f = bodyStability(project, desc, *mesh, origin);
        r.requiredSubsteps = f.requiredSubsteps;
        r.stiffnessNumber = f.maxStiffnessNumber;
    }
    r.remeshReused = b.mesh.kind == studio::MeshSource::Kind::Remesh && studio::remeshRunCount() == remeshes;
    r.seededPoints = static_cast<int64_t>(seeded);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("meshed body %s: %zu nodes, %zu tets, %zu fixed in %.2f s%s\n", be.name.c_str(), be.nodes, be.tets,
                be.fixedNodes, r.seconds, r.remeshReused ? " (the kept remesh)" : "");
    printQuality(be.quality);
    if (seeded > 0)
        std::printf("  thin parts: %zu surface point(s) the first refinement missed, seeded and meshed\n", seeded);
    std::printf("  stability: stiffness number %.3g at %d substeps per frame; %d needed\n", r.stiffnessNumber,
                r.substeps, r.requiredSubsteps);
    if (a.out) {
        sim::writeVtet(*a.out, *mesh);
        std::printf("wrote %s\n", a.out->c_str());
    }
    if (a.result) studio::writeStepResult(*a.result, r);
    return 0;
}
