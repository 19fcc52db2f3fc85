#pragma once
/// A studio project: projects/<name>/project.json plus its source meshes. The studio exports it
/// to a .vcase case package (exportCase). Parsing is strict; every error names the file, the
/// field and the rule ("project.json: bodies[0].fixed.min: must be an array of 3 numbers").
///
/// {
///   "schemaVersion": 1,
///   "caseId": "tissue-slab", "caseVersion": "1.0.0", "title": "…", "instructions": "…",
///   "steps": ["…", …],                      optional: the task's ordered steps (core/sim/scene/scene.hpp)
///   "solver": {"type": "xpbd", "dt": 0.0166667, "substeps": 10, "iterations": 1, "damping": 1.0},
///   "gravity": [0, 0, -9.81],
///   "bodies": [{
///     "name": "slab",
///     "mesh": {"generator": "box", "origin": [0,0,0], "size": [0.1,0.02,0.04], "cells": [20,4,8]}
///          | {"generator": "ellipsoid", "center": [..], "radii": [..], "slices": 48, "stacks": 24,
///             "meshing": {..}}
///          | {"generator": "liver", "center": [..], "half_size": [..], "wedge": 0.5, "meshing": {..}}
///          | {"generator": "tube", "start": [..], "end": [..], "radius": 0.004, "meshing": {..}}
///          | {"generator": "hollow_tube", "start": [..], "end": [..], "inner_radius": 0.0038,
///             "outer_radius": 0.005, "slices": 33, "layers": 2, "rings": 8}   (structured, no CGAL)
///          | {"file": "liver.obj", "scale": 0.001, "meshing": {..}}
///          | {"file": "liver.msh", "scale": 0.01}   a tet mesh (.msh, .vtu, .vtet; sim::readTetFile) as it is
///          | {"remesh": {..see RemeshSource..}, "meshing": {..}},
///     "material": {see readMaterial in core/sim/scene/scene_json.hpp},
///     "fixed": {"min": [..], "max": [..]},     nodes inside this box (metres) are fixed; or a list of
///              [{"min": .., "max": ..}, ..]     such boxes (at most kMaxHoldBoxes), nodes in any one fixed
///     "stiffness_regions": [{"min": [..], "max": [..], "weight": 4}],
///     "stiffness_paint": {"skeleton": {"min_edge_length_rel": 0.002, "medially_centered": true},
///                         "base_weight": 1, "min_weight": 0.001, "max_weight": 1e6,
///                         "strokes": [{"center": [..], "radius": 0.02, "amplitude": 4,
///                                      "scale": "peak" | "kernel",
///                                      "mode": "add" | "subtract" | "mix" | "smooth",
///                                      "target": 3 (mix only)}]},   weights × region weights
///     "light_samples": [{"tool": "brush", "samples": 8, "radius": 0.01, "points": [[..], ..]},
///                       {"tool": "fill", "samples": 4, "seed": [..], "max_angle_deg": 30}],
///                       painted light samples, replayed in order on the body's surface at rest;
///                       exported as maps/<body>.vsamples when "render" asks for painted sampling
///     "embedded_in": "organ", "embedding_compliance": 0
///   }],
///   "surfaces": [{"name": "fascia", "from_boundary_of": "organ", "region": {"min": .., "max": ..},
///                 "areal_density": 0.1, "stretch_stiffness": 50, "attach_distance": 0.001,
///                 "stiffness_paint": {"base_weight": 1, ..., "strokes": [..]}}],   optional: polygon
///                 paint on the fascia's vertices (no skeleton), exported as meshes/<surface>.vweights
///   "accuracy": {"every_frames": 60, "max_iterations": 100},
///   "suture": {...the scene's suture section (core/sim/suture/suture_scene.hpp), with
///              "trajectory": {"generator": "anastomosis", "stitches": 5, ...AnastomosisSpec fields}
///                          | {"file": "needle.traj"}}     with "solver": {"type": "fem", "dt": ..}
///   "interaction": {...the scene's interaction section (core/sim/scene/interaction.hpp), with
///                   every instrument's "track" a file of the project folder},
///   "laparoscope": {...the scene's (core/sim/scene/laparoscope.hpp)},
///   "bend": {...}, "scenery": [...]          anatomy made by code (project/anatomy_shapes.hpp)
/// }
/// The suture trajectory is generated (or read and checked) at load and exported as
/// tools/needle.traj; instrument tracks are checked at load and exported as tools/<name>.track.
/// Every file reference ("file" of a mesh or trajectory, "track") is a path relative to the
/// project folder: no '..', not absolute (sim/util/entry_name.hpp).
/// "meshing" (CGAL Mesh_3, metres and degrees): facet_angle, facet_size, facet_distance,
/// cell_radius_edge_ratio, cell_size, seed, max_tets (the cap on the tets the sizes may ask
/// for, refused before meshing; [1000, 2000000]).
#include "bake/import.hpp"
#include "bake/remesh.hpp"
#include "bake/skeleton.hpp"
#include "bake/tetrahedralize.hpp"
#include "bake/texture.hpp"
#include "bake/uv_transfer.hpp"
#include "case/signing.hpp"
#include "project/anatomy_shapes.hpp"
#include "render/case_settings.hpp"
#include "render/corner_uv.hpp"
#include "render/sample_map.hpp"
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/scene/interaction.hpp"
#include "sim/scene/scene.hpp"
#include "sim/skeleton/stiffness_paint.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {
class World;
}

namespace viscera::studio {

/// Render anatomy made simulation-ready [issue 38 item 2]: overlapping, open parts with UVs,
/// combined and remeshed on a voxel grid (bake::voxelRemesh), their UVs transferred onto the
/// result, which is then tetrahedralized with the mesh's "meshing".
///   "mesh": {"remesh": {"parts": [{"file": "anatomy/cortex.obj", "op": "union"}, ...],
///                       "unit": "m" | "cm" | "mm" | "inch", "scale": 1, "rotation_deg": [90, 0, 0],
///                       "voxel_size": 0.001 | "voxel_count": 128, "smoothing": 0,
///                       "edge_length": 0.0015, "iterations": 3,
///                       "uv_transfer": "seam-cut" | "closest" | "island" | "none",
///                       "texture": "anatomy/kidney.png"},
///            "meshing": {..}}
/// The texture (a PNG of the project) is the parts' diffuse map: export lays it on the body by
/// the transferred UVs (render.materials.<body>: diffuse + uv). A body's texture block, when it
/// has one, is laid by them instead.
/// The parts' placement (bake::ImportPlacement): "unit" the files' length unit (default "m"),
/// "scale" a uniform factor on top of it (> 0, default 1), "rotation_deg" Euler angles about x,
/// then y, then z (each in [-360, 360], default none); a part's file coordinate c becomes
/// R · (metres per unit · scale · c) metres.
/// The remeshed surface is not part of the model: it is a function of the block and its part
/// files. Make simulation-ready's Apply keeps the one it made in <project>/cache, named by the
/// hash of the block and the parts' bytes (remesh_cache.hpp), and export and Tetrahedralize read
/// it instead of remeshing again; an edit of the block or of a part file changes the name, so
/// they remesh then.
struct RemeshSource {
    struct Part {
        std::filesystem::path file; ///< resolved against the project folder
        bake::CsgOp op = bake::CsgOp::Union;
        bool operator==(const Part&) const = default;
    };
    std::vector<Part> parts;
    bake::ImportPlacement placement; ///< file units → metres, then the rotation
    bake::RemeshParams params;       ///< voxel size or count, smoothing, edge length, iterations
    std::optional<bake::UvTransferMethod> uvTransfer = bake::UvTransferMethod::SeamCutting; ///< none: no UVs
    std::filesystem::path texture;                                                          ///< empty: none
};

/// The rule readRemesh applies to the placement fields, on a value: empty when `placement` is
/// admitted, else "<field>.<key>: <rule>" with `field` the block's JSON path
/// ("bodies[1].mesh.remesh.rotation_deg[0]: must be in [-360, 360]").
std::string placementProblem(const bake::ImportPlacement& placement, const std::string& field);

struct MeshSource {
    enum class Kind { Box, Ellipsoid, Liver, Tube, HollowTube, File, Remesh };
    Kind kind = Kind::Box;
    sim::HollowTubeSpec hollow; ///< Kind::HollowTube
    sim::BoxSpec box;
    sim::Vec3 center = sim::Vec3::Zero(), radii = sim::Vec3::Constant(0.05); ///< tube: center = start
    sim::Vec3 end = sim::Vec3::Zero();                                       ///< tube end
    double radius = 0.005;                                                   ///< tube radius, m
    double wedge = 0.5;                                                      ///< liver thickness ratio
    int slices = 48, stacks = 24;
    std::filesystem::path file; ///< Kind::File: resolved against the project folder (dir / "file")
    double scale = 1.0;
    bake::MeshingParams meshing;
    RemeshSource remesh; ///< Kind::Remesh
};

/// Nodes inside an axis-aligned box get a stiffness weight (the skeleton brush comes later).
struct StiffnessRegion {
    sim::Vec3 min, max; ///< metres
    double weight = 1;  ///< > 0; multiplies the material's stiffness
};

/// Skeleton stiffness painting [A §4.3.5]: the body's curve skeleton (mean curvature flow) maps
/// every node to skeleton nodes; poly6 brush strokes on the skeleton set per-node weights. On a
/// fascia surface the same strokes select its vertices directly (polygon paint, Fig. 4.11) and
/// `skeleton` is not used.
struct StiffnessPaintProject {
    bake::SkeletonParams skeleton;
    sim::PaintParams params;
    std::vector<sim::BrushStroke> strokes;
};

/// Generated material maps of a body or surface [A §6.2, issue 17]: a texture spec
/// (bake::parseTextureSpec, `viscera-studio texture`) and how the renderer lays the maps on the
/// mesh. The spec is either a file of the project or kept in project.json itself ("generator",
/// the same JSON object, its files named relative to the project folder): the studio's
/// generator editor keeps the spec it edits in the model, so that every change is one undo step.
/// Export packages the diffuse, roughness, metallic and normal maps the spec writes as
/// textures/<name>_<map>.png and names them in the scene's render.materials; nothing else.
///   "texture": {"spec": "textures/liver.json", "tiles_per_metre": 20, "normal_strength": 1}
///   "texture": {"generator": {"size": 512, "seed": 3, ...}, "tiles_per_metre": 20}
struct TextureProject {
    std::string spec;      ///< a spec file relative to the project folder; empty when `generator` holds it
    std::string generator; ///< the spec as compact JSON text (files relative to the project folder), or empty
    float tilesPerMetre = 20.0f;
    float normalStrength = 1.0f;

    bool operator==(const TextureProject&) const = default;
};

/// The JSON text of a texture block's spec: the generator, or the spec file's contents (at most
/// 1 MiB). Throws viscera::InputError naming the file when it cannot be read.
std::string textureSpecText(const TextureProject& t, const std::filesystem::path& projectDir);
/// The block's spec, read by bake::parseTextureSpec: a file spec's files resolve against its
/// folder, a generator's against the project folder; `origin` names a generator in messages.
/// Throws viscera::InputError "<origin or file>: <JSON path>: <rule>".
bake::TextureSpec loadTextureBlock(const TextureProject& t, const std::filesystem::path& projectDir,
                                   const std::string& origin);
/// The block with its spec kept in project.json: a file spec's JSON, its file references (image
/// tiles, palette images, also of layers) rebased from the spec's folder onto the project
/// folder; a generator block as it is. Throws viscera::InputError when the file cannot be read
/// or is not JSON.
TextureProject embedTextureSpec(const TextureProject& t, const std::filesystem::path& projectDir);

/// A tet body: its scene description (what the case's scene.json carries: name, material,
/// strain limits, embedding; read by the same code as the player's scene) plus what only
/// authoring needs. meshPath, fixedNodes and nodeWeights of `scene` are filled at export.
/// The range of a light-sample brush radius in project.json, m (the reader's rule and the studio's
/// typed edits: NumberRule::closed of these).
inline constexpr double kMinSampleBrushRadius = 1e-4, kMaxSampleBrushRadius = 10.0;
/// The most boxes a body's "fixed" may list.
inline constexpr size_t kMaxHoldBoxes = 64;

struct BodyProject {
    sim::BodyDesc scene;
    MeshSource mesh;
    /// {min, max} boxes, metres: the nodes inside any one are held in place ("fixed"; each box must
    /// hold a node of the mesh). Empty: nothing held.
    std::vector<std::array<sim::Vec3, 2>> fixedBoxes;
    std::vector<StiffnessRegion> stiffnessRegions;
    std::optional<StiffnessPaintProject> paint; ///< exported as meshes/<body>.vweights
    /// Light-sample painting [A §6.3.2], by position; exported as maps/<body>.vsamples only when
    /// the scene renders with painted sampling (usesPaintedSampling).
    std::vector<render::SamplePaintOp> lightSamples;
    std::optional<TextureProject> texture;
};

/// A fascia layer cut from the boundary of a tet body (scene.attachTo, "from_boundary_of" in
/// project.json): the boundary triangles whose centroid lies in `region` (all when absent), with
/// their own particles, attached back to the body. meshPath of `scene` is filled at export.
struct SurfaceProject {
    sim::SurfaceDesc scene;
    std::optional<std::array<sim::Vec3, 2>> region;
    /// Polygon stiffness paint on the layer's vertices at rest (sim::bakeSurfacePaint); exported as
    /// meshes/<surface>.vweights. By position, so it survives the body being meshed again.
    std::optional<StiffnessPaintProject> paint;
    std::optional<TextureProject> texture;
    /// Rounds of midpoint subdivision of the cut layer ("subdivide", 0..3): a fascia finer than the
    /// body's boundary (each round halves its edges), so the energy hook opens it along its path
    /// however coarse the tets under it are.
    int subdivide = 0;
};

/// Where the suture's needle trajectory comes from ("suture.trajectory" of project.json): the
/// anastomosis generator with its spec, or else a trajectory file of the project.
struct TrajectorySource {
    /// {"generator": "anastomosis", ...}: the trajectory fields of the spec (stitches, needle_radius,
    /// needle_centre, degrees_per_frame, transfer_frames, transfer_distance, pull_frames,
    /// pull_per_segment, slack); the tube fields of AnastomosisSpec are not part of project.json.
    std::optional<sim::AnastomosisSpec> generator;
    std::filesystem::path file; ///< {"file": ...} when no generator: resolved against the project folder
};

/// The project model the studio edits and exports: the scene description the player reads
/// (`scene`: solver, gravity, accuracy, render, instructions, suture with its trajectory text,
/// interaction with its track texts; its bodies and surfaces live in `bodies` / `surfaces` with
/// their authoring settings) plus the case header and where the project's files come from.
///
/// Files of the project are held resolved against `dir` (dir / <path in project.json>):
/// MeshSource::file, TrajectorySource::file and trackFiles. projectJsonText writes them back
/// relative to `dir`, so a path must lie inside `dir`. The texts derived from files and
/// generators (scene.suture->trajectoryText, the instruments' trackText) are filled at load and
/// are what exportCase packages, under the case paths of `scene` (tools/needle.traj,
/// tools/<instrument>.track); loadProjectText(projectJsonText(p), ...) refreshes them after an
/// edit of their source.
struct Project {
    std::filesystem::path dir;
    int schemaVersion = 1;
    std::string caseId, caseVersion, title;
    sim::SceneDesc scene; ///< bodies and surfaces empty: see below
    std::vector<BodyProject> bodies;
    std::vector<SurfaceProject> surfaces;
    TrajectorySource trajectory; ///< when scene.suture is set
    /// The "track" file of every instrument of scene.interaction, in the same order (one each).
    std::vector<std::filesystem::path> trackFiles;
    /// Anatomy made by code (anatomy_shapes.hpp): the bend of the bodies and surfaces, and the
    /// render-only scenery surfaces.
    std::optional<BendSpec> bend;
    std::vector<SceneryProject> scenery;
    std::vector<std::optional<TextureProject>> sceneryTextures; ///< scenery[k]'s "texture", one each
};

/// Reads <dir>/project.json: loadProjectText of the file's text. Throws viscera::InputError.
Project loadProject(const std::filesystem::path& dir);

/// Every file of the project folder an export of `project` reads: <dir>/project.json, the
/// bodies' mesh files, the trajectory file, the tracks and the texture spec files (an output
/// must be none of them).
std::vector<std::filesystem::path> projectInputFiles(const Project& project);

/// The project reader on text: `text` is a project.json whose file references resolve against
/// `dir` (the files are read and checked now); `origin` names the text in every message
/// ("<origin>: bodies[0].fixed.min: must be an array of 3 numbers"). Throws viscera::InputError.
Project loadProjectText(const std::string& text, const std::filesystem::path& dir, const std::string& origin);

/// The project.json text of `project`: a JSON object with a 2-space indent, keys sorted (the
/// same model gives the same bytes), a final newline. Defaults that the file left out are
/// written explicitly; loadProjectText of the text gives an equal model. File references are
/// written relative to project.dir. Throws viscera::InputError when a file lies outside
/// project.dir ("<dir>/project.json: bodies[0].mesh.file: '/x/liver.obj' is not inside the
/// project folder"), std::invalid_argument when trackFiles does not match the instruments.
std::string projectJsonText(const Project& project);
/// How many times projectJsonText ran in this process (a test counts the serializations an edit
/// costs; an edit of one value should cost none).
uint64_t projectTextCount();

/// Writes projectJsonText(project) to <dir>/project.json atomically (a crash leaves the old file
/// or the new one). `dir` must be an existing, writable folder; file references stay relative to
/// project.dir (saving into another folder: copy the project's files there with the same layout).
/// Every instrument's track text (the model's) is written first to its file, at the same place
/// relative to `dir`, atomically, when the file is missing or holds another text (one that holds
/// it is not rewritten). Throws viscera::InputError naming <dir>/project.json or the track file.
void saveProject(const Project& project, const std::filesystem::path& dir);

/// The model of File → New: no body yet (the artist imports anatomy or adds one; export and the
/// scene build refuse a project without one, requireABody), under gravity, XPBD at dt 1/60 s with
/// 40 substeps (enough for the load-time stability check of a newBodyMaterial() body with 5 mm
/// cells); case version 1.0.0, title = caseId. Throws viscera::InputError when `caseId` breaks
/// the case-id rule.
Project newProject(const std::filesystem::path& dir, const std::string& caseId);
/// The material a new body starts with: stable Neo-Hookean, E 3000 Pa, ν 0.45, 1050 kg/m³.
sim::Material newBodyMaterial();
/// Throws viscera::InputError "<dir>/project.json: bodies: a case needs at least one body; import
/// anatomy or add a body" when `project` has no body (a case, and a scene to simulate, need one).
void requireABody(const Project& project);

struct BodyExport {
    std::string name;
    size_t nodes = 0, tets = 0, fixedNodes = 0;
    sim::QualityReport quality;
};

/// How an exported case is published (packaging/vcase-spec.md, "Signatures").
struct CasePublishing {
    const vcase::SigningKey* key = nullptr; ///< non-owning; null: unsigned
    std::string signer;                     ///< display name in signature.json
    std::optional<std::string> expires;     ///< manifest "expires", UTC YYYY-MM-DDTHH:MM:SSZ
};

struct ExportResult {
    std::filesystem::path casePath;
    uint64_t bytes = 0;
    std::string sha256; ///< of the package written
    std::string keyId;  ///< the signing key (vcase::keyId); empty when unsigned
    std::vector<std::string> features;
    std::vector<BodyExport> bodies;
    /// What the case allows but a trainee will find hard or impossible (reachWarnings): shown by
    /// the studio and the command line; the case is written all the same.
    std::vector<std::string> warnings;
};

/// Every task target an instrument cannot reach through its port (sim::unreachableTargets on the
/// project's scene), one line each: "<dir>/project.json: interaction.instruments[2] 'clipper':
/// its port cannot reach assessment.targets.clip[0] at (0.004, 0.009, -0.006): 0.300 m from the
/// port, outside the insertion range [0.040, 0.260]". Empty when every port reaches its targets.
std::vector<std::string> reachWarnings(const Project& project);

/// Export progress: stage `index` of `total` (1-based; total is fixed for one export) and what it
/// does ("meshing body 'organ'", "skeleton and stiffness paint of 'fat'", "cutting surface
/// 'fascia'", "checking the scene", "packaging").
using ExportProgress = std::function<void(size_t index, size_t total, const std::string& stage)>;

/// What a project becomes before it is packaged: the scene the player will read (bodies and
/// surfaces with their fixed nodes and weights filled in), the built meshes, the files of the
/// case other than scene.json, and the features the scene needs. The studio's live preview
/// simulates it (assembleWorld) without writing a case.
struct BuiltScene {
    sim::SceneDesc scene;
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;      ///< meshes[i] of scene.bodies[i]
    std::vector<sim::TriMesh> surfaces;                     ///< surfaces[s] of scene.surfaces[s]
    std::vector<std::pair<std::string, std::string>> files; ///< case path, bytes
    std::vector<std::string> features;
    ExportResult result; ///< per-body figures (casePath and bytes empty)
    /// per body: the curve skeleton its stiffness paint went through (empty: no paint)
    std::vector<std::optional<sim::Skeleton>> skeletons;
    /// render.materials entries of remeshed bodies with UVs: the corner-UV file and, from the
    /// remesh block's texture, the diffuse map (both in `files`)
    std::vector<render::CaseMaterialMaps> materials;
    /// With the project's bend: the meshes and surfaces as they were before it (flat), where the
    /// fixed box, the stiffness regions and the paint strokes apply; empty without a bend.
    std::vector<std::unique_ptr<sim::TetMesh>> flatMeshes;
    std::vector<sim::TriMesh> flatSurfaces;
};

/// The checks and figures export applies to a body's built mesh, `field` "bodies[i]": nodes, tets,
/// quality (InputError "<origin>: <field>.mesh: tet 4 is inverted (2 inverted in all)", the same
/// for a degenerate tet) and the nodes in its fixed boxes into desc.fixedNodes (heldNodes). Used by export and
/// `viscera-studio mesh`.
BodyExport checkBodyMesh(const BodyProject& b, const sim::TetMesh& mesh, sim::BodyDesc& desc, const std::string& origin,
                         const std::string& field);
/// The nodes of `mesh` (the body's mesh before any bend) inside any of b.fixedBoxes, ascending;
/// InputError "<origin>: <field>.fixed[k]: the box contains no mesh node" for a box without one.
/// checkBodyMesh's rule; the preview applies it again when only the holds changed.
std::vector<int32_t> heldNodes(const BodyProject& b, const sim::TetMesh& mesh, const std::string& origin,
                               const std::string& field);
/// The node weights of body `b` on `mesh`: its stiffness regions times its stiffness paint
/// (empty: neither). The paint's skeleton is extracted into `skeleton` when it is empty, and
/// reused when given (the same mesh, painted again). Throws viscera::InputError naming
/// `origin`, `field` and the rule.
std::vector<double> bodyNodeWeights(const BodyProject& b, sim::TetMesh& mesh, std::optional<sim::Skeleton>& skeleton,
                                    const std::string& origin, const std::string& field);

/// The vertex weights of fascia `s` on its cut surface `mesh` (polygon paint; empty: no paint).
/// Throws viscera::InputError naming `origin`, `field` and the rule.
std::vector<double> surfaceNodeWeights(const SurfaceProject& s, const sim::TriMesh& mesh, const std::string& origin,
                                       const std::string& field);

/// The material maps of the project's textured bodies and surfaces, generated from their specs:
/// the package files (textures/<name>_<map>.png, only the maps the renderer samples) and the
/// render.materials entries naming them. Throws viscera::InputError naming the spec, the field
/// and the rule. Cost: one texture generation per textured body or surface.
struct ProjectTextures {
    std::vector<std::pair<std::string, std::string>> files; ///< case path, PNG bytes
    std::vector<render::CaseMaterialMaps> materials;
};
ProjectTextures bakeProjectTextures(const Project& project);
/// True when a body, surface or scenery surface of the project has a texture block.
bool hasTextures(const Project& project);

/// `scene.render` (JSON text, may be empty) with "materials" set to `materials`.
std::string renderWithMaterials(const std::string& render, const std::vector<render::CaseMaterialMaps>& materials);

/// True when the scene's "render" block asks for painted light sampling (the sample maps are
/// then packaged and used).
bool usesPaintedSampling(const sim::SceneDesc& scene);

/// Stages exportCase reports: meshing per body, stiffness paint per painted body, cutting per
/// surface, checking the scene, packaging.
size_t exportStageCount(const Project& project);

/// Builds every body mesh and surface and fills in the scene (the first stages of exportCase).
/// Throws viscera::InputError naming the body or surface and the rule (requireABody's first).
BuiltScene buildScene(const Project& project, const ExportProgress& progress = {});

/// World::assemble on copies of the built meshes: the world the player would run. Throws
/// viscera::InputError (unstable material, bad curves, ...) naming `origin`.
std::unique_ptr<sim::World> assembleWorld(const BuiltScene& built, const std::string& origin);

/// Builds every body mesh (generator or import + tetrahedralization), checks its quality (an
/// inverted or degenerate element is an error naming the body and element), resolves fixed
/// regions to node lists, and writes the case package atomically. Only what the scene uses is
/// packaged, and the manifest's features list only the subsystems the scene needs. Before any of
/// it, `out` must be writable and none of projectInputFiles (InputError naming `out`), and the
/// project must have a body (requireABody).
///
/// `publish`: the publisher's signature (none: an unsigned case, which players refuse without
/// --allow-unsigned) and the case's expiry, both bound into manifest.json.
ExportResult exportCase(const Project& project, const std::filesystem::path& out, const ExportProgress& progress = {},
                        const CasePublishing& publish = {});

/// Builds one body's tet mesh from its source (exposed for the import command and tests). A
/// remesh body's surface is the one kept in <projectDir>/cache by Make simulation-ready's Apply
/// when it is there for the block as it is (remesh_cache.hpp), else it is remeshed now; an empty
/// projectDir always remeshes. `seededPoints`, when given, receives the meshing's
/// bake::MeshingReport::missedSurfaceSeeds (0 for a mesh not made by tetrahedralize).
std::unique_ptr<sim::TetMesh> buildBodyMesh(const BodyProject& body, const std::string& origin,
                                            std::vector<render::CornerUvF>* boundaryUv = nullptr,
                                            const std::filesystem::path& projectDir = {},
                                            size_t* seededPoints = nullptr);

/// A file named by a project.json field: a relative path by the entry-name rule (no '..', not
/// absolute) inside the project folder `dir` through links too; InputError naming the field and
/// the rule otherwise. Nothing outside the folder the user gave is read.
std::filesystem::path projectFileOf(const sim::JsonField& f, const std::filesystem::path& dir);
/// The project.json form of such a file: relative to `dir` (lexical); InputError "<where>: ..."
/// when it lies outside.
std::string projectRelativePath(const std::filesystem::path& file, const std::filesystem::path& dir,
                                const std::string& where);

} // namespace viscera::studio
