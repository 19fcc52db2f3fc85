// viscera-studio: the desktop studio, and the headless authoring commands (no display, no Qt
// application object).
//
//   viscera-studio [open <project-dir>]
//   viscera-studio export <project-dir> -o <case.vcase> [--project-file <json>]
//   viscera-studio import <mesh> [--scale S] [--tetrahedralize] [--cell-size M] [--facet-size M]
//                         [-o out.vtet]
//   viscera-studio remesh <mesh>... [--subtract M] [--intersect M] [options] -o out.obj
//   viscera-studio remesh --project <project-dir> --body NAME [--project-file <json>] -o out.vremesh
//   viscera-studio mesh <project-dir> --body NAME [--project-file <json>] [-o out.vtet]
//   viscera-studio texture <spec.json> -o <dir>
//   viscera-studio sample kidney -o <project-dir>
//   viscera-studio sample hepatocystic -o <folder>
//   viscera-studio sample rectum -o <folder>
//
// remesh runs the voxel remesh (bake/remesh.hpp) on the parts and prints its figures.
//
// texture generates the quadtree pattern mask and the material maps of one layer from a texture
// spec (bake/texture.hpp, README "Texture spec") and writes <dir>/<name>_<map>.png; stdout lists
// the palette, the files written and the time of each phase.
//
// export --project-file reads the project text from <json> instead of <project-dir>/project.json
// (its file references still resolve against <project-dir>): the authoring window exports its
// unsaved model this way, as a child process.
//
// Export progress goes to stderr, one line per stage, in a format other programs may parse:
//
//   viscera-studio: stage <i>/<n>: <what>      e.g. "viscera-studio: stage 3/9: meshing body 'organ'"
//
// <i> counts 1..<n>; <n> is the same on every line of one export (studio::ExportProgress). A
// failure is one line "viscera-studio: <message>" (no "stage"), exit code 1. The summary goes to
// stdout.
//
// Typed results: import, remesh, mesh and export take --result FILE and write what they did as
// one small JSON file (studio/project/step_result.hpp), atomically, after the work succeeded; the
// studio reads that file, never the text on stdout (which is for people).
//
// Exit codes: 0 success, 1 bad input (project, mesh, texture spec), 2 usage.
#include "app/studio_app.hpp"
#include "bake/import.hpp"
#include "bake/remesh.hpp"
#include "bake/sample_anatomy.hpp"
#include "bake/tetrahedralize.hpp"
#include "bake/texture.hpp"
#include "bake/uv_transfer.hpp"
#include "haptics/trajectory.hpp"
#include "project/project.hpp"
#include "project/publishing.hpp"
#include "project/remesh_cache.hpp"
#include "project/sample_anatomy_files.hpp"
#include "project/sample_kidney.hpp"
#include "project/step_result.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/cli_main.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "step_commands.hpp"
#include "uv_report.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace {

using namespace viscera;

void usage(std::FILE* out) {
    std::fputs("usage: viscera-studio [open <project-dir>]           the desktop studio\n"
               "       viscera-studio export <project-dir> -o <case.vcase> [--project-file <json>]\n"
               "                             [--sign-key KEY.pem [--signer NAME] | --unsigned] [--expires DATE]\n"
               "       viscera-studio keygen [-o KEY.pem]\n"
               "       viscera-studio import <mesh> [--scale S] [--tetrahedralize] [--cell-size M]\n"
               "                             [--facet-size M] [-o out.vtet]\n"
               "       viscera-studio remesh [<mesh>...] [--sample kidney] [--subtract M] [--intersect M] [options] -o "
               "out.obj\n"
               "       viscera-studio remesh --project <project-dir> --body NAME [--project-file <json>] -o "
               "out.vremesh\n"
               "       viscera-studio mesh <project-dir> --body NAME [--project-file <json>] [-o out.vtet]\n"
               "       viscera-studio texture <spec.json> -o <dir>\n"
               "       viscera-studio sample kidney -o <project-dir>\n"
               "       viscera-studio sample hepatocystic -o <folder>\n"
               "       viscera-studio sample rectum -o <folder>\n"
               "       viscera-studio replay <project-dir> -o <replay.csv> [--frames N]\n"
               "       viscera-studio --version\n",
               out);
}

constexpr const char* kExportHelp =
    "usage: viscera-studio export <project-dir> -o <case.vcase> [--project-file <json>]\n"
    "                             [--sign-key KEY.pem [--signer NAME] | --unsigned] [--expires DATE]\n"
    "\n"
    "Builds a case package from a project: meshes the bodies, cuts the fascia, bakes paint and\n"
    "textures, writes scene.json and the manifest with only the features the scene needs, and\n"
    "signs the manifest with the publisher key (Ed25519). The output is written atomically; its\n"
    "folder and the key are checked before the work starts.\n"
    "  --project-file <json>  read the project from this file instead of <project-dir>/project.json\n"
    "  --sign-key KEY.pem     the publisher key (default ~/.config/viscera/publisher-key.pem where it\n"
    "                         exists; never inside the project folder; mode 600)\n"
    "  --signer NAME          the name in the signature (default: the key file's name)\n"
    "  --unsigned             no signature (players run it only with --allow-unsigned)\n"
    "  --expires DATE         players refuse the case after DATE (YYYY-MM-DD, end of day UTC, or\n"
    "                         YYYY-MM-DDTHH:MM:SSZ)\n"
    "  --result FILE          write the export's figures as a typed result (JSON) for the studio\n";
constexpr const char* kKeygenHelp =
    "usage: viscera-studio keygen [-o KEY.pem]\n"
    "\n"
    "Makes a publisher key pair for signing cases (Ed25519): the private key at KEY.pem (mode 600;\n"
    "default ~/.config/viscera/publisher-key.pem, the key export uses when none is given) and the\n"
    "public key at KEY.pub.pem, which players trust (--trust KEY.pub.pem, or a copy in\n"
    "/etc/viscera/trusted-publishers named after the publisher). Never replaces an existing key.\n";
constexpr const char* kImportHelp =
    "usage: viscera-studio import <mesh>... [--scale S] [--tetrahedralize] [--cell-size M]\n"
    "                             [--facet-size M] [-o out.vtet]\n"
    "\n"
    "Reads a surface mesh (OBJ, STL, PLY, glTF/GLB through assimp), checks it, prints its size,\n"
    "closedness and bounds; with --tetrahedralize meshes its volume (CGAL) and prints the quality.\n"
    "  --scale S        metres per file unit (default 1)\n"
    "  --cell-size M    largest tetrahedron size, m;  --facet-size M  largest surface facet, m\n"
    "  -o out.vtet      write the tet mesh (needs --tetrahedralize)\n"
    "  --result FILE    write each file's figures as a typed result (JSON) for the studio\n";
constexpr const char* kRemeshHelp =
    "usage: viscera-studio remesh <mesh>... [--subtract <mesh>] [--intersect <mesh>] [options] -o out.obj\n"
    "\n"
    "Voxel remesh: makes open, self-intersecting or overlapping parts one closed, manifold surface\n"
    "free of self-intersections (OpenVDB level sets and CSG, CGAL isotropic remeshing) and prints\n"
    "its figures: closedness, intersecting pairs, distance to the source (mean, max), volumes.\n"
    "The parts combine in the order given: each <mesh> by union, --subtract by difference,\n"
    "--intersect by intersection. Progress goes to stderr.\n"
    "  --sample kidney     add the built-in kidney-like anatomy (four overlapping parts: a\n"
    "                      self-intersecting cortex with a hole, pelvis, open ureter, artery)\n"
    "  --scale S           metres per file unit of every part (default 1)\n"
    "  --voxel-size M      voxel edge, m (default: the longest axis / --voxels)\n"
    "  --voxels N          voxels along the longest axis (default 128)\n"
    "  --band V            narrow band half width, voxels (default 3)\n"
    "  --smooth N          mean-curvature smoothing passes (default 0)\n"
    "  --edge-length M     target edge length, m (default 1.5 voxels)\n"
    "  --iterations N      remeshing iterations (default 3; 0 keeps the isosurface)\n"
    "  --fill-openings M   cap the openings of open parts up to M wide, m (an open duct becomes\n"
    "                      solid, not a hollow shell; default: none)\n"
    "  --feature-angle D   dihedral angle that makes an edge hard, degrees (default 60)\n"
    "When every part has UVs (the sample does), the result is cut along the parts' UV seams,\n"
    "remeshed with the seam edges hard and given UVs by seam cutting [A 3.3.4]; the closest-point\n"
    "and island-labelled transfers are measured beside it (triangles over two islands or over a\n"
    "seam, angle and area distortion, UV error), one 'name value' line each, and the OBJ carries\n"
    "the UVs (vt) of the method chosen.\n"
    "  --uv-transfer M     the UVs written: seam-cut (default), closest or island\n"
    "  --no-uv             no UV transfer\n"
    "  --uv-preview P.png  checker preview: source, closest point, seam cutting (headless EGL)\n"
    "  --result FILE       write the figures as a typed result (JSON) for the studio\n"
    "With --project <project-dir> --body NAME [--project-file <json>] the parts and settings are\n"
    "those of the body's remesh block, remeshed as export remeshes them, and -o names the kept\n"
    "remesh (.vremesh) the studio's Apply moves into <project-dir>/cache for export to reuse.\n";
constexpr const char* kSampleHelp =
    "usage: viscera-studio sample kidney -o <project-dir>\n"
    "       viscera-studio sample hepatocystic -o <folder>\n"
    "       viscera-studio sample rectum -o <folder>\n"
    "\n"
    "Writes the kidney sample project, made by code: the kidney-like render anatomy (four\n"
    "overlapping parts with UV islands and seams) as anatomy/*.obj with UVs, its texture atlas\n"
    "anatomy/kidney.png, and a project.json whose body is made from them by the remesh block\n"
    "(voxel remesh, seam-cutting UV transfer, tetrahedralize). Export it with\n"
    "'viscera-studio export <project-dir> -o kidney.vcase'.\n"
    "\n"
    "hepatocystic writes the anatomy of a cholecystectomy step as bought anatomy arrives, to import\n"
    "in the studio (File > Import anatomy): liver, gallbladder, cystic_duct, common_bile_duct and\n"
    "cystic_artery .obj (overlapping parts, the liver and the ducts open, UVs in one atlas) and the\n"
    "atlas hepatocystic.png. No project is written: the case is built in the studio.\n"
    "\n"
    "rectum writes the mesorectum and its pelvis the same way: mesorectum (a closed fat shell over\n"
    "the rectum, overlapping it), rectum (an open tube), pelvic_wall and peritoneum (open surfaces)\n"
    ".obj with UVs, to import in the studio like the hepatocystic parts.\n";
constexpr const char* kOpenHelp = "usage: viscera-studio open <project-dir>\n"
                                  "\n"
                                  "Opens the desktop studio on a project (without a folder: an empty studio).\n";
constexpr const char* kTextureHelp =
    "usage: viscera-studio texture <spec.json> -o <dir>\n"
    "\n"
    "Generates a procedural tissue material from its spec (quadtree patterns, palette, layers):\n"
    "diffuse, normal, roughness, height, metallic as the spec asks, PNG, into <dir>.\n";
constexpr const char* kReplayHelp =
    "usage: viscera-studio replay <project-dir> -o <replay.csv> [--frames N]\n"
    "\n"
    "Writes a console replay of a suturing project's recorded needle motion, through the\n"
    "project's suture.device mapping, for viscera-player run --device replay:<replay.csv>.\n"
    "  --frames N   only the first N frames (default: the whole trajectory)\n";

double parsePositive(const std::string& flag, const std::string& v) {
    char* end = nullptr;
    double d = std::strtod(v.c_str(), &end);
    if (*end != '\0' || !(d > 0) || !std::isfinite(d))
        throw std::invalid_argument(flag + " '" + v + "' must be a positive number");
    return d;
}

/// The arguments of a command taking one operand, -o/--output <value> and the value options
/// `extra` names ("--project-file"): throws std::invalid_argument for an unknown option, a missing
/// value or a second operand.
struct OperandArgs {
    std::optional<std::string> operand, out;
    std::vector<std::optional<std::string>> extra; ///< one per name in `extra`, in that order
};
OperandArgs parseOperandArgs(const std::vector<std::string>& args, std::initializer_list<std::string_view> extra = {}) {
    OperandArgs r;
    r.extra.resize(extra.size());
    for (size_t i = 0; i < args.size(); ++i) {
        std::optional<std::string>* value = args[i] == "-o" || args[i] == "--output" ? &r.out : nullptr;
        for (size_t k = 0; k < extra.size(); ++k)
            if (args[i] == extra.begin()[k]) value = &r.extra[k];
        if (value) {
            if (i + 1 >= args.size()) throw std::invalid_argument(args[i] + " needs a value");
            *value = args[++i];
        } else if (!args[i].empty() && args[i][0] == '-') {
            throw std::invalid_argument("unknown option '" + args[i] + "'");
        } else if (!r.operand) {
            r.operand = args[i];
        } else {
            throw std::invalid_argument("unexpected argument '" + args[i] + "'");
        }
    }
    return r;
}

int64_t secondsNow() {
    return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

/// The publisher key export signs with: --sign-key, else the default one where it exists; none
/// with --unsigned. Loaded before the work, so that a bad key costs no meshing.
std::optional<vcase::SigningKey> exportKey(const std::optional<std::string>& given, bool unsignedCase,
                                           const std::string& projectDir) {
    if (unsignedCase) {
        if (given) throw std::invalid_argument("--unsigned and --sign-key exclude each other");
        return std::nullopt;
    }
    // The rule the studio's File → Export case… follows too (studio/project/publishing.hpp).
    const std::optional<std::filesystem::path> file =
        given ? std::optional<std::filesystem::path>(*given) : studio::defaultPublisherKey();
    if (!file) {
        std::fprintf(stderr, "viscera-studio: warning: %s\n",
                     studio::unsignedCaseWarning(studio::defaultPublisherKeyPath()).c_str());
        return std::nullopt;
    }
    return studio::loadPublisherKey(*file, projectDir);
}

int cmdExport(const std::vector<std::string>& argsIn) {
    std::vector<std::string> args;
    bool unsignedCase = false;
    for (const std::string& a : argsIn)
        (a == "--unsigned" ? unsignedCase = true : (args.push_back(a), false));
    const OperandArgs parsed =
        parseOperandArgs(args, {"--project-file", "--sign-key", "--signer", "--expires", "--result"});
    const std::optional<std::string>& dir = parsed.operand;
    const std::optional<std::string>& out = parsed.out;
    const std::optional<std::string>& projectFile = parsed.extra[0];
    if (!dir || !out) throw std::invalid_argument("export needs <project-dir> and -o <case.vcase>");
    const auto t0 = std::chrono::steady_clock::now();
    studio::CasePublishing publish;
    if (parsed.extra[3]) publish.expires = studio::parseExpiry(*parsed.extra[3], secondsNow());
    const std::optional<vcase::SigningKey> key = exportKey(parsed.extra[1], unsignedCase, *dir);
    if (key) {
        publish.key = &*key;
        publish.signer = parsed.extra[2].value_or(studio::defaultSignerName(
            parsed.extra[1] ? std::optional<std::filesystem::path>(*parsed.extra[1]) : std::nullopt));
    }
    studio::Project project =
        projectFile ? studio::loadProjectText(readFile(*projectFile), *dir, *projectFile) : studio::loadProject(*dir);
    if (projectFile) requireNotAnInput(*out, "the case", {*projectFile}); // the project's own files: exportCase
    const std::optional<std::string>& resultFile = parsed.extra[4];
    if (resultFile) requireWritableFile(*resultFile, "the step result");
    const uint64_t remeshes = studio::remeshRunCount();
    studio::ExportResult r = studio::exportCase(
        project, *out,
        [](size_t index, size_t total, const std::string& stage) {
            std::fprintf(stderr, "viscera-studio: stage %zu/%zu: %s\n", index, total, stage.c_str());
        },
        publish);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("exported %s -> %s (%llu bytes, %.2f s)\n", project.caseId.c_str(), r.casePath.c_str(),
                static_cast<unsigned long long>(r.bytes), secs);
    std::printf("  package: %s; sha256 %s%s%s\n",
                key ? ("signed by '" + publish.signer + "' (" + r.keyId + ")").c_str() : "UNSIGNED", r.sha256.c_str(),
                publish.expires ? "; expires " : "", publish.expires.value_or("").c_str());
    std::printf("  features:");
    for (const auto& f : r.features)
        std::printf(" %s", f.c_str());
    std::printf("\n");
    for (const auto& b : r.bodies) {
        std::printf("  body %s: %zu nodes, %zu tets, %zu fixed\n", b.name.c_str(), b.nodes, b.tets, b.fixedNodes);
        printQuality(b.quality);
    }
    for (const std::string& w : r.warnings)
        std::fprintf(stderr, "viscera-studio: warning: %s\n", w.c_str());
    if (resultFile) {
        studio::ExportStepResult e;
        e.casePath = std::filesystem::absolute(r.casePath).string();
        e.bytes = int64_t(r.bytes);
        e.sha256 = r.sha256;
        e.keyId = key ? r.keyId : std::string();
        e.signer = key ? publish.signer : std::string();
        e.features = r.features;
        for (const auto& b : r.bodies)
            e.bodies.push_back(bodyFigures(b));
        e.remeshes = int64_t(studio::remeshRunCount() - remeshes);
        e.seconds = secs;
        e.warnings = r.warnings;
        studio::writeStepResult(*resultFile, e);
    }
    return 0;
}

int cmdKeygen(const std::vector<std::string>& args) {
    const OperandArgs parsed = parseOperandArgs(args);
    if (parsed.operand) throw std::invalid_argument("unexpected argument '" + *parsed.operand + "'");
    const studio::NewPublisherKey k =
        studio::makePublisherKey(parsed.out ? std::filesystem::path(*parsed.out) : studio::defaultPublisherKeyPath());
    std::printf("publisher key %s\n  private %s (mode 600: keep it outside every project folder)\n  public  %s "
                "(players trust it: --trust, or a copy in /etc/viscera/trusted-publishers)\n",
                k.keyId.c_str(), k.privateFile.c_str(), k.publicFile.c_str());
    return 0;
}

int cmdImport(const std::vector<std::string>& args) {
    std::vector<std::string> ins;
    std::optional<std::string> out, resultFile;
    bool tetra = false;
    bake::ImportOptions opt;
    bake::MeshingParams meshing;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
            return args[++i];
        };
        if (a == "--scale")
            opt.scale = parsePositive(a, value());
        else if (a == "--tetrahedralize")
            tetra = true;
        else if (a == "--cell-size")
            meshing.cellSize = parsePositive(a, value());
        else if (a == "--facet-size")
            meshing.facetSize = parsePositive(a, value());
        else if (a == "-o" || a == "--output")
            out = value();
        else if (a == "--result")
            resultFile = value();
        else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option '" + a + "'");
        else
            ins.push_back(a);
    }
    if (ins.empty()) throw std::invalid_argument("import needs a mesh file");
    if (tetra && ins.size() > 1) throw std::invalid_argument("--tetrahedralize meshes one surface: give one mesh file");
    if (out && !tetra) throw std::invalid_argument("-o writes a tet mesh; add --tetrahedralize");
    if (out) { // before meshing, which can take minutes
        requireWritableFile(*out, "the tet mesh");
        requireNotAnInput(*out, "the tet mesh", {ins[0]});
    }
    if (resultFile) {
        requireWritableFile(*resultFile, "the step result");
        requireNotAnInput(*resultFile, "the step result", {ins.begin(), ins.end()});
    }
    studio::ImportStepResult imported;
    opt.keepUv = !tetra; // tells whether the parts carry texture coordinates
    sim::TriMesh surface;
    for (size_t i = 0; i < ins.size(); ++i) {
        const std::string& in = ins[i];
        if (ins.size() > 1) // progress for the studio's import task; one file keeps its one-line error
            std::fprintf(stderr, "viscera-studio: stage %zu/%zu: importing %s\n", i + 1, ins.size(), in.c_str());
        bake::ImportResult r = bake::importSurfaceWithReport(in, opt);
        surface = std::move(r.mesh);
        auto [lo, hi] = surface.bounds();
        std::printf("%s: %zu vertices, %zu triangles, closed: %s, bounds [%g %g %g] - [%g %g %g] m%s\n", in.c_str(),
                    surface.vertexCount(), surface.triangleCount(), surface.isClosedOriented() ? "yes" : "no", lo.x(),
                    lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), tetra ? "" : (r.uv.empty() ? ", uv: no" : ", uv: yes"));
        const sim::Vec3 fileLo = lo / opt.scale, fileHi = hi / opt.scale; // in file units
        imported.parts.push_back({std::filesystem::absolute(in).string(),
                                  int64_t(surface.vertexCount()),
                                  int64_t(surface.triangleCount()),
                                  surface.isClosedOriented(),
                                  !r.uv.empty(),
                                  {{{fileLo.x(), fileLo.y(), fileLo.z()}, {fileHi.x(), fileHi.y(), fileHi.z()}}}});
    }
    if (resultFile) studio::writeStepResult(*resultFile, imported);
    if (!tetra) return 0;
    const auto t0 = std::chrono::steady_clock::now();
    meshing.label = std::filesystem::path(ins[0]).filename().string();
    // Progress on stderr, a line per stage: "viscera-studio: meshing: refine (10%)".
    bake::TetrahedralizeResult r = bake::tetrahedralize(surface, meshing, [](bake::MeshingStage stage, double f) {
        std::fprintf(stderr, "viscera-studio: meshing: %s (%.0f%%)\n", std::string(bake::stageName(stage)).c_str(),
                     100.0 * f);
    });
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("tetrahedralized: %zu nodes, %zu tets in %.2f s\n", r.mesh->vertexCount(), r.mesh->tetCount(), secs);
    if (r.report.missedSurfaceSeeds > 0)
        std::printf("seeded %zu surface point(s) the first refinement missed (thin parts)\n",
                    r.report.missedSurfaceSeeds);
    printQuality(r.mesh->quality());
    if (out) {
        sim::writeVtet(*out, *r.mesh);
        std::printf("wrote %s\n", out->c_str());
    }
    return 0;
}

void printColors(const char* what, const std::vector<bake::PaletteColor>& colors) {
    std::printf("  %s:", what);
    for (const bake::PaletteColor& c : colors)
        std::printf(" %s %.1f%%", bake::hexColor(c.color).c_str(), 100.0 * c.share);
    std::printf("\n");
}

int cmdTexture(const std::vector<std::string>& args) {
    const OperandArgs parsed = parseOperandArgs(args);
    const std::optional<std::string>& specFile = parsed.operand;
    const std::optional<std::string>& out = parsed.out;
    if (!specFile || !out) throw std::invalid_argument("texture needs <spec.json> and -o <dir>");
    const auto t0 = std::chrono::steady_clock::now();
    const bake::TextureSpec spec = bake::loadTextureSpec(*specFile);
    const double loadSecs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const bake::BakeTextureResult r = bake::bakeTexture(spec, *out);
    const auto& q = spec.quadtree;
    std::printf("texture %s: %dx%d, %d levels, %zu patterns, seed %llu%s\n", spec.name.c_str(), q.size, q.size,
                q.levels, q.patterns.size(), static_cast<unsigned long long>(q.seed), q.tileable ? ", tileable" : "");
    for (size_t i = 0; i < spec.layers.size(); ++i) {
        const bake::LayerSpec& l = spec.layers[i];
        const bake::GrayImage& a = r.set.layers[i].coverage;
        double mean = 0;
        for (float v : a.pixels)
            mean += v;
        std::printf("  layer %s: %d levels, %zu patterns, seed %llu, opacity %s, mean coverage %.3f, paints%s%s%s%s\n",
                    l.name.c_str(), l.quadtree.levels, l.quadtree.patterns.size(),
                    static_cast<unsigned long long>(l.quadtree.seed), sim::formatNumber(l.opacity).c_str(),
                    a.pixels.empty() ? 0.0 : mean / static_cast<double>(a.pixels.size()),
                    l.paints.diffuse ? " diffuse" : "", l.paints.roughness ? " roughness" : "",
                    l.paints.metallic ? " metallic" : "", l.paints.height ? " height" : "");
    }
    if (spec.palette && spec.palette->colors.empty()) {
        const std::string source = spec.palette->reference ? "the synthetic reference" : spec.palette->imageFile;
        printColors(("palette of " + source).c_str(), r.set.palette);
        if (!r.set.prominent.empty()) printColors("prominent colours", r.set.prominent);
    } else if (spec.palette) {
        std::printf("  palette:");
        for (const bake::Rgb8& c : r.set.colors)
            std::printf(" %s", bake::hexColor(c).c_str());
        std::printf("\n");
    }
    for (const bake::WrittenFile& f : r.files)
        std::printf("  wrote %s (%llu bytes)\n", f.path.string().c_str(), static_cast<unsigned long long>(f.bytes));
    std::printf("  time: load %.3f s, generate %.3f s, encode %.3f s, write %.3f s\n", loadSecs, r.generateSeconds,
                r.encodeSeconds, r.writeSeconds);
    return 0;
}

/// A console replay (haptics trajectory) of a suturing project's recorded needle motion, through
/// the inverse of the suture "device" mapping: the needle hand's master at (centre − start) /
/// motion_scale with the needle's turn as its orientation, the other master lifted by pull /
/// pull_scale. What `viscera-player run --device replay:<file>` plays back on the exported case.
int cmdReplay(const std::vector<std::string>& args) {
    const OperandArgs parsed = parseOperandArgs(args, {"--frames"});
    const std::optional<std::string>& dir = parsed.operand;
    const std::optional<std::string>& out = parsed.out;
    if (!dir || !out) throw std::invalid_argument("replay needs <project-dir> and -o <replay.csv>");
    long frames = 0;
    if (const auto& v = parsed.extra[0]) {
        char* end = nullptr;
        frames = std::strtol(v->c_str(), &end, 10);
        if (*end != '\0' || frames < 2 || frames > 100000)
            throw std::invalid_argument("--frames '" + *v + "' must be an integer in [2, 100000]");
    }
    requireWritableFile(*out, "the replay");
    const studio::Project project = studio::loadProject(*dir);
    requireNotAnInput(*out, "the replay", studio::projectInputFiles(project));
    const std::string origin = (std::filesystem::path(*dir) / "project.json").string();
    const auto& su = project.scene.suture;
    if (!su) throw InputError(origin + ": suture: the project has no suture section to make a replay of");
    if (!su->device.declared)
        throw InputError(origin + ": suture.device: missing; the replay follows the device mapping it declares");
    const std::vector<sim::NeedleFrame> traj = sim::parseTrajectory(su->trajectoryText, origin + ": suture.trajectory");
    const size_t n = frames > 0 ? std::min<size_t>(static_cast<size_t>(frames), traj.size()) : traj.size();
    const sim::NeedleDeviceDesc& d = su->device;
    const int needleArm = d.hand == "left" ? 0 : 1, pullArm = 1 - needleArm;
    const Eigen::Isometry3d& rest = traj.front().pose;
    haptics::Trajectory replay;
    const double dt = project.scene.xpbd.dt;
    for (size_t f = 0; f < n; ++f) {
        const sim::NeedleFrame& fr = traj[f];
        haptics::TrajectorySample s;
        s.t = double(f) * dt;
        s.pose.position = (fr.pose.translation() - rest.translation()) / d.motionScale;
        s.pose.orientation = Eigen::Quaterniond(rest.linear().transpose() * fr.pose.linear()).normalized();
        s.grip = 0.3;
        s.pedals = haptics::kPedalDeadman;
        replay.add(needleArm, s);
        haptics::TrajectorySample p;
        p.t = s.t;
        p.pose.position = sim::Vec3(0, 0, fr.pull / d.pullScale);
        p.grip = 0.3;
        p.pedals = haptics::kPedalDeadman;
        replay.add(pullArm, p);
    }
    std::string text = replay.format();
    text.insert(text.find('\n') + 1, "# " + project.caseId + ": the recorded needle trajectory, " + std::to_string(n) +
                                         " frames at " + sim::formatNumber(dt) +
                                         " s, through the case's suture.device mapping (viscera-studio replay)\n");
    writeFileAtomic(*out, text);
    std::printf("replay %s: %zu frames (%.2f s), needle on arm %d, thread pull on arm %d\n", out->c_str(), n,
                double(n) * dt, needleArm, pullArm);
    return 0;
}

int parseCount(const std::string& flag, const std::string& v, int lo, int hi) {
    char* end = nullptr;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || n < lo || n > hi)
        throw std::invalid_argument(flag + " '" + v + "' must be an integer in [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
    return int(n);
}

int cmdSample(const std::vector<std::string>& args) {
    if (args.size() != 3 || (args[0] != "kidney" && args[0] != "hepatocystic" && args[0] != "rectum") ||
        args[1] != "-o")
        throw std::invalid_argument("sample needs 'kidney -o <project-dir>', 'hepatocystic -o <folder>' or 'rectum -o "
                                    "<folder>' (the built-in samples)");
    const std::filesystem::path dir = args[2];
    if (args[0] != "kidney") {
        const studio::AnatomyFiles f =
            args[0] == "rectum" ? studio::writeRectumAnatomy(dir) : studio::writeHepatocysticAnatomy(dir);
        std::printf("wrote %zu anatomy parts%s%s into %s\n", f.parts.size(), f.atlas.empty() ? "" : " and the atlas ",
                    f.atlas.filename().c_str(), dir.c_str());
        return 0;
    }
    std::error_code ec;
    std::filesystem::create_directories(dir, ec); // a failure is reported by the check
    requireWritableFile(dir / "project.json", "the sample project");
    const studio::Project p = studio::writeKidneySample(dir);
    std::printf("wrote %s: %zu anatomy parts, texture %s\n", (dir / "project.json").c_str(),
                p.bodies.at(0).mesh.remesh.parts.size(), p.bodies.at(0).mesh.remesh.texture.filename().c_str());
    return 0;
}

/// What `viscera-studio remesh` was asked for: its input meshes, the output and the options.
struct RemeshArgs {
    struct Input {
        std::string file;
        bake::CsgOp op;
    };
    std::vector<Input> inputs;
    std::optional<std::string> out;
    bool sample = false;
    bake::ImportOptions opt;
    bake::RemeshParams params;
    std::optional<std::string> preview;
    bake::UvTransferMethod uvMethod = bake::UvTransferMethod::SeamCutting;
    std::optional<std::string> result;                     ///< --result: the typed result file
    std::optional<std::string> project, projectFile, body; ///< --body mode: a project body's block
    std::optional<std::string> setting;                    ///< the first remesh setting given (none in --body mode)
};

RemeshArgs parseRemeshArgs(const std::vector<std::string>& args) {
    RemeshArgs r;
    bake::RemeshParams& params = r.params;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
            return args[++i];
        };
        if (a != "--uv-preview" && a != "--result" && a != "--project" && a != "--project-file" && a != "--body" &&
            a != "-o" && a != "--output" && !a.empty() && a[0] == '-' && !r.setting)
            r.setting = a;
        if (a == "--no-uv")
            params.transferUv = false;
        else if (a == "--result")
            r.result = value();
        else if (a == "--project")
            r.project = value();
        else if (a == "--project-file")
            r.projectFile = value();
        else if (a == "--body")
            r.body = value();
        else if (a == "--uv-transfer")
            r.uvMethod = parseUvTransferOption(value());
        else if (a == "--uv-preview")
            r.preview = value();
        else if (a == "--sample") {
            if (value() != "kidney") throw std::invalid_argument("--sample: the built-in sample is 'kidney'");
            r.sample = true;
        } else if (a == "--subtract")
            r.inputs.push_back({value(), bake::CsgOp::Difference});
        else if (a == "--intersect")
            r.inputs.push_back({value(), bake::CsgOp::Intersection});
        else if (a == "--scale")
            r.opt.scale = parsePositive(a, value());
        else if (a == "--voxel-size")
            params.voxelSize = parsePositive(a, value());
        else if (a == "--voxels")
            params.voxelCount = parseCount(a, value(), 8, params.maxVoxelsPerAxis);
        else if (a == "--band")
            params.bandVoxels = parseCount(a, value(), 3, 16);
        else if (a == "--smooth")
            params.smoothingIterations = parseCount(a, value(), 0, 100);
        else if (a == "--edge-length")
            params.targetEdgeLength = parsePositive(a, value());
        else if (a == "--iterations")
            params.remeshIterations = parseCount(a, value(), 0, 20);
        else if (a == "--fill-openings") {
            params.fillOpenings = parsePositive(a, value());
            if (params.fillOpenings > 1) throw std::invalid_argument("--fill-openings must be in (0, 1] m");
        } else if (a == "--feature-angle") {
            params.featureAngleDeg = parsePositive(a, value());
            if (params.featureAngleDeg > 180) throw std::invalid_argument("--feature-angle must be in (0, 180]");
        } else if (a == "-o" || a == "--output")
            r.out = value();
        else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option '" + a + "'");
        else
            r.inputs.push_back({a, bake::CsgOp::Union});
    }
    if (r.body || r.project || r.projectFile) {
        if (!r.body || !r.project || !r.out)
            throw std::invalid_argument(
                "remesh --body needs --project <project-dir>, --body <name> and -o out.vremesh");
        if (!r.inputs.empty() || r.sample)
            throw std::invalid_argument("remesh --body: the parts are the body's; give no <mesh> or --sample");
        if (r.setting)
            throw std::invalid_argument("remesh --body: " + *r.setting +
                                        ": the settings are the body's remesh block (edit it in the project)");
        return r;
    }
    if ((r.inputs.empty() && !r.sample) || !r.out)
        throw std::invalid_argument("remesh needs at least one <mesh> (or --sample kidney) and -o out.obj");
    return r;
}

/// Refuses, before the work (which can take minutes), an output that cannot be written or that
/// would overwrite an input.
void checkRemeshOutputs(const RemeshArgs& a) {
    const std::string& out = *a.out;
    const char* ext = a.body ? ".vremesh" : ".obj";
    if (std::filesystem::path(out).extension() != ext)
        throw std::invalid_argument("-o '" + out + "': the result is written as " +
                                    (a.body ? "a kept remesh (.vremesh)" : "OBJ (.obj)"));
    requireWritableFile(out, "the remeshed surface");
    std::vector<std::filesystem::path> inputPaths;
    for (const auto& part : a.inputs)
        inputPaths.emplace_back(part.file);
    requireNotAnInput(out, "the remeshed surface", inputPaths);
    if (a.preview) {
        if (std::filesystem::path(*a.preview).extension() != ".png")
            throw std::invalid_argument("--uv-preview '" + *a.preview + "': the preview is written as PNG (.png)");
        requireWritableFile(*a.preview, "the UV preview");
        requireNotAnInput(*a.preview, "the UV preview", inputPaths);
    }
    if (a.result) {
        requireWritableFile(*a.result, "the step result");
        requireNotAnInput(*a.result, "the step result", inputPaths);
    }
}

/// The parts to remesh: the kidney sample's (with --sample), then every input mesh, each reported.
std::vector<bake::RemeshPart> loadRemeshParts(const RemeshArgs& a) {
    std::vector<bake::RemeshPart> parts;
    if (a.sample)
        for (bake::RemeshPart& part : bake::kidneyAnatomy()) {
            std::printf("part %s (sample, union): %zu vertices, %zu triangles, closed: %s\n", part.name.c_str(),
                        part.surface.vertexCount(), part.surface.triangleCount(),
                        part.surface.isClosedOriented() ? "yes" : "no");
            parts.push_back(std::move(part));
        }
    bake::ImportOptions opt = a.opt;
    opt.keepUv = a.params.transferUv; // the parts' UVs, transferred when every part has them
    for (const RemeshArgs::Input& in : a.inputs) {
        bake::ImportResult imported = bake::importSurfaceWithReport(in.file, opt);
        sim::TriMesh m = std::move(imported.mesh);
        std::printf("part %s (%s): %zu vertices, %zu triangles, closed: %s\n", in.file.c_str(),
                    std::string(bake::csgOpName(in.op)).c_str(), m.vertexCount(), m.triangleCount(),
                    m.isClosedOriented() ? "yes" : "no");
        parts.push_back(
            {std::filesystem::path(in.file).filename().string(), std::move(m), in.op, std::move(imported.uv)});
    }
    return parts;
}

void printRemeshReport(const bake::RemeshReport& q, double secs) {
    std::printf("grid: voxel %.4g mm, %d x %d x %d voxels, %zu active; %zu open part(s) thickened (%zu of them "
                "leaked), %zu closed over small holes, %zu filled\n",
                q.voxelSize * 1e3, q.voxels[0], q.voxels[1], q.voxels[2], q.activeVoxels, q.openParts, q.leakedParts,
                q.closedHoles, q.filledParts);
    std::printf("isosurface: %zu triangles, volume %.6g m^3\n", q.isoTriangles, q.isoVolume);
    std::printf("result: %zu vertices, %zu triangles, target edge %.4g mm, %zu hard edges\n", q.vertices, q.triangles,
                q.targetEdgeLength * 1e3, q.featureEdges);
    std::printf("checks: closed %s, manifold %s, self-intersecting pairs %zu\n", q.closed ? "yes" : "no",
                q.manifold ? "yes" : "no", q.selfIntersections);
    std::printf("distance to source: mean %.4f mm, max %.4f mm\n", q.distanceMeanMm, q.distanceMaxMm);
    std::printf("volume: result %.6g m^3, isosurface %.6g m^3 (remeshing %+.3f%%), source parts %.6g m^3 (%+.3f%%)\n",
                q.volume, q.isoVolume, 100.0 * q.volumeChangeFromIso, q.sourceVolume,
                q.sourceVolume > 0 ? 100.0 * (q.volume - q.sourceVolume) / q.sourceVolume : 0.0);
    std::printf("time: level sets %.2f s, isosurface %.2f s, remeshing %.2f s, UV cut and transfer %.2f s, checks "
                "%.2f s (total %.2f s)\n",
                q.levelSetSeconds, q.isosurfaceSeconds, q.remeshSeconds, q.uvSeconds, q.checkSeconds, secs);
}

/// The typed result of a remesh: its report's figures, each UV method's, where the files went.
studio::RemeshStepResult remeshStepResult(const RemeshArgs& a, const bake::RemeshReport& q, const UvChoice& uv,
                                          const std::string& uvMethod, double secs) {
    studio::RemeshStepResult r;
    r.surface = std::filesystem::absolute(*a.out).string();
    r.vertices = int64_t(q.vertices);
    r.triangles = int64_t(q.triangles);
    r.closed = q.closed;
    r.manifold = q.manifold;
    r.selfIntersections = int64_t(q.selfIntersections);
    r.uvMethod = q.uvTransferred ? uvMethod : "none";
    for (const auto& [method, st] : uv.stats)
        r.uv.push_back({method, int64_t(st.spanningIslands), 100.0 * st.overThreshold, st.uvErrorMean});
    r.preview = a.preview && !uv.stats.empty() ? std::filesystem::absolute(*a.preview).string() : std::string();
    r.seconds = secs;
    return r;
}

bool remeshProgress(std::string_view stage, double f) {
    std::fprintf(stderr, "viscera-studio: remesh: %.*s (%.0f%%)\n", int(stage.size()), stage.data(), 100.0 * f);
    return true;
}

/// remesh --body: the block of a project's body remeshed as export remeshes it (remesh_cache.hpp),
/// written as a kept remesh (.vremesh) that Make simulation-ready's Apply moves into the project.
int remeshProjectBody(const RemeshArgs& a) {
    const studio::Project project = a.projectFile
                                        ? studio::loadProjectText(readFile(*a.projectFile), *a.project, *a.projectFile)
                                        : studio::loadProject(*a.project);
    const std::string origin = a.projectFile.value_or((std::filesystem::path(*a.project) / "project.json").string());
    const studio::BodyProject* body = nullptr;
    for (const studio::BodyProject& b : project.bodies)
        if (b.scene.name == *a.body) body = &b;
    if (!body || body->mesh.kind != studio::MeshSource::Kind::Remesh)
        throw InputError(origin + ": bodies: no body '" + *a.body + "' made by a remesh block");
    const studio::RemeshSource& block = body->mesh.remesh;
    requireNotAnInput(*a.out, "the remeshed surface", studio::projectInputFiles(project));
    const std::string key = studio::remeshKey(block);
    studio::RemeshRun run;
    const auto t0 = std::chrono::steady_clock::now();
    const studio::RemeshedSurface surface = studio::remeshSurface(block, &run, remeshProgress);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    printRemeshReport(run.result.report, secs);
    UvChoice uv;
    if (run.result.report.uvTransferred)
        uv = reportUvTransfers(run.parts, run.result, bake::UvTransferMethod::SeamCutting, a.preview);
    studio::writeRemeshedSurface(*a.out, surface);
    std::printf("wrote %s (key %s)\n", a.out->c_str(), key.c_str());
    if (a.result) {
        const std::string method = block.uvTransfer ? std::string(uvTransferOptionName(*block.uvTransfer)) : "none";
        studio::RemeshStepResult r = remeshStepResult(a, run.result.report, uv, method, secs);
        r.uvMethod = method; // the block's, also where only the seam cut measures (closest, island)
        r.cacheKey = key;
        studio::writeStepResult(*a.result, r);
    }
    return 0;
}

int cmdRemesh(const std::vector<std::string>& args) {
    const RemeshArgs a = parseRemeshArgs(args);
    checkRemeshOutputs(a);
    if (a.body) return remeshProjectBody(a);
    const std::string& out = *a.out;
    const std::vector<bake::RemeshPart> parts = loadRemeshParts(a);
    const auto t0 = std::chrono::steady_clock::now();
    const bake::RemeshResult r = bake::voxelRemesh(parts, a.params, remeshProgress);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const bake::RemeshReport& q = r.report;
    if (!q.uvTransferred) bake::writeObj(out, r.mesh);
    printRemeshReport(q, secs);
    UvChoice choice;
    if (!q.uvTransferred) {
        if (a.params.transferUv) std::printf("uv: not transferred (a part has no UVs)\n");
    } else {
        choice = reportUvTransfers(parts, r, a.uvMethod, a.preview);
        bake::writeObjWithUv(out, *choice.mesh, choice.uv);
        std::printf("uv.written %s\n", std::string(uvTransferOptionName(a.uvMethod)).c_str());
    }
    std::printf("wrote %s\n", out.c_str());
    if (a.result)
        studio::writeStepResult(*a.result,
                                remeshStepResult(a, q, choice, std::string(uvTransferOptionName(a.uvMethod)), secs));
    return 0;
}

int g_argc = 0;
char** g_argv = nullptr;

int cmdOpen(const std::vector<std::string>& args) {
    if (args.size() != 1) throw std::invalid_argument("open needs one <project-dir>");
    return studio::runStudio(g_argc, g_argv, QString::fromStdString(args[0]));
}

} // namespace

int main(int argc, char** argv) {
    g_argc = argc;
    g_argv = argv;
    sim::CliProgram program;
    program.name = "viscera-studio";
    program.version = VISCERA_VERSION;
    program.usage = usage;
    program.subcommands = {
        {"export", cmdExport, kExportHelp}, {"import", cmdImport, kImportHelp},    {"open", cmdOpen, kOpenHelp},
        {"remesh", cmdRemesh, kRemeshHelp}, {"texture", cmdTexture, kTextureHelp}, {"replay", cmdReplay, kReplayHelp},
        {"keygen", cmdKeygen, kKeygenHelp}, {"sample", cmdSample, kSampleHelp},    {"mesh", cmdMesh, kMeshHelp}};
    program.noArguments = [] { return studio::runStudio(g_argc, g_argv, {}); };
    return sim::runCli(program, argc, argv);
}
