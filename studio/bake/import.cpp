#include "bake/import.hpp"

#include "bake/format_check.hpp"
#include "bake/references.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "sim/util/log.hpp"

#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace viscera::bake {
namespace {

constexpr std::array<std::string_view, 6> kExtensions{".obj", ".stl", ".ply", ".gltf", ".glb", ".fbx"};
constexpr int kMaxNodeDepth = 1024;
constexpr std::string_view kMaxFileBytesName = "ImportOptions::maxFileBytes";

[[noreturn]] void fail(const std::string& label, const std::string& message) {
    throw InputError(label + ": " + message);
}

/// The bytes of a mesh file for the format checks: a regular file only (a FIFO or device would
/// be read here and then again, differently, by assimp), at most `maxBytes`.
std::string readMeshBytes(const std::filesystem::path& file, std::uintmax_t maxBytes) {
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (std::filesystem::exists(status) && !std::filesystem::is_directory(status) &&
        !std::filesystem::is_regular_file(status))
        fail(file.string(), "is not a regular file");
    return readFile(file, maxBytes, kMaxFileBytesName); // missing, directory, size: its messages
}

/// The importer's file system: opens the mesh file and files inside its folder (symbolic links
/// resolved), for reading only. The references were checked before parsing
/// (detail::checkReferences); this refuses what a parser would still reach another way (a link
/// out of the folder, a path it builds itself) and remembers the first refusal for the message.
class FolderIOSystem : public Assimp::DefaultIOSystem {
public:
    explicit FolderIOSystem(const std::filesystem::path& file)
        : m_folder(file.parent_path()), m_main(std::filesystem::weakly_canonical(file, m_ec)) {}
    bool Exists(const char* path) const override { return path && allowed(path) && DefaultIOSystem::Exists(path); }
    Assimp::IOStream* Open(const char* path, const char* mode = "rb") override {
        if (path == nullptr) return nullptr;
        const std::string_view m = mode ? mode : "rb";
        if (m.find_first_of("wa+") != std::string_view::npos) {
            refuse(path, "for writing (the importer only reads)");
            return nullptr;
        }
        if (!allowed(path)) return nullptr;
        return DefaultIOSystem::Open(path, "rb");
    }
    /// The first refusal: the path and why.
    mutable std::optional<std::pair<std::string, std::string>> refused;

private:
    void refuse(const char* path, const char* why) const {
        if (!refused) refused.emplace(path, why);
    }
    /// The mesh file itself (also through a link to it), or a regular file inside its folder; not
    /// a FIFO or device, which would block or never end.
    bool allowed(const char* path) const {
        std::error_code ec;
        const std::filesystem::path p(path);
        if (!std::filesystem::exists(p, ec)) return false; // nothing to open; assimp reports it
        if (!m_ec && std::filesystem::weakly_canonical(p, ec) == m_main && !ec) return true;
        if (!sim::insideFolder(m_folder, p)) {
            refuse(path, "outside the file's folder (references must be relative paths inside it)");
            return false;
        }
        if (!std::filesystem::is_regular_file(p, ec)) {
            refuse(path, "not a regular file");
            return false;
        }
        return true;
    }
    std::filesystem::path m_folder;
    std::error_code m_ec;
    std::filesystem::path m_main;
};

std::string meshName(const aiMesh* mesh, unsigned index) {
    std::string s = "mesh " + std::to_string(index);
    if (mesh->mName.length > 0) s += " ('" + std::string(mesh->mName.C_Str()) + "')";
    return s;
}

std::string formatVec(double x, double y, double z) {
    std::string s = "("; // appended, not "(" + string&&: GCC 12 warns (-Wrestrict) on that
    s.append(sim::formatNumber(x)).append(", ").append(sim::formatNumber(y)).append(", ");
    return s.append(sim::formatNumber(z)).append(")");
}

/// Checks of the scene exactly as the parser produced it, before any post-processing step can
/// hide a problem (joining vertices with NaN coordinates, for one, silently merges them).
void checkRawScene(const std::string& label, const aiScene* scene) {
    if (scene->mNumMeshes == 0 || scene->mMeshes == nullptr) fail(label, "empty scene: the file contains no meshes");
    size_t polygons = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        if (mesh == nullptr) fail(label, "mesh " + std::to_string(m) + " is missing");
        if (mesh->mNumVertices > 0 && mesh->mVertices == nullptr)
            fail(label, meshName(mesh, m) + " has no vertex positions");
        if (mesh->mNumFaces > 0 && mesh->mFaces == nullptr)
            fail(label, meshName(mesh, m) + " declares faces but holds none");
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D& p = mesh->mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                fail(label, meshName(mesh, m) + " vertex " + std::to_string(v) + " has a non-finite coordinate " +
                                formatVec(p.x, p.y, p.z) + "; coordinates must be finite");
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices > 0 && face.mIndices == nullptr)
                fail(label, meshName(mesh, m) + " face " + std::to_string(f) + " has no indices");
            for (unsigned k = 0; k < face.mNumIndices; ++k)
                if (face.mIndices[k] >= mesh->mNumVertices)
                    fail(label, meshName(mesh, m) + " face " + std::to_string(f) + ": index " + std::to_string(k) +
                                    " references vertex " + std::to_string(face.mIndices[k]) + " (the mesh has " +
                                    std::to_string(mesh->mNumVertices) + " vertices)");
            if (face.mNumIndices >= 3) ++polygons;
        }
    }
    if (polygons == 0)
        fail(label,
             "no faces: the scene's " + std::to_string(scene->mNumMeshes) + " mesh(es) hold no triangles or polygons");
}

Eigen::Matrix4d toEigen(const aiMatrix4x4& a) {
    Eigen::Matrix4d m;
    m << a.a1, a.a2, a.a3, a.a4, a.b1, a.b2, a.b3, a.b4, a.c1, a.c2, a.c3, a.c4, a.d1, a.d2, a.d3, a.d4;
    return m;
}

/// Bitwise key of a position for exact joining (-0 and +0 are the same point).
struct PosKey {
    std::array<uint64_t, 3> bits;
    bool operator==(const PosKey&) const = default;
};

struct PosKeyHash {
    size_t operator()(const PosKey& k) const {
        uint64_t h = 1469598103934665603ull;
        for (uint64_t b : k.bits)
            h = (h ^ b) * 1099511628211ull ^ (h >> 29);
        return static_cast<size_t>(h);
    }
};

PosKey keyOf(const sim::Vec3& p) {
    PosKey k{};
    for (int i = 0; i < 3; ++i) {
        const double c = p[i] == 0.0 ? 0.0 : p[i];
        std::memcpy(&k.bits[i], &c, sizeof c);
    }
    return k;
}

struct Merged {
    std::vector<sim::Vec3> positions;
    std::vector<sim::Tri> triangles;
    std::vector<std::array<Eigen::Vector2d, 3>> uv; ///< per triangle, when every mesh has UVs
    bool allUv = true;
    size_t instances = 0;
};

/// Walks the node tree (iteratively, depth-limited), applies the accumulated transforms and the
/// unit scale, joins identical positions across meshes and collects the triangles.
Merged mergeScene(const std::string& label, const aiScene* scene, const ImportOptions& options) {
    const double scale = options.scale;
    if (scene->mRootNode == nullptr) fail(label, "empty scene: the file has no root node");
    Merged out;
    std::unordered_map<PosKey, int32_t, PosKeyHash> index;
    struct Item {
        const aiNode* node;
        Eigen::Matrix4d parent;
        int depth;
    };
    std::vector<Item> stack{{scene->mRootNode, Eigen::Matrix4d::Identity(), 0}};
    std::vector<int32_t> remap;
    while (!stack.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        const aiNode* node = item.node;
        const std::string nodeName = "node '" + std::string(node->mName.C_Str()) + "'";
        if (item.depth > kMaxNodeDepth)
            fail(label, nodeName + ": the node hierarchy is deeper than " + std::to_string(kMaxNodeDepth) + " levels");
        const Eigen::Matrix4d world = item.parent * toEigen(node->mTransformation);
        const double det = world.topLeftCorner<3, 3>().determinant();
        if (!world.allFinite() || !std::isfinite(det) || det == 0.0)
            fail(label, nodeName + ": the transform is singular or not finite");
        const bool mirrored = det < 0;
        for (unsigned i = 0; i < node->mNumMeshes; ++i) {
            const unsigned mi = node->mMeshes[i];
            if (mi >= scene->mNumMeshes)
                fail(label, nodeName + " references mesh " + std::to_string(mi) + " (the scene has " +
                                std::to_string(scene->mNumMeshes) + ")");
            const aiMesh* mesh = scene->mMeshes[mi];
            ++out.instances;
            // Instancing multiplies a mesh: the caps are checked before each instance is added.
            if (out.positions.size() + mesh->mNumVertices > options.maxVertices)
                fail(label, "more than " + std::to_string(options.maxVertices) + " vertices (" + nodeName + " adds " +
                                meshName(mesh, mi) + " of " + std::to_string(mesh->mNumVertices) + " to the " +
                                std::to_string(out.positions.size()) +
                                " so far): over the import cap ImportOptions::maxVertices");
            if (out.triangles.size() + mesh->mNumFaces > options.maxTriangles)
                fail(label, "more than " + std::to_string(options.maxTriangles) + " triangles (" + nodeName + " adds " +
                                meshName(mesh, mi) + " of " + std::to_string(mesh->mNumFaces) + " faces to the " +
                                std::to_string(out.triangles.size()) +
                                " so far): over the import cap ImportOptions::maxTriangles");
            remap.assign(mesh->mNumVertices, 0);
            for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
                const aiVector3D& a = mesh->mVertices[v];
                const Eigen::Vector4d h = world * Eigen::Vector4d(a.x, a.y, a.z, 1.0);
                const sim::Vec3 p = options.rotation * (scale * h.head<3>());
                if (!p.allFinite())
                    fail(label, meshName(mesh, mi) + " vertex " + std::to_string(v) +
                                    " is not finite after the node transform and unit scale " +
                                    formatVec(p.x(), p.y(), p.z()));
                const auto [it, inserted] = index.try_emplace(keyOf(p), static_cast<int32_t>(out.positions.size()));
                if (inserted) out.positions.push_back(p);
                remap[v] = it->second;
            }
            const bool uv = options.keepUv && mesh->HasTextureCoords(0);
            out.allUv = out.allUv && uv;
            for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
                const aiFace& face = mesh->mFaces[f];
                if (face.mNumIndices != 3) continue; // points and lines are not surface
                sim::Tri t{remap[face.mIndices[0]], remap[face.mIndices[1]], remap[face.mIndices[2]]};
                std::array<Eigen::Vector2d, 3> c{};
                for (int k = 0; k < 3 && uv; ++k) {
                    const aiVector3D& w = mesh->mTextureCoords[0][face.mIndices[k]];
                    c[size_t(k)] = Eigen::Vector2d(w.x, w.y);
                    if (!c[size_t(k)].allFinite())
                        fail(label, meshName(mesh, mi) + " face " + std::to_string(f) +
                                        ": a texture coordinate is not finite");
                }
                if (mirrored) {
                    std::swap(t[1], t[2]);
                    std::swap(c[1], c[2]);
                }
                out.triangles.push_back(t);
                if (uv) out.uv.push_back(c);
            }
        }
        for (unsigned c = node->mNumChildren; c-- > 0;)
            if (node->mChildren[c] != nullptr) stack.push_back({node->mChildren[c], world, item.depth + 1});
    }
    return out;
}

} // namespace

std::string_view unitName(LengthUnit unit) {
    switch (unit) {
    case LengthUnit::Metre:
        return "m";
    case LengthUnit::Centimetre:
        return "cm";
    case LengthUnit::Millimetre:
        return "mm";
    case LengthUnit::Inch:
        return "inch";
    }
    return "m";
}

std::string_view unitLongName(LengthUnit unit) {
    switch (unit) {
    case LengthUnit::Metre:
        return "metres";
    case LengthUnit::Centimetre:
        return "centimetres";
    case LengthUnit::Millimetre:
        return "millimetres";
    case LengthUnit::Inch:
        return "inches";
    }
    return "metres";
}

double metresPerUnit(LengthUnit unit) {
    switch (unit) {
    case LengthUnit::Metre:
        return 1.0;
    case LengthUnit::Centimetre:
        return 0.01;
    case LengthUnit::Millimetre:
        return 0.001;
    case LengthUnit::Inch:
        return 0.0254;
    }
    return 1.0;
}

std::optional<LengthUnit> lengthUnitFromName(std::string_view name) {
    for (LengthUnit u : {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre, LengthUnit::Inch})
        if (unitName(u) == name) return u;
    return std::nullopt;
}

LengthUnit guessLengthUnit(double extent) {
    if (!(extent > 0) || !std::isfinite(extent) || (extent >= 0.01 && extent <= 1.0)) return LengthUnit::Metre;
    LengthUnit best = LengthUnit::Metre;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (LengthUnit u : {LengthUnit::Metre, LengthUnit::Centimetre, LengthUnit::Millimetre}) {
        const double distance = std::abs(std::log(extent * metresPerUnit(u) / 0.08));
        if (distance < bestDistance) {
            best = u;
            bestDistance = distance;
        }
    }
    return best;
}

Eigen::Matrix3d ImportPlacement::rotation() const {
    const Eigen::Vector3d r = rotationDeg * (std::acos(-1.0) / 180.0);
    return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
}

ImportOptions placedOptions(const ImportPlacement& placement, ImportOptions base) {
    base.scale = placement.metresPerFileUnit();
    base.rotation = placement.rotation();
    return base;
}

std::string_view formatName(SurfaceFormat format) {
    switch (format) {
    case SurfaceFormat::Obj:
        return "OBJ";
    case SurfaceFormat::StlAscii:
        return "ASCII STL";
    case SurfaceFormat::StlBinary:
        return "binary STL";
    case SurfaceFormat::Ply:
        return "PLY";
    case SurfaceFormat::Gltf:
        return "glTF";
    case SurfaceFormat::Glb:
        return "GLB";
    case SurfaceFormat::Fbx:
        return "FBX";
    }
    return "unknown";
}

std::span<const std::string_view> acceptedExtensions() {
    return kExtensions;
}

SurfaceFormat detectSurfaceFormat(const std::filesystem::path& file) {
    const std::string label = file.string();
    const std::string bytes = readMeshBytes(file, ImportOptions{}.maxFileBytes);
    return detail::sniffFormat(label, detail::lowerExtension(file), bytes);
}

ImportResult importSurfaceWithReport(const std::filesystem::path& file, const ImportOptions& options) {
    if (!std::isfinite(options.scale) || options.scale <= 0)
        throw std::invalid_argument("bake::importSurface(): ImportOptions::scale is " + std::to_string(options.scale) +
                                    " (must be finite and > 0)");
    const Eigen::Matrix3d& r = options.rotation;
    if (!r.allFinite() || !(r * r.transpose()).isIdentity(1e-9) || !(std::abs(r.determinant() - 1.0) < 1e-9))
        throw std::invalid_argument("bake::importSurface(): ImportOptions::rotation is not a proper rotation");
    const std::string label = file.string();
    ImportReport report;
    {
        // The bytes are only needed for the checks; release them before assimp reads the file.
        const std::string ext = detail::lowerExtension(file);
        detail::checkExtension(label, ext); // before reading a file that is rejected anyway
        const std::string bytes = readMeshBytes(file, options.maxFileBytes);
        report.format = detail::sniffFormat(label, ext, bytes);
        detail::checkStructure(label, report.format, bytes);
        // Before any parser runs: a reference out of the folder refuses the file unread.
        detail::checkReferences(label, report.format, bytes, file.parent_path());
    }

    Assimp::Importer importer;
    auto* io = new FolderIOSystem(file); // owned by the importer
    importer.SetIOHandler(io);
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const int removed = aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS | aiComponent_COLORS |
                        aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS | aiComponent_TEXTURES | aiComponent_LIGHTS |
                        aiComponent_CAMERAS | aiComponent_MATERIALS;
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, options.keepUv ? removed : removed | aiComponent_TEXCOORDS);
    importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);

    const aiScene* scene = nullptr;
    try {
        // No post-processing yet: the raw scene is checked first.
        scene = importer.ReadFile(label, 0);
    } catch (const std::exception& e) {
        fail(label, "cannot be parsed as " + std::string(formatName(report.format)) + ": " + e.what());
    }
    if (io->refused)
        fail(label,
             "the importer asked for '" + sim::displayName(io->refused->first) + "', refused: " + io->refused->second);
    if (scene == nullptr) {
        std::string why = importer.GetErrorString();
        if (why.rfind("No suitable reader found", 0) == 0)
            why = "the importer does not recognise the content (malformed or truncated file)";
        fail(label, "cannot be parsed as " + std::string(formatName(report.format)) + ": " + why);
    }
    checkRawScene(label, scene);

    try {
        scene = importer.ApplyPostProcessing(aiProcess_ValidateDataStructure | aiProcess_RemoveComponent |
                                             aiProcess_Triangulate | aiProcess_SortByPType |
                                             aiProcess_JoinIdenticalVertices);
    } catch (const std::exception& e) {
        fail(label, std::string("invalid scene structure: ") + e.what());
    }
    if (scene == nullptr) fail(label, std::string("invalid scene structure: ") + importer.GetErrorString());

    Merged merged = mergeScene(label, scene, options);
    report.meshInstances = merged.instances;
    report.sourceTriangles = merged.triangles.size();
    if (merged.triangles.empty()) fail(label, "no faces: no mesh instance in the scene graph holds triangles");

    // Drop triangles that collapsed when vertices were joined, then unreferenced vertices.
    std::vector<sim::Tri> triangles;
    triangles.reserve(merged.triangles.size());
    const bool withUv = options.keepUv && merged.allUv && merged.uv.size() == merged.triangles.size();
    std::vector<std::array<Eigen::Vector2d, 3>> uv;
    for (size_t i = 0; i < merged.triangles.size(); ++i)
        if (const sim::Tri& t = merged.triangles[i]; t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) {
            triangles.push_back(t);
            if (withUv) uv.push_back(merged.uv[i]);
        }
    report.degenerateTrianglesDropped = merged.triangles.size() - triangles.size();
    if (triangles.empty())
        fail(label, "no faces: all " + std::to_string(merged.triangles.size()) +
                        " triangles collapse when identical vertices are joined");
    std::vector<int32_t> compact(merged.positions.size(), -1);
    std::vector<sim::Vec3> positions;
    positions.reserve(merged.positions.size());
    for (sim::Tri& t : triangles)
        for (int32_t& v : t) {
            if (compact[v] < 0) {
                compact[v] = static_cast<int32_t>(positions.size());
                positions.push_back(merged.positions[v]);
            }
            v = compact[v];
        }
    report.unreferencedVerticesDropped = merged.positions.size() - positions.size();
    if (report.degenerateTrianglesDropped > 0)
        log::warn(label + ": dropped " + std::to_string(report.degenerateTrianglesDropped) +
                  " triangle(s) that collapse when identical vertices are joined");

    try {
        return {sim::TriMesh::fromArrays(std::move(positions), std::move(triangles), label), report, std::move(uv)};
    } catch (const std::invalid_argument& e) {
        throw InputError(e.what());
    }
}

sim::TriMesh importSurface(const std::filesystem::path& file, const ImportOptions& options) {
    return importSurfaceWithReport(file, options).mesh;
}

} // namespace viscera::bake
