#include "case/semver.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace viscera::vcase {
namespace {

bool isDigits(std::string_view s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool isIdentifierChar(char c) {
    return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '-';
}

/// A MAJOR/MINOR/PATCH field: digits, no leading zero, fits in 64 bits.
std::optional<uint64_t> parseNumber(std::string_view s) {
    if (!isDigits(s) || (s.size() > 1 && s[0] == '0')) return std::nullopt;
    uint64_t value = 0;
    for (char c : s) {
        uint64_t digit = static_cast<uint64_t>(c - '0');
        if (value > (UINT64_MAX - digit) / 10) return std::nullopt;
        value = value * 10 + digit;
    }
    return value;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    size_t start = 0;
    while (true) {
        size_t end = s.find(sep, start);
        parts.push_back(s.substr(start, end == std::string_view::npos ? end : end - start));
        if (end == std::string_view::npos) return parts;
        start = end + 1;
    }
}

/// Dot-separated identifiers; pre-release numeric identifiers must not have leading zeros.
bool validIdentifiers(std::string_view s, bool prerelease) {
    for (std::string_view id : split(s, '.')) {
        if (id.empty() || !std::all_of(id.begin(), id.end(), isIdentifierChar)) return false;
        if (prerelease && isDigits(id) && id.size() > 1 && id[0] == '0') return false;
    }
    return true;
}

std::strong_ordering compareIdentifier(std::string_view a, std::string_view b) {
    bool an = isDigits(a), bn = isDigits(b);
    if (an && bn) {
        // No leading zeros, so a longer number is larger; equal lengths compare as text.
        if (a.size() != b.size()) return a.size() <=> b.size();
        return a.compare(b) <=> 0;
    }
    if (an != bn) return an ? std::strong_ordering::less : std::strong_ordering::greater;
    return a.compare(b) <=> 0;
}

} // namespace

std::optional<SemVer> SemVer::parse(std::string_view text) {
    SemVer v;
    size_t plus = text.find('+');
    if (plus != std::string_view::npos) {
        v.build = std::string(text.substr(plus + 1));
        if (!validIdentifiers(v.build, false)) return std::nullopt;
        text = text.substr(0, plus);
    }
    size_t dash = text.find('-');
    if (dash != std::string_view::npos) {
        v.prerelease = std::string(text.substr(dash + 1));
        if (!validIdentifiers(v.prerelease, true)) return std::nullopt;
        text = text.substr(0, dash);
    }
    std::vector<std::string_view> core = split(text, '.');
    if (core.size() != 3) return std::nullopt;
    auto major = parseNumber(core[0]), minor = parseNumber(core[1]), patch = parseNumber(core[2]);
    if (!major || !minor || !patch) return std::nullopt;
    v.major = *major;
    v.minor = *minor;
    v.patch = *patch;
    return v;
}

std::string SemVer::toString() const {
    std::string s = std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
    if (!prerelease.empty()) s += "-" + prerelease;
    if (!build.empty()) s += "+" + build;
    return s;
}

std::strong_ordering compare(const SemVer& a, const SemVer& b) {
    if (auto c = a.major <=> b.major; c != 0) return c;
    if (auto c = a.minor <=> b.minor; c != 0) return c;
    if (auto c = a.patch <=> b.patch; c != 0) return c;
    if (a.prerelease.empty() || b.prerelease.empty())
        return a.prerelease.empty() <=> b.prerelease.empty(); // a release is higher
    std::vector<std::string_view> ai = split(a.prerelease, '.'), bi = split(b.prerelease, '.');
    for (size_t i = 0; i < ai.size() && i < bi.size(); ++i)
        if (auto c = compareIdentifier(ai[i], bi[i]); c != 0) return c;
    return ai.size() <=> bi.size();
}

const SemVer& playerVersion() {
    static const SemVer version = [] {
        std::optional<SemVer> v = SemVer::parse(VISCERA_VERSION);
        if (!v)
            throw std::logic_error("vcase::playerVersion(): VISCERA_VERSION '" VISCERA_VERSION
                                   "' is not a semantic version");
        return *v;
    }();
    return version;
}

} // namespace viscera::vcase
