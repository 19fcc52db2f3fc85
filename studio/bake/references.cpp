#include "bake/references.hpp"

#include "bake/format_check.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <cstdint>
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

char lower(char c) {
    return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
}

bool startsWithNoCase(std::string_view s, std::string_view prefix) {
    if (s.size() < prefix.size()) return false;
    for (size_t i = 0; i < prefix.size(); ++i)
        if (lower(s[i]) != lower(prefix[i])) return false;
    return true;
}

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && isBlank(s.front()))
        s.remove_prefix(1);
    while (!s.empty() && isBlank(s.back()))
        s.remove_suffix(1);
    return s;
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

/// Line-based statements (OBJ, MTL): `keyword(first token)` picks the statements to collect.
template <class Pick>
std::vector<MeshReference> lineStatements(std::string_view b, const std::string& prefix, const Pick& pick) {
    std::vector<MeshReference> out;
    size_t pos = 0, lineNo = 0;
    while (pos < b.size()) {
        size_t end = b.find('\n', pos);
        if (end == std::string_view::npos) end = b.size();
        ++lineNo;
        std::string_view line = b.substr(pos, end - pos);
        pos = end + 1;
        const size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
        line = trim(line);
        size_t k = 0;
        while (k < line.size() && !isBlank(line[k]))
            ++k;
        const std::string_view keyword = line.substr(0, k);
        if (keyword.empty() || !pick(keyword)) continue;
        addStatement(out, prefix + "line " + std::to_string(lineNo) + ": " + std::string(keyword), line.substr(k));
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
                    if (!startsWithNoCase(uri, "data:")) out.push_back({sub, uri});
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

uint32_t readU32le(std::string_view b, size_t at) {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
        v |= static_cast<uint32_t>(static_cast<unsigned char>(b[at + i])) << (8 * i);
    return v;
}

} // namespace

std::optional<std::string> referenceProblem(std::string_view path) {
    if (path.empty()) return "empty reference";
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

std::vector<MeshReference> materialReferences(std::string_view bytes) {
    return lineStatements(bytes, "", [](std::string_view k) {
        return startsWithNoCase(k, "map_") || startsWithNoCase(k, "bump") || startsWithNoCase(k, "disp") ||
               startsWithNoCase(k, "decal") || startsWithNoCase(k, "refl") || startsWithNoCase(k, "norm");
    });
}

std::vector<MeshReference> meshReferences(const std::string& label, SurfaceFormat format, std::string_view bytes) {
    std::vector<MeshReference> out;
    switch (format) {
    case SurfaceFormat::Obj:
        return lineStatements(bytes, "", [](std::string_view k) { return k == "mtllib"; });
    case SurfaceFormat::Gltf:
        collectUris(sim::parseJsonText(bytes, label), out);
        break;
    case SurfaceFormat::Glb: {
        if (bytes.size() < 20) break; // checkStructure refuses it
        const uint64_t length = readU32le(bytes, 12);
        if (20 + length > bytes.size()) break;
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

bool insideFolder(const std::filesystem::path& folder, const std::filesystem::path& file) {
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::weakly_canonical(folder.empty() ? "." : folder, ec);
    if (ec) return false;
    const std::filesystem::path target = std::filesystem::weakly_canonical(file, ec);
    if (ec) return false;
    auto b = base.begin(), t = target.begin();
    for (; b != base.end(); ++b, ++t)
        if (t == target.end() || *b != *t) return false;
    return true;
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
    for (const MeshReference& r : refs) {
        const std::filesystem::path lib = folder / r.path;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(lib, ec) || !insideFolder(folder, lib)) continue;
        const std::string text = readFile(lib, kMaxMaterialLibraryBytes, "the material library limit of 64 MiB");
        check(sim::displayName(r.path) + " ", materialReferences(text));
    }
}

} // namespace viscera::bake::detail
