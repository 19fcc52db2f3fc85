#include "project/step_result.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

namespace viscera::studio {
namespace {

using nlohmann::json;
using sim::JsonField;
using sim::NumberRule;

/// A count: a non-negative JSON integer.
int64_t count(const JsonField& f) {
    const json& v = f.value();
    if (!v.is_number_integer() || (v.is_number_integer() && !v.is_number_unsigned() && v.get<int64_t>() < 0))
        f.fail("must be a non-negative integer");
    return v.get<int64_t>();
}

/// An absolute path, or (with `mayBeEmpty`) "".
std::string absolutePath(const JsonField& f, bool mayBeEmpty) {
    const std::string s = f.string();
    if (s.empty() && mayBeEmpty) return s;
    if (!std::filesystem::path(s).is_absolute()) f.fail("must be an absolute path");
    return s;
}

json bodyJson(const BodyFigures& b) {
    return {{"name", b.name},
            {"nodes", b.nodes},
            {"tets", b.tets},
            {"fixed_nodes", b.fixedNodes},
            {"min_dihedral_deg", b.minDihedralDeg},
            {"max_dihedral_deg", b.maxDihedralDeg},
            {"min_mean_ratio", b.minMeanRatio},
            {"mean_mean_ratio", b.meanMeanRatio},
            {"inverted", b.inverted},
            {"degenerate", b.degenerate},
            {"slivers", b.slivers},
            {"volume", b.volume}};
}

BodyFigures readBody(const JsonField& f) {
    f.object({"name", "nodes", "tets", "fixed_nodes", "min_dihedral_deg", "max_dihedral_deg", "min_mean_ratio",
              "mean_mean_ratio", "inverted", "degenerate", "slivers", "volume"});
    BodyFigures b;
    b.name = f["name"].nonEmptyString();
    b.nodes = count(f["nodes"]);
    b.tets = count(f["tets"]);
    b.fixedNodes = count(f["fixed_nodes"]);
    b.minDihedralDeg = f["min_dihedral_deg"].number(NumberRule::closed(0, 180));
    b.maxDihedralDeg = f["max_dihedral_deg"].number(NumberRule::closed(0, 180));
    b.minMeanRatio = f["min_mean_ratio"].number(NumberRule::any());
    b.meanMeanRatio = f["mean_mean_ratio"].number(NumberRule::any());
    b.inverted = count(f["inverted"]);
    b.degenerate = count(f["degenerate"]);
    b.slivers = count(f["slivers"]);
    b.volume = f["volume"].number(NumberRule::any());
    return b;
}

json toJson(const ImportStepResult& r) {
    json parts = json::array();
    for (const ImportedPartResult& p : r.parts)
        parts.push_back({{"file", p.file},
                         {"vertices", p.vertices},
                         {"triangles", p.triangles},
                         {"closed", p.closed},
                         {"uv", p.hasUv},
                         {"bounds", {p.bounds[0], p.bounds[1]}}});
    return {{"parts", parts}};
}

ImportStepResult readImport(const JsonField& f) {
    f.object({"kind", "parts"});
    ImportStepResult r;
    for (const JsonField& p : f["parts"].items(1)) {
        p.object({"file", "vertices", "triangles", "closed", "uv", "bounds"});
        ImportedPartResult part;
        part.file = absolutePath(p["file"], false);
        part.vertices = count(p["vertices"]);
        part.triangles = count(p["triangles"]);
        part.closed = p["closed"].boolean();
        part.hasUv = p["uv"].boolean();
        const std::vector<JsonField> box = p["bounds"].items(2, 2);
        for (int k = 0; k < 2; ++k) {
            const sim::Vec3 v = box[size_t(k)].vec3();
            part.bounds[size_t(k)] = {v.x(), v.y(), v.z()};
        }
        for (int k = 0; k < 3; ++k)
            if (part.bounds[0][size_t(k)] > part.bounds[1][size_t(k)])
                p["bounds"].fail("the minimum must not exceed the maximum");
        r.parts.push_back(std::move(part));
    }
    return r;
}

json toJson(const RemeshStepResult& r) {
    json uv = json::array();
    for (const UvTransferFigures& u : r.uv)
        uv.push_back({{"method", u.method},
                      {"over_two_islands", u.overTwoIslands},
                      {"over_threshold_pct", u.overThresholdPct},
                      {"uv_error_mean", u.uvErrorMean}});
    return {{"surface", r.surface},
            {"cache_key", r.cacheKey},
            {"vertices", r.vertices},
            {"triangles", r.triangles},
            {"closed", r.closed},
            {"manifold", r.manifold},
            {"self_intersections", r.selfIntersections},
            {"uv_method", r.uvMethod},
            {"uv", uv},
            {"preview", r.preview},
            {"seconds", r.seconds}};
}

RemeshStepResult readRemesh(const JsonField& f) {
    f.object({"kind", "surface", "cache_key", "vertices", "triangles", "closed", "manifold", "self_intersections",
              "uv_method", "uv", "preview", "seconds"});
    RemeshStepResult r;
    r.surface = absolutePath(f["surface"], false);
    r.cacheKey = f["cache_key"].string();
    if (!r.cacheKey.empty() &&
        (r.cacheKey.size() != 64 || r.cacheKey.find_first_not_of("0123456789abcdef") != std::string::npos))
        f["cache_key"].fail("must be empty or 64 lowercase hex characters (a sha256)");
    r.vertices = count(f["vertices"]);
    r.triangles = count(f["triangles"]);
    r.closed = f["closed"].boolean();
    r.manifold = f["manifold"].boolean();
    r.selfIntersections = count(f["self_intersections"]);
    r.uvMethod = f["uv_method"].choice({"seam-cut", "closest", "island", "none"});
    for (const JsonField& u : f["uv"].items(0, 3)) {
        u.object({"method", "over_two_islands", "over_threshold_pct", "uv_error_mean"});
        UvTransferFigures m;
        m.method = u["method"].choice({"seam-cut", "closest", "island"});
        m.overTwoIslands = count(u["over_two_islands"]);
        m.overThresholdPct = u["over_threshold_pct"].number(NumberRule::closed(0, 100));
        m.uvErrorMean = u["uv_error_mean"].number(NumberRule::nonNegative());
        r.uv.push_back(std::move(m));
    }
    r.preview = absolutePath(f["preview"], true);
    r.seconds = f["seconds"].number(NumberRule::nonNegative());
    return r;
}

json toJson(const MeshingStepResult& r) {
    return {{"body", bodyJson(r.body)},
            {"substeps", r.substeps},
            {"required_substeps", r.requiredSubsteps},
            {"stiffness_number", r.stiffnessNumber},
            {"remesh_reused", r.remeshReused},
            {"seconds", r.seconds},
            {"seeded_surface_points", r.seededPoints}};
}

MeshingStepResult readMeshing(const JsonField& f) {
    f.object({"kind", "body", "substeps", "required_substeps", "stiffness_number", "remesh_reused", "seconds",
              "seeded_surface_points"});
    MeshingStepResult r;
    r.body = readBody(f["body"]);
    r.substeps = f["substeps"].integer(1, INT32_MAX);
    r.requiredSubsteps = f["required_substeps"].integer(1, INT32_MAX);
    r.stiffnessNumber = f["stiffness_number"].number(NumberRule::nonNegative());
    r.remeshReused = f["remesh_reused"].boolean();
    r.seconds = f["seconds"].number(NumberRule::nonNegative());
    r.seededPoints = count(f["seeded_surface_points"]);
    return r;
}

json toJson(const ExportStepResult& r) {
    json bodies = json::array();
    for (const BodyFigures& b : r.bodies)
        bodies.push_back(bodyJson(b));
    return {{"case", r.casePath},   {"bytes", r.bytes},       {"sha256", r.sha256}, {"key_id", r.keyId},
            {"signer", r.signer},   {"features", r.features}, {"bodies", bodies},   {"remeshes", r.remeshes},
            {"seconds", r.seconds}, {"warnings", r.warnings}};
}

ExportStepResult readExport(const JsonField& f) {
    f.object({"kind", "case", "bytes", "sha256", "key_id", "signer", "features", "bodies", "remeshes", "seconds",
              "warnings"});
    ExportStepResult r;
    r.casePath = absolutePath(f["case"], false);
    r.bytes = count(f["bytes"]);
    r.sha256 = f["sha256"].string();
    if (r.sha256.size() != 64 || r.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
        f["sha256"].fail("must be 64 lowercase hex characters");
    r.keyId = f["key_id"].string();
    r.signer = f["signer"].string();
    if (r.keyId.empty() != r.signer.empty())
        f["signer"].fail("must be given exactly when key_id is (a signed case names both)");
    for (const JsonField& s : f["features"].items())
        r.features.push_back(s.nonEmptyString());
    for (const JsonField& b : f["bodies"].items())
        r.bodies.push_back(readBody(b));
    r.remeshes = count(f["remeshes"]);
    r.seconds = f["seconds"].number(NumberRule::nonNegative());
    for (const JsonField& w : f["warnings"].items())
        r.warnings.push_back(w.nonEmptyString());
    return r;
}

} // namespace

const char* stepKindName(const StepResult& r) {
    static constexpr const char* kNames[] = {"import", "remesh", "meshing", "export"};
    return kNames[r.index()];
}

std::string stepResultJson(const StepResult& r) {
    json j = std::visit([](const auto& v) { return toJson(v); }, r);
    j["kind"] = stepKindName(r);
    return j.dump(2) + "\n";
}

StepResult parseStepResult(const std::string& text, const std::string& origin) {
    const json doc = sim::parseJsonText(text, origin);
    const JsonField root(doc, "", origin);
    const std::string kind = root.anyObject()["kind"].choice({"import", "remesh", "meshing", "export"});
    if (kind == "import") return readImport(root);
    if (kind == "remesh") return readRemesh(root);
    if (kind == "meshing") return readMeshing(root);
    return readExport(root);
}

void writeStepResult(const std::filesystem::path& file, const StepResult& r) {
    writeFileAtomic(file, stepResultJson(r));
}

template <class T> T readStepResult(const std::filesystem::path& file) {
    const std::string origin = file.string();
    StepResult r = parseStepResult(readFile(file, std::uintmax_t{16} << 20), origin);
    if (T* v = std::get_if<T>(&r)) return std::move(*v);
    const char* want = stepKindName(StepResult(T{}));
    throw InputError(origin + ": kind: must be '" + want + "' (it is '" + stepKindName(r) + "')");
}

template ImportStepResult readStepResult<ImportStepResult>(const std::filesystem::path&);
template RemeshStepResult readStepResult<RemeshStepResult>(const std::filesystem::path&);
template MeshingStepResult readStepResult<MeshingStepResult>(const std::filesystem::path&);
template ExportStepResult readStepResult<ExportStepResult>(const std::filesystem::path&);

} // namespace viscera::studio
