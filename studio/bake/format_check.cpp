#include "bake/format_check.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

namespace viscera::bake::detail {

// ---- text and byte helpers, shared with references.cpp (format_check.hpp) ----------------

std::string_view trimLeft(std::string_view s) {
    while (!s.empty() && isSpace(s.front()))
        s.remove_prefix(1);
    return s;
}

bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

char lower(char c) {
    return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
}

std::string_view trim(std::string_view s) {
    s = trimLeft(s);
    while (!s.empty() && isSpace(s.back()))
        s.remove_suffix(1);
    return s;
}

bool startsWithNoCase(std::string_view s, std::string_view prefix) {
    if (s.size() < prefix.size()) return false;
    for (size_t i = 0; i < prefix.size(); ++i)
        if (lower(s[i]) != lower(prefix[i])) return false;
    return true;
}

uint32_t readU32le(std::string_view b, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i)
        v = (v << 8) | static_cast<unsigned char>(b[at + i]);
    return v;
}

namespace {

[[noreturn]] void fail(const std::string& label, const std::string& message) {
    throw InputError(label + ": " + message);
}

// ---- small text helpers --------------------------------------------------------------------

std::string_view skipBom(std::string_view s) {
    if (s.size() >= 3 && s.substr(0, 3) == "\xEF\xBB\xBF") s.remove_prefix(3);
    return s;
}

/// Splits on blanks; returns the tokens (views into s).
std::vector<std::string_view> tokens(std::string_view s) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && isSpace(s[i]))
            ++i;
        size_t j = i;
        while (j < s.size() && !isSpace(s[j]))
            ++j;
        if (j > i) out.push_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

/// Quotes a token for a message, shortened and with control bytes replaced.
std::string quoted(std::string_view tok) {
    std::string out = "'";
    for (size_t i = 0; i < tok.size() && i < 32; ++i) {
        unsigned char c = static_cast<unsigned char>(tok[i]);
        out += (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
    }
    if (tok.size() > 32) out += "...";
    return out + "'";
}

std::optional<double> parseDouble(std::string_view tok) {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    double v = 0;
    auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ptr != tok.data() + tok.size()) return std::nullopt;
    if (ec == std::errc::result_out_of_range) {
        // Too large or too small for a double: an underflow (negative exponent) reads as zero,
        // an overflow as infinity so that the finiteness rule names it.
        const size_t e = tok.find_first_of("eE");
        if (e != std::string_view::npos && e + 1 < tok.size() && tok[e + 1] == '-') return 0.0;
        return tok.front() == '-' ? -HUGE_VAL : HUGE_VAL;
    }
    if (ec != std::errc()) return std::nullopt;
    return v;
}

std::optional<int64_t> parseInt(std::string_view tok) {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    int64_t v = 0;
    auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || ptr != tok.data() + tok.size()) return std::nullopt;
    return v;
}

float readF32le(std::string_view b, size_t at) {
    return std::bit_cast<float>(readU32le(b, at));
}

// ---- content sniffing ------------------------------------------------------------------------

/// Each test returns an empty string when the content matches, else the rule it broke.
std::string objRule(std::string_view b) {
    size_t nul = b.find('\0');
    if (nul != std::string_view::npos) return "expected text, found a NUL byte at offset " + std::to_string(nul);
    size_t pos = 0;
    while (pos < b.size()) {
        size_t end = b.find('\n', pos);
        if (end == std::string_view::npos) end = b.size();
        std::string_view line = trimLeft(b.substr(pos, end - pos));
        if (line.size() >= 2 && line[0] == 'v' && (line[1] == ' ' || line[1] == '\t')) return {};
        pos = end + 1;
    }
    return "expected text with 'v x y z' vertex lines, found none";
}

bool isBinaryStl(std::string_view b) {
    if (b.size() < 84) return false;
    uint64_t n = readU32le(b, 80);
    return b.size() == 84 + 50 * n;
}

bool isAsciiStl(std::string_view b) {
    return startsWithNoCase(trimLeft(skipBom(b)), "solid") && b.find('\0') == std::string_view::npos;
}

std::string stlRule(std::string_view b) {
    if (isBinaryStl(b) || isAsciiStl(b)) return {};
    std::string rule = "expected ASCII text starting with 'solid', or binary data of 84 + 50*n bytes "
                       "for the n triangles its header declares; the file has " +
                       std::to_string(b.size()) + " bytes";
    if (b.size() >= 84) rule += " and its header declares n = " + std::to_string(readU32le(b, 80));
    return rule;
}

bool isPly(std::string_view b) {
    return b.substr(0, 4) == "ply\n" || b.substr(0, 5) == "ply\r\n";
}

std::string plyRule(std::string_view b) {
    return isPly(b) ? std::string{} : "expected the 'ply' magic line at the start";
}

bool isGlb(std::string_view b) {
    return b.size() >= 4 && b.substr(0, 4) == "glTF";
}

std::string glbRule(std::string_view b) {
    return isGlb(b) ? std::string{} : "expected the 'glTF' magic in the first 4 bytes";
}

bool isGltf(std::string_view b) {
    std::string_view s = trimLeft(skipBom(b));
    if (s.empty() || s.front() != '{' || b.find('\0') != std::string_view::npos) return false;
    size_t pos = 0;
    while ((pos = s.find("\"asset\"", pos)) != std::string_view::npos) {
        pos += 7;
        std::string_view rest = trimLeft(s.substr(pos));
        if (!rest.empty() && rest.front() == ':') return true;
    }
    return false;
}

std::string gltfRule(std::string_view b) {
    return isGltf(b) ? std::string{} : "expected a JSON object with an \"asset\" key";
}

bool isBinaryFbx(std::string_view b) {
    return b.substr(0, 18) == "Kaydara FBX Binary";
}

bool isAsciiFbx(std::string_view b) {
    return trimLeft(skipBom(b)).substr(0, 5) == "; FBX" && b.find('\0') == std::string_view::npos;
}

std::string fbxRule(std::string_view b) {
    return (isBinaryFbx(b) || isAsciiFbx(b)) ? std::string{}
                                             : "expected the 'Kaydara FBX Binary' magic or an ASCII '; FBX' header";
}

struct FormatEntry {
    std::string_view extension;
    std::string_view family; ///< name used in "does not look like ..."
    std::string (*rule)(std::string_view);
};

constexpr std::array<FormatEntry, 6> kFormats{{
    {".obj", "OBJ", objRule},
    {".stl", "STL", stlRule},
    {".ply", "PLY", plyRule},
    {".gltf", "glTF", gltfRule},
    {".glb", "GLB", glbRule},
    {".fbx", "FBX", fbxRule},
}};

std::string acceptedList() {
    std::string s;
    for (const auto& f : kFormats) {
        if (!s.empty()) s += ' ';
        s += f.extension;
    }
    return s;
}

// ---- OBJ -----------------------------------------------------------------------------------

struct ObjRef {
    size_t line;
    size_t face;
    int64_t index;
    char kind; // 'v', 't', 'n'
};

const char* objKindName(char kind) {
    return kind == 'v' ? "vertex" : kind == 't' ? "texture coordinate" : "normal";
}

std::string objCount(size_t n, char kind) {
    const char* plural = kind == 'v' ? "vertices" : kind == 't' ? "texture coordinates" : "normals";
    return std::to_string(n) + " " + (n == 1 ? objKindName(kind) : plural);
}

/// A 'v' line: at least x y z, each a finite number.
void checkObjVertex(const std::string& where, size_t vi, const std::vector<std::string_view>& tok) {
    if (tok.size() < 4)
        throw InputError(where + "vertex " + std::to_string(vi) + " has " + std::to_string(tok.size() - 1) +
                         " coordinates (needs x y z)");
    for (int k = 1; k <= 3; ++k) {
        const auto v = parseDouble(tok[k]);
        if (!v)
            throw InputError(where + "vertex " + std::to_string(vi) + ": cannot parse coordinate " + quoted(tok[k]) +
                             " as a number");
        if (!std::isfinite(*v))
            throw InputError(where + "vertex " + std::to_string(vi) + " has a non-finite coordinate (" +
                             std::string(tok[k]) + "); coordinates must be finite");
    }
}

void checkObj(const std::string& label, std::string_view b) {
    size_t counts[3] = {0, 0, 0}; // v, vt, vn
    size_t faces = 0, polygons = 0;
    std::vector<ObjRef> forward; // positive references beyond what was defined so far
    std::string joined;          // a logical line built from '\' continuations
    size_t pos = 0, lineNo = 0;
    while (pos < b.size()) {
        size_t end = b.find('\n', pos);
        if (end == std::string_view::npos) end = b.size();
        ++lineNo;
        const size_t firstLine = lineNo;
        std::string_view raw = b.substr(pos, end - pos);
        pos = end + 1;
        std::string_view line = raw;
        joined.clear();
        while (!trim(line).empty() && trim(line).back() == '\\' && pos < b.size()) {
            joined.append(trim(line).substr(0, trim(line).size() - 1)).push_back(' ');
            end = b.find('\n', pos);
            if (end == std::string_view::npos) end = b.size();
            ++lineNo;
            line = b.substr(pos, end - pos);
            pos = end + 1;
        }
        if (!joined.empty()) {
            joined.append(line);
            line = joined;
        }
        const size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
        const std::vector<std::string_view> tok = tokens(line);
        if (tok.empty()) continue;
        const std::string where = label + ": line " + std::to_string(firstLine) + ": ";
        if (tok[0] == "v") {
            checkObjVertex(where, ++counts[0], tok);
        } else if (tok[0] == "vt") {
            ++counts[1];
        } else if (tok[0] == "vn") {
            ++counts[2];
        } else if (tok[0] == "f") {
            const size_t fi = ++faces;
            const std::string faceWhere = where + "face " + std::to_string(fi);
            for (size_t c = 1; c < tok.size(); ++c) {
                std::string_view corner = tok[c];
                std::string_view parts[3];
                int nparts = 0;
                while (true) {
                    if (nparts == 3)
                        throw InputError(faceWhere + ": cannot parse corner " + quoted(tok[c]) +
                                         " (expected v, v/vt, v//vn or v/vt/vn)");
                    const size_t slash = corner.find('/');
                    parts[nparts++] = corner.substr(0, slash);
                    if (slash == std::string_view::npos) break;
                    corner.remove_prefix(slash + 1);
                }
                for (int k = 0; k < nparts; ++k) {
                    if (parts[k].empty() && k > 0) continue; // "v//vn" or a trailing "/"
                    const char kind = "vtn"[k];
                    const auto idx = parseInt(parts[k]);
                    if (!idx)
                        throw InputError(faceWhere + ": cannot parse " + objKindName(kind) + " index " +
                                         quoted(parts[k]));
                    if (*idx == 0)
                        throw InputError(faceWhere + ": " + objKindName(kind) +
                                         " index 0 is invalid (OBJ indices start at 1)");
                    const size_t have = counts[k];
                    if (*idx < 0) {
                        if (static_cast<uint64_t>(-(*idx + 1)) >= have)
                            throw InputError(faceWhere + ": " + objKindName(kind) + " index " + std::to_string(*idx) +
                                             " is out of range (only " + objCount(have, kind) + " defined before it)");
                    } else if (static_cast<uint64_t>(*idx) > have) {
                        forward.push_back({firstLine, fi, *idx, kind});
                    }
                }
            }
            if (tok.size() - 1 >= 3) ++polygons;
        }
    }
    for (const ObjRef& r : forward) {
        const size_t have = counts[r.kind == 'v' ? 0 : r.kind == 't' ? 1 : 2];
        if (static_cast<uint64_t>(r.index) > have)
            throw InputError(label + ": line " + std::to_string(r.line) + ": face " + std::to_string(r.face) + ": " +
                             objKindName(r.kind) + " index " + std::to_string(r.index) +
                             " is out of range (the file has " + objCount(have, r.kind) + ")");
    }
    if (polygons == 0) fail(label, "no faces: the file has no 'f' line with 3 or more vertices");
}

// ---- STL -----------------------------------------------------------------------------------

void checkStlBinary(const std::string& label, std::string_view b) {
    const uint32_t n = readU32le(b, 80);
    if (n == 0) fail(label, "no faces: the binary STL header declares 0 triangles");
    for (uint32_t t = 0; t < n; ++t) {
        const size_t rec = 84 + size_t{50} * t;
        for (int corner = 0; corner < 3; ++corner) {
            for (int k = 0; k < 3; ++k) {
                const float v = readF32le(b, rec + 12 + 12 * corner + 4 * k);
                if (!std::isfinite(v))
                    fail(label, "facet " + std::to_string(t) + " vertex " + std::to_string(corner) +
                                    " has a non-finite coordinate (" + sim::formatNumber(v) +
                                    "); coordinates must be finite");
            }
        }
    }
}

void checkStlAscii(const std::string& label, std::string_view b) {
    const std::vector<std::string_view> tok = tokens(skipBom(b));
    size_t facets = 0, corner = 0;
    for (size_t i = 0; i < tok.size(); ++i) {
        if (tok[i] == "facet") {
            ++facets;
            corner = 0;
        } else if (tok[i] == "vertex") {
            if (i + 3 >= tok.size())
                fail(label, "facet " + std::to_string(facets == 0 ? 0 : facets - 1) +
                                ": 'vertex' is followed by fewer than 3 coordinates (truncated)");
            for (int k = 1; k <= 3; ++k) {
                const auto v = parseDouble(tok[i + k]);
                const std::string where =
                    "facet " + std::to_string(facets == 0 ? 0 : facets - 1) + " vertex " + std::to_string(corner);
                if (!v) fail(label, where + ": cannot parse coordinate " + quoted(tok[i + k]) + " as a number");
                if (!std::isfinite(*v))
                    fail(label, where + " has a non-finite coordinate (" + std::string(tok[i + k]) +
                                    "); coordinates must be finite");
            }
            ++corner;
            i += 3;
        }
    }
    if (facets == 0) fail(label, "no faces: the ASCII STL has no 'facet' entries");
}

// ---- PLY -----------------------------------------------------------------------------------

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<PlyType> plyType(std::string_view s) {
    struct Name {
        std::string_view name;
        PlyType type;
    };
    static constexpr Name names[] = {
        {"char", PlyType::Int8},       {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
        {"uint8", PlyType::UInt8},     {"short", PlyType::Int16},     {"int16", PlyType::Int16},
        {"ushort", PlyType::UInt16},   {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
        {"int32", PlyType::Int32},     {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32},   {"float32", PlyType::Float32}, {"double", PlyType::Float64},
        {"float64", PlyType::Float64},
    };
    for (const Name& n : names)
        if (n.name == s) return n.type;
    return std::nullopt;
}

size_t plySize(PlyType t) {
    switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8:
        return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
        return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
        return 4;
    case PlyType::Float64:
        return 8;
    }
    return 1;
}

bool plyIsInteger(PlyType t) {
    return t != PlyType::Float32 && t != PlyType::Float64;
}

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32; ///< item type for a list
    bool list = false;
    PlyType countType = PlyType::UInt8;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
};

enum class PlyEncoding { Ascii, BinaryLE, BinaryBE };

/// Reads scalar values from the body of a PLY file, ASCII or binary.
class PlyBodyReader {
public:
    PlyBodyReader(std::string_view body, PlyEncoding enc) : m_body(body), m_enc(enc) {}

    /// False when the body ends before the value.
    bool read(PlyType type, double& out, std::string_view& badToken) {
        if (m_enc == PlyEncoding::Ascii) return readAscii(type, out, badToken);
        const size_t n = plySize(type);
        if (m_pos + n > m_body.size()) return false;
        unsigned char raw[8];
        std::memcpy(raw, m_body.data() + m_pos, n);
        m_pos += n;
        const bool bigEndianData = m_enc == PlyEncoding::BinaryBE;
        if (bigEndianData != (std::endian::native == std::endian::big)) std::reverse(raw, raw + n);
        switch (type) {
        case PlyType::Int8:
            out = static_cast<int8_t>(raw[0]);
            break;
        case PlyType::UInt8:
            out = raw[0];
            break;
        case PlyType::Int16:
            out = load<int16_t>(raw);
            break;
        case PlyType::UInt16:
            out = load<uint16_t>(raw);
            break;
        case PlyType::Int32:
            out = load<int32_t>(raw);
            break;
        case PlyType::UInt32:
            out = load<uint32_t>(raw);
            break;
        case PlyType::Float32:
            out = load<float>(raw);
            break;
        case PlyType::Float64:
            out = load<double>(raw);
            break;
        }
        return true;
    }

    /// Set when read() returned true but the ASCII token did not parse.
    bool parseError() const { return m_parseError; }

private:
    template <class T> static T load(const unsigned char* raw) {
        T v;
        std::memcpy(&v, raw, sizeof v);
        return v;
    }

    bool readAscii(PlyType type, double& out, std::string_view& badToken) {
        while (m_pos < m_body.size() && isSpace(m_body[m_pos]))
            ++m_pos;
        if (m_pos >= m_body.size()) return false;
        size_t end = m_pos;
        while (end < m_body.size() && !isSpace(m_body[end]))
            ++end;
        const std::string_view tok = m_body.substr(m_pos, end - m_pos);
        m_pos = end;
        m_parseError = false;
        if (plyIsInteger(type)) {
            const auto v = parseInt(tok);
            if (!v) {
                m_parseError = true;
                badToken = tok;
                return true;
            }
            out = static_cast<double>(*v);
        } else {
            const auto v = parseDouble(tok);
            if (!v) {
                m_parseError = true;
                badToken = tok;
                return true;
            }
            out = *v;
        }
        return true;
    }

    std::string_view m_body;
    PlyEncoding m_enc;
    size_t m_pos = 0;
    bool m_parseError = false;
};

/// The PLY header: the body's encoding, the declared elements, and where the body starts.
struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::Ascii;
    std::vector<PlyElement> elements;
    size_t bodyStart = 0;
};

PlyEncoding parsePlyFormat(const std::string& label, const std::string& where,
                           const std::vector<std::string_view>& tok) {
    if (tok.size() < 2) fail(label, where + "'format' needs an encoding");
    if (tok[1] == "ascii") return PlyEncoding::Ascii;
    if (tok[1] == "binary_little_endian") return PlyEncoding::BinaryLE;
    if (tok[1] == "binary_big_endian") return PlyEncoding::BinaryBE;
    fail(label, where + "unknown encoding " + quoted(tok[1]) + " (ascii, binary_little_endian or binary_big_endian)");
}

PlyElement parsePlyElement(const std::string& label, const std::string& where,
                           const std::vector<std::string_view>& tok) {
    if (tok.size() != 3) fail(label, where + "expected 'element <name> <count>'");
    const auto count = parseInt(tok[2]);
    if (!count || *count < 0) fail(label, where + "element count " + quoted(tok[2]) + " is not a non-negative integer");
    return {std::string(tok[1]), static_cast<uint64_t>(*count), {}};
}

PlyProperty parsePlyProperty(const std::string& label, const std::string& where,
                             const std::vector<std::string_view>& tok) {
    if (tok.size() >= 2 && tok[1] == "list") {
        if (tok.size() != 5) fail(label, where + "expected 'property list <count type> <item type> <name>'");
        const auto ct = plyType(tok[2]);
        const auto it = plyType(tok[3]);
        if (!ct || !plyIsInteger(*ct))
            fail(label, where + "list count type " + quoted(tok[2]) + " is not an integer type");
        if (!it) fail(label, where + "unknown property type " + quoted(tok[3]));
        return {std::string(tok[4]), *it, true, *ct};
    }
    if (tok.size() != 3) fail(label, where + "expected 'property <type> <name>'");
    const auto t = plyType(tok[1]);
    if (!t) fail(label, where + "unknown property type " + quoted(tok[1]));
    return {std::string(tok[2]), *t, false, PlyType::UInt8};
}

PlyHeader parsePlyHeader(const std::string& label, std::string_view b) {
    // Header: "ply", format, elements with properties, end_header.
    std::optional<PlyEncoding> encoding;
    PlyHeader header;
    std::vector<PlyElement>& elements = header.elements;
    size_t pos = 0, lineNo = 0;
    bool ended = false;
    while (pos < b.size()) {
        size_t end = b.find('\n', pos);
        if (end == std::string_view::npos) end = b.size();
        const std::string_view line = b.substr(pos, end - pos);
        pos = end + 1;
        ++lineNo;
        const std::string where = "PLY header line " + std::to_string(lineNo) + ": ";
        const std::vector<std::string_view> tok = tokens(line);
        if (lineNo == 1) continue; // the "ply" magic, checked by the sniffer
        if (tok.empty()) continue;
        const std::string_view key = tok[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            ended = true;
            break;
        }
        if (key == "format") {
            encoding = parsePlyFormat(label, where, tok);
        } else if (key == "element") {
            elements.push_back(parsePlyElement(label, where, tok));
        } else if (key == "property") {
            if (elements.empty()) fail(label, where + "'property' before any 'element'");
            elements.back().props.push_back(parsePlyProperty(label, where, tok));
        } else {
            fail(label, where + "unknown keyword " + quoted(key));
        }
    }
    if (!ended) fail(label, "PLY header has no 'end_header' line (truncated or not a PLY file)");
    if (!encoding) fail(label, "PLY header has no 'format' line");
    header.encoding = *encoding;
    header.bodyStart = std::min(pos, b.size());
    return header;
}

/// Pointers into PlyHeader::elements.
struct PlyGeometry {
    const PlyElement* vertexElem = nullptr;
    const PlyElement* faceElem = nullptr;
    const PlyProperty* indexProp = nullptr;
};

PlyGeometry findPlyGeometry(const std::string& label, const std::vector<PlyElement>& elements) {
    // Which element/properties carry the geometry.
    const PlyElement* vertexElem = nullptr;
    const PlyElement* faceElem = nullptr;
    for (const PlyElement& e : elements) {
        if (e.name == "vertex" && !vertexElem) vertexElem = &e;
        if (e.name == "face" && !faceElem) faceElem = &e;
    }
    auto hasScalar = [](const PlyElement* e, std::string_view name) {
        for (const PlyProperty& p : e->props)
            if (p.name == name && !p.list) return true;
        return false;
    };
    if (!vertexElem || !hasScalar(vertexElem, "x") || !hasScalar(vertexElem, "y") || !hasScalar(vertexElem, "z"))
        fail(label, "PLY header declares no 'vertex' element with x, y, z properties");
    if (!faceElem) fail(label, "no faces: the PLY header declares no 'face' element");
    if (faceElem->count == 0) fail(label, "no faces: the PLY header declares 0 faces");
    const PlyProperty* indexProp = nullptr;
    for (const PlyProperty& p : faceElem->props)
        if (p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) indexProp = &p;
    if (!indexProp) fail(label, "PLY 'face' element has no 'vertex_indices' list property");
    if (!plyIsInteger(indexProp->type))
        fail(label, "PLY face property '" + indexProp->name + "' has a non-integer item type");
    return {vertexElem, faceElem, indexProp};
}

/// Returns the number of faces with 3 or more vertices.
uint64_t checkPlyBody(const std::string& label, std::string_view b, const PlyHeader& header,
                      const PlyGeometry& geometry) {
    // Body: every declared element must be present; geometry must be finite and in range.
    PlyBodyReader reader(b.substr(header.bodyStart), header.encoding);
    const uint64_t vertexCount = geometry.vertexElem->count;
    uint64_t polygons = 0;
    for (const PlyElement& e : header.elements) {
        if (e.props.empty()) continue;
        const bool isVertex = &e == geometry.vertexElem;
        const bool isFace = &e == geometry.faceElem;
        for (uint64_t i = 0; i < e.count; ++i) {
            auto where = [&] { return "PLY element '" + e.name + "' " + std::to_string(i); };
            auto truncated = [&]() {
                fail(label, "PLY data ends inside element '" + e.name + "' " + std::to_string(i) + " of " +
                                std::to_string(e.count) + " (truncated)");
            };
            auto get = [&](PlyType t, double& v) {
                std::string_view bad;
                if (!reader.read(t, v, bad)) truncated();
                if (reader.parseError())
                    fail(label, where() + ": cannot parse " + quoted(bad) + " as " +
                                    (plyIsInteger(t) ? "an integer" : "a number"));
            };
            for (const PlyProperty& p : e.props) {
                double v = 0;
                if (!p.list) {
                    get(p.type, v);
                    if (isVertex && (p.name == "x" || p.name == "y" || p.name == "z") && !std::isfinite(v))
                        fail(label, "vertex " + std::to_string(i) + " has a non-finite " + p.name + " coordinate (" +
                                        sim::formatNumber(v) + "); coordinates must be finite");
                    continue;
                }
                double nd = 0;
                get(p.countType, nd);
                if (nd < 0) fail(label, where() + ": list '" + p.name + "' has a negative length");
                const uint64_t n = static_cast<uint64_t>(nd);
                const bool indices = isFace && &p == geometry.indexProp;
                for (uint64_t k = 0; k < n; ++k) {
                    get(p.type, v);
                    if (indices && (v < 0 || v >= static_cast<double>(vertexCount)))
                        fail(label, "face " + std::to_string(i) + ": index " + std::to_string(k) +
                                        " references vertex " + sim::formatNumber(v) + " (the file has " +
                                        std::to_string(vertexCount) + " vertices)");
                }
                if (indices && n >= 3) ++polygons;
            }
        }
    }
    return polygons;
}

void checkPly(const std::string& label, std::string_view b) {
    const PlyHeader header = parsePlyHeader(label, b);
    const PlyGeometry geometry = findPlyGeometry(label, header.elements);
    const uint64_t polygons = checkPlyBody(label, b, header, geometry);
    if (polygons == 0) fail(label, "no faces: no PLY face has 3 or more vertices");
}

// ---- GLB -----------------------------------------------------------------------------------

void checkGlb(const std::string& label, std::string_view b) {
    if (b.size() < 20)
        fail(label, "GLB file is " + std::to_string(b.size()) +
                        " bytes, shorter than its 12-byte header and first chunk header "
                        "(truncated)");
    const uint32_t version = readU32le(b, 4);
    const uint32_t length = readU32le(b, 8);
    if (version != 1 && version != 2)
        fail(label, "GLB version " + std::to_string(version) + " is not supported (1 or 2)");
    if (length != b.size())
        fail(label, "GLB header declares " + std::to_string(length) + " bytes but the file has " +
                        std::to_string(b.size()) + " (truncated or corrupt)");
    const uint64_t chunk = readU32le(b, 12);
    if (20 + chunk > b.size())
        fail(label, "GLB first chunk of " + std::to_string(chunk) + " bytes runs past the end of the file");
    if (version == 2 && b.substr(16, 4) != "JSON") fail(label, "GLB first chunk is not of type 'JSON'");
}

} // namespace

std::vector<std::string_view> blankSeparatedTokens(std::string_view s) {
    return tokens(s);
}

std::string lowerExtension(const std::filesystem::path& file) {
    std::string ext = file.extension().string();
    for (char& c : ext)
        c = lower(c);
    return ext;
}

void checkExtension(const std::string& label, std::string_view extension) {
    for (const auto& f : kFormats)
        if (f.extension == extension) return;
    fail(label, (extension.empty() ? std::string("unsupported format (no extension)")
                                   : "unsupported format " + quoted(extension)) +
                    " (accepted: " + acceptedList() + ")");
}

SurfaceFormat sniffFormat(const std::string& label, std::string_view extension, std::string_view bytes) {
    checkExtension(label, extension);
    const FormatEntry* entry = nullptr;
    for (const auto& f : kFormats)
        if (f.extension == extension) entry = &f;
    if (bytes.empty()) fail(label, "file is empty (0 bytes)");
    const std::string rule = entry->rule(bytes);
    if (!rule.empty()) {
        std::string msg = "content does not look like " + std::string(entry->family) + " (" + rule + ")";
        for (const auto& other : kFormats)
            if (&other != entry && other.rule(bytes).empty()) {
                msg += "; it looks like " + std::string(other.family) + ", rename it to " +
                       std::string(other.extension) + "?";
                break;
            }
        fail(label, msg);
    }
    if (extension == ".obj") return SurfaceFormat::Obj;
    if (extension == ".stl") return isBinaryStl(bytes) ? SurfaceFormat::StlBinary : SurfaceFormat::StlAscii;
    if (extension == ".ply") return SurfaceFormat::Ply;
    if (extension == ".gltf") return SurfaceFormat::Gltf;
    if (extension == ".glb") return SurfaceFormat::Glb;
    return SurfaceFormat::Fbx;
}

void checkStructure(const std::string& label, SurfaceFormat format, std::string_view bytes) {
    switch (format) {
    case SurfaceFormat::Obj:
        checkObj(label, bytes);
        break;
    case SurfaceFormat::StlBinary:
        checkStlBinary(label, bytes);
        break;
    case SurfaceFormat::StlAscii:
        checkStlAscii(label, bytes);
        break;
    case SurfaceFormat::Ply:
        checkPly(label, bytes);
        break;
    case SurfaceFormat::Glb:
        checkGlb(label, bytes);
        break;
    case SurfaceFormat::Gltf:
    case SurfaceFormat::Fbx:
        break;
    }
}

} // namespace viscera::bake::detail
