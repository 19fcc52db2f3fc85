#include "bake/references.hpp"

#include "bake/format_check.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <cstdint>
#include <set>
#include <system_error>
#include <utility>

namespace viscera::bake::detail {
namespace {

constexpr std::uintmax_t kMaxMaterialLibraryBytes = std::uintmax_t{64} << 20;

bool isLetter(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

bool isSchemeChar(char c) {
    return isLetter(c) || (c >= '0' && c <= '9') || c == '+' || c == '-' || c == '.';
}

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

int hexValue(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    c = lower(c);
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

/// URI percent-decoding ("%2E" → '.'); a '%' not followed by two hex digits stays as it is.
std::string percentDecoded(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size()) {
            const int hi = hexValue(s[i + 1]), lo = hexValue(s[i + 2]);
            if (hi >= 0 && lo >= 0) {
                out.push_back(static_cast<char>(hi * 16 + lo));
                i += 2;
                continue;
            }
        }
        out.push_back(s[i]);
    }
    return out;
}

/// The statement's arguments: each token, and the whole rest of the line when it has several
/// (importers differ in whether a file name may hold blanks), each a reference to check.
void addStatement(std::vector<MeshReference>& out, const std::string& where, std::string_view rest) {
    const std::vector<std::string_view> tok = blankSeparatedTokens(rest);
    for (std::string_view t : tok)
        out.push_back({where, std::string(t)});
    if (tok.size() > 1) out.push_back({where, std::string(trim(rest))});
}

/// Line-based statements (OBJ, MTL) as assimp reads them: a line ends at LF, CR, FF or NUL; a
/// backslash at the end of a line joins the next one; '#' starts a comment only at the start of a
/// line (a statement takes the rest of its line, '#' included). `pick(first token)` selects the
/// statements to collect; more than kMaxStatements of them refuse the file.
constexpr size_t kMaxStatements = 10000;

template <class Pick>
std::vector<MeshReference> lineStatements(std::string_view b, const std::string& label, const std::string& prefix,
                                          const Pick& pick) {
    std::vector<MeshReference> out;
    auto isEnd = [](char c) { return c == '\n' || c == '\r' || c == '\f' || c == '\0'; };
    size_t pos = 0, lineNo = 1;
    std::string joined;
    while (pos < b.size()) {
        const size_t first = lineNo;
        joined.clear();
        for (;;) {
            size_t end = pos;
            while (end < b.size() && !isEnd(b[end]))
                ++end;
            std::string_view piece = b.substr(pos, end - pos);
            if (end < b.size() && b[end] == '\n') ++lineNo;
            pos = end + 1;
            const bool continued = !piece.empty() && piece.back() == '\\' && end < b.size();
            if (continued) piece.remove_suffix(1);
            joined.append(piece);
            if (!continued) break;
        }
        std::string_view line = trim(joined);
        if (line.empty() || line.front() == '#') continue;
        size_t k = 0;
        while (k < line.size() && !isBlank(line[k]))
            ++k;
        const std::string_view keyword = line.substr(0, k);
        if (!pick(keyword)) continue;
        if (out.size() >= 2 * kMaxStatements)
            throw InputError(label + ": " + prefix + "more than " + std::to_string(kMaxStatements) + " " +
                             sim::displayName(keyword) + " statements (the limit of a mesh file's references)");
        addStatement(out, prefix + "line " + std::to_string(first) + ": " + sim::displayName(keyword), line.substr(k));
    }
    return out;
}

/// Every string under a key "uri" anywhere in the document (glTF 2 buffers and images, glTF 1
/// buffers, images and shaders, extensions), with its JSON path; iterative, so depth costs no stack.
void collectUris(const nlohmann::json& doc, std::vector<MeshReference>& out) {
    std::vector<std::pair<const nlohmann::json*, std::string>> stack{{&doc, std::string()}};
    while (!stack.empty()) {
        auto [node, path] = std::move(stack.back());
        stack.pop_back();
        if (node->is_object()) {
            for (auto it = node->begin(); it != node->end(); ++it) {
                const std::string sub = path.empty() ? it.key() : path + "." + it.key();
                if (it.key() == "uri" && it->is_string()) {
                    const std::string& uri = it->get_ref<const std::string&>();
                    // Embedded data, exactly as assimp recognises it (case-sensitive); "DATA:" is a
                    // file name to assimp, and a scheme to the rule.
                    if (uri.rfind("data:", 0) != 0) out.push_back({sim::displayName(sub), uri});
                } else if (it->is_structured()) {
                    stack.emplace_back(&*it, sub);
                }
            }
        } else if (node->is_array()) {
            for (size_t i = 0; i < node->size(); ++i)
                if ((*node)[i].is_structured()) stack.emplace_back(&(*node)[i], path + "[" + std::to_string(i) + "]");
        }
    }
}

/// Refuses JSON nested deeper than kMaxJsonDepth before any parser sees it: assimp's glTF parser
/// (rapidjson) recurses per level, so a deep document would overflow its stack.
constexpr int kMaxJsonDepth = 64;

void checkJsonDepth(const std::string& label, std::string_view json) {
    int depth = 0;
    bool inString = false;
    for (size_t i = 0; i < json.size(); ++i) {
        const char c = json[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw InputError(label + ": JSON nested more than " + std::to_string(kMaxJsonDepth) +
                                 " levels deep at byte " + std::to_string(i) + " (the limit of a glTF document)");
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
}

} // namespace

std::optional<std::string> referenceProblem(std::string_view path) {
    if (path.empty()) return "empty reference";
    if (isBlank(path.front()) || isBlank(path.back()))
        return std::string("begins or ends with a blank (importers strip them differently)");
    for (char c : path)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return std::string("contains a control character");
    const size_t colon = path.find(':');
    if (colon != std::string_view::npos && colon >= 2 && isLetter(path[0])) {
        bool scheme = true;
        for (size_t i = 1; i < colon && scheme; ++i)
            scheme = isSchemeChar(path[i]);
        if (scheme)
            return "a URI scheme ('" + std::string(path.substr(0, colon + 1)) +
                   "') is refused, only relative paths are";
    }
    if (path.front() == '/' || path.front() == '\\') return std::string("absolute path");
    if (path.size() >= 2 && isLetter(path[0]) && path[1] == ':') return std::string("absolute path (drive letter)");
    size_t start = 0;
    while (start <= path.size()) {
        size_t end = path.find_first_of("/\\", start);
        if (end == std::string_view::npos) end = path.size();
        if (path.substr(start, end - start) == "..") return std::string("leaves the file's folder ('..' component)");
        start = end + 1;
    }
    return std::nullopt;
}

std::vector<MeshReference> materialReferences(const std::string& label, std::string_view bytes) {
    return lineStatements(bytes, label, "", [](std::string_view k) {
        return startsWithNoCase(k, "map_") || startsWithNoCase(k, "bump") || startsWithNoCase(k, "disp") ||
               startsWithNoCase(k, "decal") || startsWithNoCase(k, "refl") || startsWithNoCase(k, "norm");
    });
}

std::vector<MeshReference> meshReferences(const std::string& label, SurfaceFormat format, std::string_view bytes) {
    std::vector<MeshReference> out;
    switch (format) {
    case SurfaceFormat::Obj:
        return lineStatements(bytes, label, "", [](std::string_view k) { return k == "mtllib"; });
    case SurfaceFormat::Gltf:
        checkJsonDepth(label, bytes);
        collectUris(sim::parseJsonText(bytes, label), out);
        break;
    case SurfaceFormat::Glb: {
        if (bytes.size() < 20) break; // checkStructure refuses it
        const uint64_t length = readU32le(bytes, 12);
        if (20 + length > bytes.size()) break;
        checkJsonDepth(label + " (JSON chunk)", bytes.substr(20, length));
        collectUris(sim::parseJsonText(bytes.substr(20, length), label + " (JSON chunk)"), out);
        break;
    }
    case SurfaceFormat::StlAscii:
    case SurfaceFormat::StlBinary:
    case SurfaceFormat::Ply:
    case SurfaceFormat::Fbx:
        break;
    }
    if (format == SurfaceFormat::Gltf || format == SurfaceFormat::Glb) {
        // A URI is percent-encoded: the decoded form is what names the file.
        const size_t n = out.size();
        for (size_t i = 0; i < n; ++i) {
            std::string decoded = percentDecoded(out[i].path);
            if (decoded != out[i].path) out.push_back({out[i].where, std::move(decoded)});
        }
    }
    return out;
}

void checkReferences(const std::string& label, SurfaceFormat format, std::string_view bytes,
                     const std::filesystem::path& folder) {
    auto check = [&](const std::string& prefix, const std::vector<MeshReference>& refs) {
        for (const MeshReference& r : refs)
            if (const auto problem = referenceProblem(r.path))
                throw InputError(label + ": " + prefix + r.where + " '" + sim::displayName(r.path) + "': " + *problem +
                                 "; references must be relative paths inside the file's folder");
    };
    const std::vector<MeshReference> refs = meshReferences(label, format, bytes);
    check("", refs);
    if (format != SurfaceFormat::Obj) return;
    std::set<std::filesystem::path> read; // each library once, whatever the statements repeat
    for (const MeshReference& r : refs) {
        const std::filesystem::path lib = folder / r.path;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(lib, ec) || !sim::insideFolder(folder, lib)) continue;
        if (!read.insert(std::filesystem::weakly_canonical(lib, ec)).second) continue;
        std::string text;
        try {
            text = readFile(lib, kMaxMaterialLibraryBytes, "the material library limit of 64 MiB");
        } catch (const InputError& e) {
            throw InputError(label + ": " + r.where + ": " + e.what());
        }
        check(sim::displayName(r.path) + " ", materialReferences(label, text));
    }
}

} // namespace viscera::bake::detail
