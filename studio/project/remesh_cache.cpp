#include "project/remesh_cache.hpp"

#include "case/sha256.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <atomic>
#include <cmath>
#include <cstring>

namespace viscera::studio {
namespace {

std::atomic<uint64_t> g_remeshRuns{0};

constexpr char kMagic[] = "VISCERA-REMESH 1\n"; // 17 bytes, then the meshes
constexpr uint64_t kMaxCount = uint64_t{1} << 26;

template <class T> void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

void putMesh(std::string& out, const sim::TriMesh& m) {
    put(out, uint64_t(m.positions().size()));
    put(out, uint64_t(m.triangles().size()));
    for (const sim::Vec3& p : m.positions())
        put(out, p.x()), put(out, p.y()), put(out, p.z());
    for (const sim::Tri& t : m.triangles())
        put(out, t[0]), put(out, t[1]), put(out, t[2]);
}

/// Reads the bytes back in order; every failure names the file and what is wrong.
struct Reader {
    const std::string& bytes;
    const std::string& origin;
    size_t at = 0;

    template <class T> T get() {
        if (bytes.size() - at < sizeof(T)) throw InputError(origin + ": truncated at byte " + std::to_string(at));
        T v;
        std::memcpy(&v, bytes.data() + at, sizeof v);
        at += sizeof v;
        return v;
    }
    uint64_t count(const char* what) {
        const uint64_t n = get<uint64_t>();
        if (n > kMaxCount)
            throw InputError(origin + ": " + what + " count " + std::to_string(n) + " exceeds " +
                             std::to_string(kMaxCount));
        return n;
    }
    double finite(const char* what) {
        const double v = get<double>();
        if (!std::isfinite(v)) throw InputError(origin + ": a " + std::string(what) + " is not finite");
        return v;
    }
    sim::TriMesh mesh(const char* what) {
        const uint64_t nv = count("vertex"), nt = count("triangle");
        std::vector<sim::Vec3> pos(nv);
        for (sim::Vec3& p : pos)
            for (int k = 0; k < 3; ++k)
                p[k] = finite("coordinate");
        std::vector<sim::Tri> tris(nt);
        for (sim::Tri& t : tris)
            for (int k = 0; k < 3; ++k)
                t[k] = get<int32_t>();
        try {
            return sim::TriMesh::fromArrays(std::move(pos), std::move(tris), origin + ": " + what);
        } catch (const std::invalid_argument& e) {
            throw InputError(e.what());
        }
    }
};

} // namespace

std::vector<bake::RemeshPart> importRemeshParts(const RemeshSource& r) {
    std::vector<bake::RemeshPart> parts;
    for (const RemeshSource::Part& p : r.parts) {
        bake::ImportOptions opt = bake::placedOptions(r.placement);
        opt.keepUv = r.uvTransfer.has_value();
        bake::ImportResult in = bake::importSurfaceWithReport(p.file, opt);
        if (opt.keepUv && in.uv.empty())
            throw InputError(p.file.string() + ": has no texture coordinates (uv_transfer needs UVs on every part; "
                                               "'none' remeshes without them)");
        parts.push_back({p.file.filename().string(), std::move(in.mesh), p.op, std::move(in.uv)});
    }
    return parts;
}

RemeshedSurface remeshSurface(const RemeshSource& r, RemeshRun* run, const bake::RemeshProgress& progress) {
    ++g_remeshRuns;
    RemeshRun local;
    RemeshRun& x = run ? *run : local;
    x.parts = importRemeshParts(r);
    bake::RemeshParams params = r.params;
    params.transferUv = r.uvTransfer == bake::UvTransferMethod::SeamCutting;
    x.result = bake::voxelRemesh(x.parts, params, progress);
    RemeshedSurface s;
    s.surface = x.result.mesh;
    s.uv = x.result.uv;
    if (r.uvTransfer && *r.uvTransfer != bake::UvTransferMethod::SeamCutting)
        s.uv = bake::transferUv(bake::UvSource(x.parts), x.result.mesh, *r.uvTransfer);
    // The tets fill the remeshed surface before the seam cut (its triangles are well shaped; the
    // cut's pieces along the seams would become features and slivers).
    s.hull = x.result.uncut.triangleCount() > 0 ? x.result.uncut : x.result.mesh;
    return s;
}

uint64_t remeshRunCount() {
    return g_remeshRuns.load();
}

std::string remeshKey(const RemeshSource& r) {
    std::string text = "remesh 1\n";
    char buf[512];
    for (const RemeshSource::Part& p : r.parts)
        text += "part " + std::string(bake::csgOpName(p.op)) + " " + vcase::sha256Hex(readFile(p.file)) + "\n";
    const bake::ImportPlacement& pl = r.placement;
    const bake::RemeshParams& q = r.params;
    std::snprintf(buf, sizeof buf,
                  "placement %s %.17g %.17g %.17g %.17g\nparams %.17g %d %.17g %d %.17g %d %.17g %d %zu\nuv %d\n",
                  std::string(bake::unitName(pl.unit)).c_str(), pl.scale, pl.rotationDeg.x(), pl.rotationDeg.y(),
                  pl.rotationDeg.z(), q.voxelSize, q.voxelCount, q.bandVoxels, q.smoothingIterations,
                  q.targetEdgeLength, q.remeshIterations, q.featureAngleDeg, q.maxVoxelsPerAxis, q.maxTriangles,
                  r.uvTransfer ? int(*r.uvTransfer) : -1);
    if (q.fillOpenings > 0) { // only then: the keys of blocks without it stay as they were
        std::snprintf(buf + std::strlen(buf), sizeof buf - std::strlen(buf), "fill %.17g\n", q.fillOpenings);
    }
    return vcase::sha256Hex(text + buf);
}

std::filesystem::path keptRemeshFile(const std::filesystem::path& projectDir, const std::string& key) {
    return projectDir / "cache" / ("remesh-" + key + ".vremesh");
}

void writeRemeshedSurface(const std::filesystem::path& file, const RemeshedSurface& s) {
    std::string out(kMagic);
    putMesh(out, s.hull);
    putMesh(out, s.surface);
    put(out, uint64_t(s.uv.size()));
    for (const bake::CornerUv& c : s.uv)
        for (const Eigen::Vector2d& v : c)
            put(out, v.x()), put(out, v.y());
    writeFileAtomic(file, out);
}

RemeshedSurface readRemeshedSurface(const std::filesystem::path& file) {
    const std::string bytes = readFile(file);
    const std::string origin = file.string();
    if (bytes.compare(0, sizeof kMagic - 1, kMagic) != 0)
        throw InputError(origin + ": not a kept remesh (no '" + std::string(kMagic, sizeof kMagic - 2) + "' header)");
    Reader in{bytes, origin, sizeof kMagic - 1};
    RemeshedSurface s;
    s.hull = in.mesh("hull");
    s.surface = in.mesh("surface");
    const uint64_t n = in.count("uv");
    if (n != 0 && n != s.surface.triangleCount())
        throw InputError(origin + ": " + std::to_string(n) + " corner UVs for " +
                         std::to_string(s.surface.triangleCount()) + " triangles (must be one per triangle or none)");
    s.uv.resize(n);
    for (bake::CornerUv& c : s.uv)
        for (Eigen::Vector2d& v : c)
            v.x() = in.finite("UV"), v.y() = in.finite("UV");
    if (in.at != bytes.size())
        throw InputError(origin + ": " + std::to_string(bytes.size() - in.at) + " bytes after the end");
    return s;
}

RemeshedSurface keptOrFreshRemesh(const RemeshSource& r, const std::filesystem::path& projectDir, bool* reused) {
    if (reused) *reused = false;
    if (!projectDir.empty()) {
        const std::filesystem::path kept = keptRemeshFile(projectDir, remeshKey(r));
        std::error_code ec;
        if (std::filesystem::is_regular_file(kept, ec)) {
            if (reused) *reused = true;
            return readRemeshedSurface(kept);
        }
    }
    return remeshSurface(r);
}

} // namespace viscera::studio
