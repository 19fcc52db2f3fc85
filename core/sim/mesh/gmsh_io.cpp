#include "sim/mesh/gmsh_io.hpp"

#include "sim/mesh/tet_io.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/line_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iterator>
#include <unordered_map>

namespace viscera::sim {
namespace {

using detail::LineReader;
constexpr int64_t kMaxCount = int64_t{1} << 28;
constexpr int kGmshTet = 4, kVtkTet = 10;

/// Nodes by tag and tetrahedra by node tag, as read; made into a mesh by finish().
struct Raw {
    std::unordered_map<int64_t, Vec3> nodes;
    std::vector<std::array<int64_t, 4>> tets;
};

/// The tetrahedra's nodes only, renumbered in order of first use, each tetrahedron positive.
std::unique_ptr<TetMesh> finish(const Raw& raw, const std::string& origin, double scale) {
    if (raw.tets.empty()) throw InputError(origin + ": has no linear tetrahedra (Gmsh type 4, VTK cell type 10)");
    if (!(scale > 0) || !std::isfinite(scale)) throw InputError(origin + ": scale must be a positive number");
    std::unordered_map<int64_t, int32_t> index;
    std::vector<Vec3> positions;
    std::vector<Tet> tets;
    tets.reserve(raw.tets.size());
    for (size_t t = 0; t < raw.tets.size(); ++t) {
        Tet tet{};
        for (int k = 0; k < 4; ++k) {
            const int64_t tag = raw.tets[t][size_t(k)];
            auto [it, fresh] = index.try_emplace(tag, static_cast<int32_t>(positions.size()));
            if (fresh) {
                const auto node = raw.nodes.find(tag);
                if (node == raw.nodes.end())
                    throw InputError(origin + ": tetrahedron " + std::to_string(t) + " uses node " +
                                     std::to_string(tag) + ", which the file does not define");
                positions.push_back(node->second * scale);
            }
            tet[size_t(k)] = it->second;
        }
        const Vec3 &a = positions[size_t(tet[0])], &b = positions[size_t(tet[1])], &c = positions[size_t(tet[2])],
                   &d = positions[size_t(tet[3])];
        const double volume = (b - a).cross(c - a).dot(d - a);
        if (!(std::abs(volume) > 0))
            throw InputError(origin + ": tetrahedron " + std::to_string(t) + " (nodes " +
                             std::to_string(raw.tets[t][0]) + " " + std::to_string(raw.tets[t][1]) + " " +
                             std::to_string(raw.tets[t][2]) + " " + std::to_string(raw.tets[t][3]) + ") has no volume");
        if (volume < 0) std::swap(tet[2], tet[3]);
        tets.push_back(tet);
    }
    try {
        return TetMesh::fromArrays(std::move(positions), std::move(tets), origin);
    } catch (const std::invalid_argument& e) { // the mesh rules (a repeated node, a facet of three tets)
        throw InputError(e.what());
    }
}

/// Adds node `tag` at `p`; a tag defined twice is refused.
void addNode(LineReader& in, Raw& raw, int64_t tag, const Vec3& p) {
    if (!raw.nodes.try_emplace(tag, p).second) in.fail("node " + std::to_string(tag) + " is defined twice");
}

int64_t count(LineReader& in, std::string_view tok, const char* what) {
    const auto n = in.number<int64_t>(tok, what);
    if (n < 0 || n > kMaxCount) in.fail(std::string(what) + " " + std::to_string(n) + " is out of range [0, 2^28]");
    return n;
}

void expectLine(LineReader& in, std::vector<std::string_view>& tok, std::string_view keyword) {
    if (!in.next(tok)) in.failEof("'" + std::string(keyword) + "'");
    if (tok.size() != 1 || tok[0] != keyword) in.fail("expected '" + std::string(keyword) + "'");
}

Vec3 coordinates(LineReader& in, const std::vector<std::string_view>& tok, size_t from, const std::string& what) {
    if (tok.size() < from + 3) in.fail(what + " needs x y z");
    const Vec3 p(in.number<double>(tok[from], "coordinate"), in.number<double>(tok[from + 1], "coordinate"),
                 in.number<double>(tok[from + 2], "coordinate"));
    if (!p.allFinite()) in.fail(what + " has a non-finite coordinate");
    return p;
}

/// A Gmsh element of `type`: a linear tetrahedron is kept; points, lines and surface elements
/// (the boundary Gmsh saves with the volume) are skipped; any other element (a volume element
/// other than the linear tetrahedron, or a type this reader does not know) is refused, since
/// dropping it would leave a hole.
bool keepGmshElement(LineReader& in, int type, int64_t tag) {
    if (type == kGmshTet) return true;
    const bool lowerDimension = type == 1 || type == 2 || type == 3 || (type >= 8 && type <= 10) || type == 15 ||
                                type == 16 || (type >= 20 && type <= 28) || type == 34 || (type >= 36 && type <= 70);
    if (lowerDimension) return false;
    const char* name = type == 11   ? "10-node tetrahedron"
                       : type == 5  ? "hexahedron"
                       : type == 6  ? "prism"
                       : type == 7  ? "pyramid"
                       : type == 35 ? "polyhedron"
                                    : "a volume or unknown element";
    in.fail("element " + std::to_string(tag) + " is of type " + std::to_string(type) + " (" + name +
            "): only linear tetrahedra (type 4) are read");
}

void gmshNodesV2(LineReader& in, Raw& raw) {
    std::vector<std::string_view> tok;
    if (!in.next(tok) || tok.size() != 1) in.fail("expected the node count");
    const int64_t n = count(in, tok[0], "node count");
    for (int64_t i = 0; i < n; ++i) {
        if (!in.next(tok)) in.failEof("node " + std::to_string(i));
        const auto tag = in.number<int64_t>(tok[0], "node tag");
        addNode(in, raw, tag, coordinates(in, tok, 1, "node " + std::to_string(tag)));
    }
    expectLine(in, tok, "$EndNodes");
}

void gmshElementsV2(LineReader& in, Raw& raw) {
    std::vector<std::string_view> tok;
    if (!in.next(tok) || tok.size() != 1) in.fail("expected the element count");
    const int64_t n = count(in, tok[0], "element count");
    for (int64_t i = 0; i < n; ++i) {
        if (!in.next(tok)) in.failEof("element " + std::to_string(i));
        if (tok.size() < 3) in.fail("an element line needs its number, type and tag count");
        const auto tag = in.number<int64_t>(tok[0], "element number");
        const auto type = in.number<int>(tok[1], "element type");
        const auto tags = in.number<int64_t>(tok[2], "tag count");
        if (!keepGmshElement(in, type, tag)) continue;
        if (tags < 0 || tags > static_cast<int64_t>(tok.size()) || static_cast<int64_t>(tok.size()) != 3 + tags + 4)
            in.fail("element " + std::to_string(tag) + " (a tetrahedron) needs 4 node tags after its " +
                    std::to_string(tags) + " tag(s)");
        std::array<int64_t, 4> t{};
        for (size_t k = 0; k < 4; ++k)
            t[k] = in.number<int64_t>(tok[3 + size_t(tags) + k], "node tag");
        raw.tets.push_back(t);
    }
    expectLine(in, tok, "$EndElements");
}

void gmshNodesV4(LineReader& in, Raw& raw) {
    std::vector<std::string_view> tok;
    if (!in.next(tok) || tok.size() != 4) in.fail("expected 'numEntityBlocks numNodes minNodeTag maxNodeTag'");
    const int64_t blocks = count(in, tok[0], "block count");
    for (int64_t b = 0; b < blocks; ++b) {
        if (!in.next(tok) || tok.size() != 4) in.fail("expected 'entityDim entityTag parametric numNodesInBlock'");
        const bool parametric = in.number<int>(tok[2], "parametric") != 0;
        const int64_t n = count(in, tok[3], "node count");
        std::vector<int64_t> tags;
        for (int64_t i = 0; i < n; ++i) {
            if (!in.next(tok) || tok.size() != 1) in.fail("expected a node tag");
            tags.push_back(in.number<int64_t>(tok[0], "node tag"));
        }
        for (int64_t i = 0; i < n; ++i) {
            if (!in.next(tok)) in.failEof("the coordinates of node " + std::to_string(tags[size_t(i)]));
            if (!parametric && tok.size() != 3) in.fail("node " + std::to_string(tags[size_t(i)]) + " needs x y z");
            addNode(in, raw, tags[size_t(i)], coordinates(in, tok, 0, "node " + std::to_string(tags[size_t(i)])));
        }
    }
    expectLine(in, tok, "$EndNodes");
}

void gmshElementsV4(LineReader& in, Raw& raw) {
    std::vector<std::string_view> tok;
    if (!in.next(tok) || tok.size() != 4) in.fail("expected 'numEntityBlocks numElements minTag maxTag'");
    const int64_t blocks = count(in, tok[0], "block count");
    for (int64_t b = 0; b < blocks; ++b) {
        if (!in.next(tok) || tok.size() != 4) in.fail("expected 'entityDim entityTag elementType numElementsInBlock'");
        const auto type = in.number<int>(tok[2], "element type");
        const int64_t n = count(in, tok[3], "element count");
        for (int64_t i = 0; i < n; ++i) {
            if (!in.next(tok)) in.failEof("an element");
            const auto tag = in.number<int64_t>(tok[0], "element tag");
            if (!keepGmshElement(in, type, tag)) continue;
            if (tok.size() != 5) in.fail("element " + std::to_string(tag) + " (a tetrahedron) needs 4 node tags");
            raw.tets.push_back({in.number<int64_t>(tok[1], "node tag"), in.number<int64_t>(tok[2], "node tag"),
                                in.number<int64_t>(tok[3], "node tag"), in.number<int64_t>(tok[4], "node tag")});
        }
    }
    expectLine(in, tok, "$EndElements");
}

/// Skips a section `$Name` up to its `$EndName`.
void skipSection(LineReader& in, std::string_view name) {
    std::vector<std::string_view> tok;
    const std::string end = "$End" + std::string(name.substr(1));
    while (in.next(tok))
        if (tok.size() == 1 && tok[0] == end) return;
    in.failEof("'" + end + "'");
}

} // namespace

std::unique_ptr<TetMesh> parseGmshTets(std::string_view text, const std::string& origin, double scale) {
    LineReader in(text, origin);
    std::vector<std::string_view> tok;
    expectLine(in, tok, "$MeshFormat");
    if (!in.next(tok) || tok.size() != 3) in.fail("expected 'version file-type data-size'");
    const std::string version(tok[0]);
    const bool v2 = version == "2.2" || version == "2.1" || version == "2.0", v4 = version == "4.1";
    if (!v2 && !v4) in.fail("MSH version " + version + " is not read (2.2 and 4.1 are)");
    if (tok[1] != "0") in.fail("a binary .msh is not read: save it as ASCII (Gmsh: File > Export > 'Version 4 ASCII')");
    expectLine(in, tok, "$EndMeshFormat");
    Raw raw;
    while (in.next(tok)) {
        if (tok.size() != 1 || tok[0].empty() || tok[0][0] != '$') in.fail("expected a section such as '$Nodes'");
        if (tok[0] == "$Nodes")
            v2 ? gmshNodesV2(in, raw) : gmshNodesV4(in, raw);
        else if (tok[0] == "$Elements")
            v2 ? gmshElementsV2(in, raw) : gmshElementsV4(in, raw);
        else
            skipSection(in, tok[0]);
    }
    return finish(raw, origin, scale);
}

namespace {

/// A minimal reader of the VTK XML elements the unstructured grid needs: the text of an element's
/// opening tag, its attributes and its character data.
struct VtuText {
    std::string_view text;
    const std::string& origin;

    [[noreturn]] void fail(const std::string& rule) const { throw InputError(origin + ": " + rule); }

    /// The value of attribute `name` in the tag text `tag` (empty when absent).
    static std::string attribute(std::string_view tag, std::string_view name) {
        for (size_t at = tag.find(name); at != std::string_view::npos; at = tag.find(name, at + 1)) {
            const bool starts = at > 0 && std::isspace(static_cast<unsigned char>(tag[at - 1]));
            size_t q = at + name.size();
            if (!starts || q + 1 >= tag.size() || tag[q] != '=' || (tag[q + 1] != '"' && tag[q + 1] != '\'')) continue;
            const char quote = tag[q + 1];
            const size_t end = tag.find(quote, q + 2);
            if (end == std::string_view::npos) return {};
            return std::string(tag.substr(q + 2, end - q - 2));
        }
        return {};
    }

    /// The DataArray inside `within` (a range of the text) whose Name is `name` (any when empty):
    /// its numbers, checked to be ASCII data.
    template <class T> std::vector<T> array(std::string_view within, std::string_view name, const char* what) const {
        for (size_t at = within.find("<DataArray"); at != std::string_view::npos;
             at = within.find("<DataArray", at + 1)) {
            const size_t close = within.find('>', at);
            if (close == std::string_view::npos) fail(std::string(what) + ": unterminated DataArray tag");
            const std::string_view tag = within.substr(at, close - at);
            if (!name.empty() && attribute(tag, "Name") != name) continue;
            const std::string format = attribute(tag, "format");
            if (format != "ascii")
                fail(std::string(what) + ": DataArray is format=\"" + format +
                     "\": only ascii data is read (ParaView: Save Data with Data Mode 'Ascii'; meshio: binary=False)");
            const size_t end = within.find("</DataArray>", close);
            if (end == std::string_view::npos) fail(std::string(what) + ": DataArray has no '</DataArray>'");
            return numbers<T>(within.substr(close + 1, end - close - 1), what);
        }
        fail(std::string(what) + ": no DataArray" + (name.empty() ? "" : " named '" + std::string(name) + "'"));
    }

    template <class T> std::vector<T> numbers(std::string_view data, const char* what) const {
        std::vector<T> out;
        size_t i = 0;
        while (i < data.size()) {
            while (i < data.size() && std::isspace(static_cast<unsigned char>(data[i])))
                ++i;
            size_t j = i;
            while (j < data.size() && !std::isspace(static_cast<unsigned char>(data[j])))
                ++j;
            if (j == i) break;
            T v{};
            const auto r = std::from_chars(data.data() + i, data.data() + j, v);
            if (r.ec != std::errc() || r.ptr != data.data() + j)
                fail(std::string(what) + ": value " + std::to_string(out.size()) + " '" +
                     std::string(data.substr(i, j - i)) + "' is not a valid number");
            if (static_cast<int64_t>(out.size()) >= kMaxCount) fail(std::string(what) + ": more than 2^28 values");
            out.push_back(v);
            i = j;
        }
        return out;
    }

    /// The text between `<open ...>` and `</open>`.
    std::string_view section(const std::string& open) const {
        std::string start = "<", close = "</";
        start += open;
        close += open;
        close += '>';
        const size_t at = text.find(start);
        if (at == std::string_view::npos) fail("has no " + start + "> element");
        const size_t end = text.find(close, at);
        if (end == std::string_view::npos) fail(start + "> is not closed");
        return text.substr(at, end - at);
    }
};

} // namespace

std::unique_ptr<TetMesh> parseVtuTets(std::string_view text, const std::string& origin, double scale) {
    const VtuText vtu{text, origin};
    const size_t head = text.find("<VTKFile");
    if (head == std::string_view::npos) vtu.fail("is not a VTK XML file (no <VTKFile> element)");
    const std::string type = VtuText::attribute(text.substr(head, text.find('>', head) - head), "type");
    if (type != "UnstructuredGrid") vtu.fail("VTKFile type is '" + type + "': an UnstructuredGrid (.vtu) is read");
    if (text.find("<AppendedData") != std::string_view::npos)
        vtu.fail("appended data is not read: save the .vtu as ASCII (ParaView: Data Mode 'Ascii')");
    size_t pieces = 0;
    for (size_t at = text.find("<Piece"); at != std::string_view::npos; at = text.find("<Piece", at + 1))
        ++pieces;
    if (pieces != 1) vtu.fail("has " + std::to_string(pieces) + " <Piece> elements: one is read (merge the pieces)");
    const auto points = vtu.array<double>(vtu.section("Points"), "", "Points");
    const std::string_view cells = vtu.section("Cells");
    const auto connectivity = vtu.array<int64_t>(cells, "connectivity", "Cells/connectivity");
    const auto offsets = vtu.array<int64_t>(cells, "offsets", "Cells/offsets");
    const auto types = vtu.array<int>(cells, "types", "Cells/types");
    if (points.size() % 3 != 0) vtu.fail("Points: " + std::to_string(points.size()) + " values are not x y z triples");
    if (offsets.size() != types.size())
        vtu.fail("Cells: " + std::to_string(offsets.size()) + " offsets for " + std::to_string(types.size()) +
                 " types");
    Raw raw;
    for (size_t i = 0; i < points.size() / 3; ++i) {
        const Vec3 p(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
        if (!p.allFinite()) vtu.fail("Points: point " + std::to_string(i) + " has a non-finite coordinate");
        raw.nodes[static_cast<int64_t>(i)] = p;
    }
    int64_t from = 0;
    for (size_t c = 0; c < types.size(); ++c) {
        const int64_t to = offsets[c];
        if (to < from || to > static_cast<int64_t>(connectivity.size()))
            vtu.fail("Cells/offsets: offset " + std::to_string(c) + " (" + std::to_string(to) + ") is out of order");
        // points, lines and surface cells are skipped; any other cell is refused (a hole otherwise)
        constexpr int kLower[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 21, 22, 23, 28, 30, 34, 35, 36, 68, 69, 70, 75, 76, 77};
        const bool lower = std::find(std::begin(kLower), std::end(kLower), types[c]) != std::end(kLower);
        if (types[c] == kVtkTet) {
            if (to - from != 4)
                vtu.fail("Cells: cell " + std::to_string(c) + " is a tetrahedron with " + std::to_string(to - from) +
                         " points");
            raw.tets.push_back({connectivity[size_t(from)], connectivity[size_t(from + 1)],
                                connectivity[size_t(from + 2)], connectivity[size_t(from + 3)]});
        } else if (!lower) {
            vtu.fail("Cells: cell " + std::to_string(c) + " is of VTK type " + std::to_string(types[c]) +
                     ": only linear tetrahedra (type 10) are read (points, lines and surfaces are skipped)");
        }
        from = to;
    }
    if (from != static_cast<int64_t>(connectivity.size()))
        vtu.fail("Cells/offsets: the last offset (" + std::to_string(from) + ") is not the connectivity's length (" +
                 std::to_string(connectivity.size()) + ")");
    return finish(raw, origin, scale);
}

namespace {

/// The extension of `path`, lower case, with the dot.
std::string lowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace

bool isTetFile(const std::filesystem::path& path) {
    const std::string ext = lowerExtension(path);
    return ext == ".msh" || ext == ".vtu" || ext == ".vtet";
}

std::unique_ptr<TetMesh> readTetFile(const std::filesystem::path& path, double scale) {
    const std::string ext = lowerExtension(path);
    const std::string origin = path.filename().string();
    constexpr std::uintmax_t kMaxBytes = std::uintmax_t{512} << 20;
    if (ext == ".msh") return parseGmshTets(readFile(path, kMaxBytes), origin, scale);
    if (ext == ".vtu") return parseVtuTets(readFile(path, kMaxBytes), origin, scale);
    if (ext == ".vtet") {
        Raw raw;
        const auto mesh = parseVtet(readFile(path, kMaxBytes), origin);
        for (size_t i = 0; i < mesh->vertexCount(); ++i)
            raw.nodes[static_cast<int64_t>(i)] = mesh->positions()[i];
        for (const Tet& t : mesh->tets())
            raw.tets.push_back({t[0], t[1], t[2], t[3]});
        return finish(raw, origin, scale);
    }
    throw InputError(origin + ": is not a tetrahedral mesh file (.msh, .vtu or .vtet)");
}

} // namespace viscera::sim
