#include "sim/mesh/tet_io.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/line_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

namespace viscera::sim {
namespace {

using detail::LineReader;

constexpr int64_t kMaxCount = int64_t{1} << 28;

} // namespace

namespace {

/// Header, vertex block and element block shared by .vtet (N = 4) and .vtri (N = 3).
template <size_t N>
void parseElements(LineReader& in, const char* magic, const char* elemKeyword, const char* elemName,
                   std::vector<Vec3>& pos, std::vector<std::array<int32_t, N>>& elems) {
    std::vector<std::string_view> tok;
    if (!in.next(tok)) in.failEof(std::string("header '") + magic + " 1'");
    if (tok.size() != 2 || tok[0] != magic) in.fail(std::string("header must be '") + magic + " <version>'");
    if (in.number<int>(tok[1], "version") != 1)
        in.fail(std::string("unsupported ") + magic + " version " + std::string(tok[1]) + " (supported: 1)");
    auto readCount = [&](const char* keyword) {
        if (!in.next(tok)) in.failEof(std::string("'") + keyword + " <count>'");
        if (tok.size() != 2 || tok[0] != keyword) in.fail(std::string("expected '") + keyword + " <count>'");
        auto n = in.number<int64_t>(tok[1], "count");
        if (n < 0 || n > kMaxCount)
            in.fail(std::string(keyword) + " count " + std::to_string(n) + " is out of range [0, 2^28]");
        return n;
    };
    // A count only reserves what a few lines would need: the lines themselves grow the arrays, so
    // a header claiming 2^28 elements over a short file costs no more memory than the file.
    constexpr int64_t kReserveAtMost = 1 << 16;
    const int64_t nv = readCount("vertices");
    pos.reserve(static_cast<size_t>(std::min(nv, kReserveAtMost)));
    for (int64_t v = 0; v < nv; ++v) {
        if (!in.next(tok)) in.failEof("vertex " + std::to_string(v));
        if (tok.size() != 3) in.fail("vertex " + std::to_string(v) + " must have 3 coordinates");
        Vec3 p(in.number<double>(tok[0], "coordinate"), in.number<double>(tok[1], "coordinate"),
               in.number<double>(tok[2], "coordinate"));
        if (!p.allFinite()) in.fail("vertex " + std::to_string(v) + " has a non-finite coordinate");
        pos.push_back(p);
    }
    const int64_t ne = readCount(elemKeyword);
    if (ne == 0) in.fail(std::string("mesh has no ") + elemKeyword);
    elems.reserve(static_cast<size_t>(std::min(ne, kReserveAtMost)));
    for (int64_t t = 0; t < ne; ++t) {
        const std::string what = std::string(elemName) + " " + std::to_string(t);
        if (!in.next(tok)) in.failEof(what);
        if (tok.size() != N) in.fail(what + " must have " + std::to_string(N) + " vertex indices");
        std::array<int32_t, N> e;
        for (size_t k = 0; k < N; ++k) {
            auto idx = in.number<int64_t>(tok[k], "vertex index");
            if (idx < 0 || idx >= nv)
                in.fail(what + " references vertex " + std::to_string(idx) + " (mesh has " + std::to_string(nv) +
                        " vertices)");
            e[k] = static_cast<int32_t>(idx);
        }
        elems.push_back(e);
    }
    if (in.next(tok)) in.fail(std::string("unexpected content after the last ") + elemName);
}

template <size_t N>
std::string formatElements(const char* magic, const char* elemKeyword, const std::vector<Vec3>& pos,
                           const std::vector<std::array<int32_t, N>>& elems) {
    std::string out;
    out.reserve(pos.size() * 64 + elems.size() * 32 + 64);
    out += std::string(magic) + " 1\nvertices " + std::to_string(pos.size()) + "\n";
    char buf[128];
    for (const Vec3& p : pos) {
        int n = std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
        out.append(buf, static_cast<size_t>(n));
    }
    out += std::string(elemKeyword) + " " + std::to_string(elems.size()) + "\n";
    for (const auto& e : elems) {
        for (size_t k = 0; k < N; ++k) {
            out += std::to_string(e[k]);
            out += k + 1 < N ? ' ' : '\n';
        }
    }
    return out;
}

} // namespace

std::unique_ptr<TetMesh> parseVtet(std::string_view text, const std::string& origin) {
    LineReader in(text, origin);
    std::vector<Vec3> pos;
    std::vector<Tet> tets;
    parseElements<4>(in, "vtet", "tets", "tet", pos, tets);
    try {
        return TetMesh::fromArrays(std::move(pos), std::move(tets), origin);
    } catch (const std::invalid_argument& e) {
        throw InputError(e.what());
    }
}

std::string formatVtet(const TetMesh& mesh) {
    return formatElements<4>("vtet", "tets", mesh.positions(), mesh.tets());
}

TriMesh parseVtri(std::string_view text, const std::string& origin) {
    LineReader in(text, origin);
    std::vector<Vec3> pos;
    std::vector<Tri> tris;
    parseElements<3>(in, "vtri", "triangles", "triangle", pos, tris);
    try {
        return TriMesh::fromArrays(std::move(pos), std::move(tris), origin);
    } catch (const std::invalid_argument& e) {
        throw InputError(e.what());
    }
}

std::string formatVtri(const TriMesh& mesh) {
    return formatElements<3>("vtri", "triangles", mesh.positions(), mesh.triangles());
}

std::unique_ptr<TetMesh> readVtet(const std::filesystem::path& path) {
    return parseVtet(readFile(path), path.filename().string());
}

void writeVtet(const std::filesystem::path& path, const TetMesh& mesh) {
    writeFileAtomic(path, formatVtet(mesh));
}

} // namespace viscera::sim
