#include "sim/util/entry_name.hpp"

namespace viscera::sim {
namespace {

bool isPortable(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
}

std::string hexByte(unsigned char c) {
    static constexpr char kHex[] = "0123456789abcdef";
    return std::string("\\x") + kHex[c >> 4] + kHex[c & 0xf];
}

} // namespace

std::optional<std::string> entryNameProblem(std::string_view path) {
    if (path.empty()) return "empty entry name";
    if (path.size() > kMaxEntryNameBytes)
        return "entry name is " + std::to_string(path.size()) + " bytes, longer than the limit of " +
               std::to_string(kMaxEntryNameBytes);
    if (path.front() == '/') return "absolute entry path";
    bool letter = (path[0] >= 'A' && path[0] <= 'Z') || (path[0] >= 'a' && path[0] <= 'z');
    if (path.size() >= 2 && letter && path[1] == ':') return "absolute entry path (drive letter)";
    if (path.find('\\') != std::string_view::npos) return "entry name contains a backslash (paths use '/')";
    size_t start = 0;
    while (start <= path.size()) {
        size_t end = path.find('/', start);
        if (end == std::string_view::npos) end = path.size();
        std::string_view component = path.substr(start, end - start);
        if (component == "..") return "entry name escapes the package ('..' component)";
        if (component.empty()) return "entry name has an empty component ('//' or a trailing '/')";
        if (component == ".") return "entry name has a '.' component";
        start = end + 1;
    }
    for (char c : path)
        if (c != '/' && !isPortable(c))
            return "entry name contains the character " + hexByte(static_cast<unsigned char>(c)) +
                   " (allowed: A-Z a-z 0-9 . _ - and '/' between components)";
    return std::nullopt;
}

std::string displayName(std::string_view name) {
    std::string out;
    for (size_t i = 0; i < name.size() && i < kMaxEntryNameBytes; ++i) {
        unsigned char c = static_cast<unsigned char>(name[i]);
        if (c < 0x20 || c >= 0x7f)
            out += hexByte(c);
        else
            out += static_cast<char>(c);
    }
    if (name.size() > kMaxEntryNameBytes) out += "...";
    return out;
}

bool insideFolder(const std::filesystem::path& folder, const std::filesystem::path& file) {
    std::error_code ec;
    std::filesystem::path base = std::filesystem::weakly_canonical(folder.empty() ? "." : folder, ec);
    if (ec) return false;
    if (base.filename().empty()) base = base.parent_path(); // "dir/": no empty last component
    const std::filesystem::path target = std::filesystem::weakly_canonical(file, ec);
    if (ec) return false;
    auto b = base.begin(), t = target.begin();
    for (; b != base.end(); ++b, ++t)
        if (t == target.end() || *b != *t) return false;
    return true;
}

} // namespace viscera::sim
