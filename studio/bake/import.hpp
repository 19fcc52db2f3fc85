#pragma once
/// Import of authoring surfaces (anatomy meshes from modelling tools) into a sim::TriMesh.
///
/// Accepted formats form a whitelist checked twice: by the file extension and by the file's
/// content (magic bytes or leading tokens must agree with the extension). Everything else is
/// rejected with viscera::InputError before any third-party parser sees the bytes. Messages are
/// one line: "<file>: <element or field>: <rule that failed>".
///
/// The importer merges every mesh instance of the scene graph (node transforms applied, winding
/// reversed under mirroring transforms), triangulates polygons, drops points and lines, joins
/// identical vertices (by position, across meshes), drops triangles that collapse when vertices
/// are joined and applies the unit scale. It does not repair geometry (holes, self-intersections,
/// orientation): that is the sanitize stage's job, and tetrahedralize() checks what it needs.
/// Unit metadata stored in a file (FBX UnitScaleFactor) is not applied: ImportOptions::scale is
/// the only unit conversion (glTF is in metres by specification; OBJ, STL and PLY carry no unit),
/// followed by ImportOptions::rotation. ImportPlacement is how an artist states both (a length
/// unit, guessed from the size when not known, a uniform scale and Euler angles).
/// Dropped triangles are counted in ImportReport and logged through viscera::log (warning).
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>

namespace viscera::bake {

enum class SurfaceFormat { Obj, StlAscii, StlBinary, Ply, Gltf, Glb, Fbx };

/// Short human-readable name: "OBJ", "ASCII STL", "binary STL", "PLY", "glTF", "GLB", "FBX".
std::string_view formatName(SurfaceFormat format);

/// The accepted extensions, lower case with the dot: .obj .stl .ply .gltf .glb .fbx
/// (matched case-insensitively).
std::span<const std::string_view> acceptedExtensions();

/// A file's length unit.
enum class LengthUnit { Metre, Centimetre, Millimetre, Inch };

/// "m", "cm", "mm", "inch" (the project's spelling) and "metres", "centimetres", "millimetres",
/// "inches" (for people).
std::string_view unitName(LengthUnit unit);
std::string_view unitLongName(LengthUnit unit);
/// Metres per unit: 1, 0.01, 0.001, 0.0254.
double metresPerUnit(LengthUnit unit);
/// The unit named `name` (unitName's spelling), none when it names no unit.
std::optional<LengthUnit> lengthUnitFromName(std::string_view name);
/// The unit a surface whose longest bounding-box edge is `extent` file units most likely uses:
/// metres when that is an organ's size already (1 cm to 1 m), else the one of metres, centimetres
/// and millimetres that makes it closest to 8 cm (a ratio). Inches are never guessed (a guess
/// cannot tell them from centimetres). A liver 6.4 units long: centimetres; 250 units: millimetres.
LengthUnit guessLengthUnit(double extent);

/// Where an imported surface goes, after the file's own node transforms: file units to metres
/// (the unit times a uniform scale), then rotated about the origin.
struct ImportPlacement {
    LengthUnit unit = LengthUnit::Metre;
    double scale = 1.0; ///< uniform, on top of the unit; finite and > 0
    /// Euler angles in degrees, each in [-360, 360]: about x, then y, then z of the file's frame
    /// (R = Rz · Ry · Rx). A Y-up file (most modelling tools) becomes Z-up with (90, 0, 0).
    Eigen::Vector3d rotationDeg = Eigen::Vector3d::Zero();

    /// The file-unit-to-metre factor: metresPerUnit(unit) · scale.
    double metresPerFileUnit() const { return metresPerUnit(unit) * scale; }
    /// R (a proper rotation).
    Eigen::Matrix3d rotation() const;
    bool operator==(const ImportPlacement&) const = default;
};

struct ImportOptions {
    /// Factor from file units to metres, applied after node transforms (0.001 for a file in
    /// millimetres, 0.01 for centimetres). Finite and > 0.
    double scale = 1.0;
    /// Applied after the scale, about the origin: a proper rotation (orthonormal, determinant 1).
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    /// Files larger than this are rejected before parsing (bytes).
    std::uintmax_t maxFileBytes = std::uintmax_t{1} << 30;
    /// Caps on the merged surface (after node instancing, before joining): a file over them is
    /// refused naming the cap, before the vertices are copied.
    size_t maxVertices = 10'000'000;
    size_t maxTriangles = 20'000'000;
    /// Keep the first texture-coordinate set, per triangle corner (ImportResult::uv): anatomy for
    /// the remesh with UV transfer. Vertices are still joined by position.
    bool keepUv = false;
};

/// The options that place a surface as `placement` says (scale and rotation), the rest `base`.
ImportOptions placedOptions(const ImportPlacement& placement, ImportOptions base = {});

struct ImportReport {
    SurfaceFormat format = SurfaceFormat::Obj;
    size_t meshInstances = 0;               ///< mesh instances merged from the scene graph
    size_t sourceTriangles = 0;             ///< triangles after triangulation, before cleanup
    size_t degenerateTrianglesDropped = 0;  ///< triangles that collapsed when vertices were joined
    size_t unreferencedVerticesDropped = 0; ///< vertices used by no kept triangle
};

struct ImportResult {
    sim::TriMesh mesh; ///< positions in metres, file's world frame; triangles as in the file
    ImportReport report;
    /// With ImportOptions::keepUv: (u, v) of each triangle's three corners, one per triangle of
    /// `mesh`; empty when a mesh of the file has no texture coordinates.
    std::vector<std::array<Eigen::Vector2d, 3>> uv;
};

/// Checks the extension and the content of `file` and returns its format without parsing the
/// whole scene. Throws InputError: file missing or unreadable, empty, unsupported extension,
/// content that does not match the extension.
SurfaceFormat detectSurfaceFormat(const std::filesystem::path& file);

/// Imports the surface in `file` (see the file comment for what is merged and joined).
/// Throws viscera::InputError, naming the file, the element and the rule, when: the format is not
/// accepted or the content does not match the extension; the file is empty, truncated or
/// malformed; the scene has no triangles; a coordinate is not finite (names the vertex); a face
/// references a vertex that does not exist (names the face and the index); the file refers to
/// another file (material library, texture, buffer, image) by a path that is not a relative path
/// inside its folder (bake/references.hpp: before any parser runs, so nothing outside is opened;
/// names the reference and the rule); the merged surface exceeds maxVertices or maxTriangles.
/// Throws std::invalid_argument when `options.scale` is not finite and > 0 or `options.rotation`
/// is not a proper rotation.
/// Cost: linear in the file size; the whole file is read into memory once for the checks.
sim::TriMesh importSurface(const std::filesystem::path& file, const ImportOptions& options = {});

/// importSurface() with the figures of what was merged and cleaned up.
ImportResult importSurfaceWithReport(const std::filesystem::path& file, const ImportOptions& options = {});

} // namespace viscera::bake
