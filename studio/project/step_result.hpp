#pragma once
/// What a long studio step hands back across the process boundary [issue 57 item 6]: the child
/// `viscera-studio <command> ... --result FILE` writes one small JSON file (atomically) and the
/// studio reads it back with the strict field reader; nothing is read back from the child's text
/// output (that carries only the progress lines and, on failure, the one error line).
///
///   {"kind": "import",  "parts": [{"file": "/p/anatomy/cortex.obj", "vertices": 812, "triangles": 1620,
///                                   "closed": false, "uv": true, "bounds": [[x,y,z], [x,y,z]]}, ...]}
///   {"kind": "remesh",  "surface": "/p/.viscera-task-x/remesh.vremesh", "cache_key": "<64 hex>" | "",
///                       "vertices": 5120, "triangles": 10236, "closed": true, "manifold": true,
///                       "self_intersections": 0, "uv_method": "seam-cut" | "none",
///                       "uv": [{"method": "closest", "over_two_islands": 12, "over_threshold_pct": 1.5,
///                               "uv_error_mean": 0.002}, ...],
///                       "preview": "/p/.viscera-task-x/preview.png" | "", "seconds": 2.5}
///   {"kind": "meshing", "body": {..a body's figures..}, "substeps": 10, "required_substeps": 12,
///                       "stiffness_number": 1.4, "remesh_reused": true, "seconds": 3.1}
///   {"kind": "export",  "case": "/out/case.vcase", "bytes": 123456, "sha256": "<64 hex>",
///                       "key_id": "ed25519:…" | "", "signer": "publisher" | "", "features": ["xpbd", ..],
///                       "bodies": [{..a body's figures..}], "remeshes": 0, "seconds": 12.0}
/// A body's figures: {"name", "nodes", "tets", "fixed_nodes", "min_dihedral_deg", "max_dihedral_deg",
///                    "min_mean_ratio", "mean_mean_ratio", "inverted", "degenerate", "slivers", "volume"}
/// (counts; degrees; m^3). Paths are absolute. Every field is required; unknown fields are refused.
/// Errors: "<file>: <field>: <rule>" ("r.json: body.tets: must be an integer in [0, 2147483647]").
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

namespace viscera::studio {

struct ImportedPartResult {
    std::string file;
    int64_t vertices = 0, triangles = 0;
    bool closed = false, hasUv = false;
    std::array<std::array<double, 3>, 2> bounds{}; ///< file units (scale 1): {min, max}
    bool operator==(const ImportedPartResult&) const = default;
};
struct ImportStepResult {
    std::vector<ImportedPartResult> parts;
    bool operator==(const ImportStepResult&) const = default;
};

/// One UV transfer method measured on the remeshed surface.
struct UvTransferFigures {
    std::string method; ///< "closest", "island", "seam-cut"
    int64_t overTwoIslands = 0;
    double overThresholdPct = 0; ///< share of faces stretched over the threshold, %
    double uvErrorMean = 0;
    bool operator==(const UvTransferFigures&) const = default;
};
struct RemeshStepResult {
    std::string surface;  ///< the remeshed surface (RemeshedSurface file), kept by Apply
    std::string cacheKey; ///< remeshKey of the block it was made from (empty: files, not a block)
    int64_t vertices = 0, triangles = 0, selfIntersections = 0;
    bool closed = false, manifold = false;
    std::string uvMethod; ///< "seam-cut", "closest", "island" or "none"
    std::vector<UvTransferFigures> uv;
    std::string preview; ///< the checker preview PNG, or empty
    double seconds = 0;
    bool operator==(const RemeshStepResult&) const = default;
};

/// A meshed body's figures (project.hpp BodyExport, flattened).
struct BodyFigures {
    std::string name;
    int64_t nodes = 0, tets = 0, fixedNodes = 0;
    double minDihedralDeg = 0, maxDihedralDeg = 0, minMeanRatio = 0, meanMeanRatio = 0;
    int64_t inverted = 0, degenerate = 0, slivers = 0;
    double volume = 0; ///< m^3
    bool operator==(const BodyFigures&) const = default;
};
struct MeshingStepResult {
    BodyFigures body;
    int substeps = 1;           ///< the project's substeps per frame
    int requiredSubsteps = 1;   ///< the stability check's smallest count (> substeps: unstable)
    double stiffnessNumber = 0; ///< the largest over the tets (limit sim::kMaxStiffnessNumber)
    bool remeshReused = false;  ///< the body's kept remesh was read instead of remeshing
    double seconds = 0;
    /// Surface points seeded after the first refinement on thin parts it missed
    /// (bake::MeshingReport::missedSurfaceSeeds); 0: it covered the whole surface.
    int64_t seededPoints = 0;
    bool operator==(const MeshingStepResult&) const = default;
};
struct ExportStepResult {
    std::string casePath;
    int64_t bytes = 0;
    std::string sha256, keyId, signer; ///< keyId and signer empty: unsigned
    std::vector<std::string> features;
    std::vector<BodyFigures> bodies;
    int64_t remeshes = 0; ///< remeshes the export ran (a body's kept remesh reused counts none)
    double seconds = 0;
    std::vector<std::string> warnings; ///< ExportResult::warnings (targets a port cannot reach), one line each
    bool operator==(const ExportStepResult&) const = default;
};

using StepResult = std::variant<ImportStepResult, RemeshStepResult, MeshingStepResult, ExportStepResult>;

/// "import", "remesh", "meshing", "export": the "kind" of each alternative.
const char* stepKindName(const StepResult& r);

/// The JSON text (2-space indent, keys sorted, final newline).
std::string stepResultJson(const StepResult& r);
/// The reader: throws viscera::InputError "<origin>: <field>: <rule>" on invalid JSON, a missing,
/// unknown or ill-typed field, a count out of range or a number not finite.
StepResult parseStepResult(const std::string& text, const std::string& origin);

/// Writes stepResultJson atomically (sim/util/atomic_file.hpp).
void writeStepResult(const std::filesystem::path& file, const StepResult& r);
/// Reads `file` (at most 16 MiB) and requires the alternative T: "<file>: kind: must be 'remesh'
/// (it is 'export')" otherwise.
template <class T> T readStepResult(const std::filesystem::path& file);

} // namespace viscera::studio
