#include "case/manifest.hpp"

#include "case/semver.hpp"
#include "case/sha256.hpp"
#include "case/signing.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <algorithm>
#include <cstdio>
#include <initializer_list>
#include <set>

namespace viscera::vcase {

using sim::displayName;
using sim::entryNameProblem;
namespace {

using nlohmann::json;

constexpr size_t kMaxIdLength = 64;

/// SI units the player assumes for the quantities a manifest must state.
const std::map<std::string, std::string>& requiredUnits() {
    static const std::map<std::string, std::string> units = {{"length", "m"}, {"mass", "kg"}, {"time", "s"}};
    return units;
}

bool isLowerId(std::string_view s, std::string_view extra) {
    if (s.empty() || s.size() > kMaxIdLength) return false;
    auto lowerAlnum = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); };
    if (!lowerAlnum(s[0])) return false;
    return std::all_of(s.begin(), s.end(),
                       [&](char c) { return lowerAlnum(c) || extra.find(c) != std::string_view::npos; });
}

FileEntry readFileEntry(const sim::JsonField& f) {
    f.object({"path", "size", "sha256"});
    FileEntry entry;
    const sim::JsonField path = f["path"];
    entry.path = path.string();
    if (auto problem = entryNameProblem(entry.path)) path.fail(*problem);
    if (entry.path == kManifestName) path.fail("manifest.json must not list itself");
    if (entry.path == kSignatureName) path.fail("signature.json is the package's signature and is not listed");
    const sim::JsonField size = f["size"];
    if (!size.value().is_number_unsigned())
        size.fail(std::string("must be a non-negative integer (found ") +
                  (size.value().is_number_integer() ? "a negative integer" : size.value().type_name()) + ")");
    entry.size = size.value().get<uint64_t>();
    const sim::JsonField sha = f["sha256"];
    entry.sha256 = sha.string();
    if (!isSha256Hex(entry.sha256)) sha.fail("must be 64 lowercase hex characters");
    return entry;
}

} // namespace

std::string readSemVer(const sim::JsonField& f) {
    std::string text = f.string();
    if (!SemVer::parse(text))
        f.fail("'" + displayName(text) + "' is not a semantic version (MAJOR.MINOR.PATCH[-PRERELEASE][+BUILD])");
    return text;
}

std::string readCaseId(const sim::JsonField& f) {
    std::string id = f.string();
    if (!isLowerId(id, "._-"))
        f.fail("'" + displayName(id) + "' must match [a-z0-9][a-z0-9._-]* (at most 64 characters)");
    return id;
}

nlohmann::json Manifest::toJson() const {
    json j = json::object();
    j["schemaVersion"] = schemaVersion;
    j["caseId"] = caseId;
    j["caseVersion"] = caseVersion;
    j["minPlayerVersion"] = minPlayerVersion;
    if (title) j["title"] = *title;
    if (expires) j["expires"] = *expires;
    j["features"] = features;
    j["units"] = units;
    j["device"] = device;
    json list = json::array();
    for (const FileEntry& f : files)
        list.push_back({{"path", f.path}, {"size", f.size}, {"sha256", f.sha256}});
    j["files"] = std::move(list);
    return j;
}

std::string Manifest::toJsonText() const {
    return toJson().dump(2) + "\n";
}

Manifest Manifest::fromJson(const nlohmann::json& j, std::string_view origin) {
    const std::string where(origin);
    if (!j.is_object()) throw InputError(where + ": must be a JSON object (found " + j.type_name() + ")");
    const sim::JsonField root(j, "", where);
    root.object({"schemaVersion", "caseId", "caseVersion", "minPlayerVersion", "title", "expires", "features", "units",
                 "device", "files"});
    Manifest m;
    m.schemaVersion = root["schemaVersion"].integer();

    m.caseId = readCaseId(root["caseId"]);

    m.caseVersion = readSemVer(root["caseVersion"]);
    m.minPlayerVersion = readSemVer(root["minPlayerVersion"]);
    if (auto t = root.find("title")) m.title = t->displayText(kMaxTitleBytes);
    if (auto e = root.find("expires")) {
        m.expires = e->string();
        if (!parseUtcTime(*m.expires))
            e->fail("'" + displayName(*m.expires) + "' is not a UTC time YYYY-MM-DDTHH:MM:SSZ");
    }

    std::set<std::string> seenFeatures;
    for (const sim::JsonField& f : root["features"].items()) {
        std::string name = f.string();
        if (!isLowerId(name, "_-")) f.fail("'" + displayName(name) + "' must match [a-z0-9][a-z0-9_-]*");
        if (!seenFeatures.insert(name).second) f.fail("duplicate feature '" + name + "'");
        m.features.push_back(std::move(name));
    }

    const sim::JsonField units = root["units"];
    m.units.clear();
    for (const auto& [quantity, value] : units.members())
        m.units[quantity] = value.string();
    for (const auto& [quantity, si] : requiredUnits()) {
        auto it = m.units.find(quantity);
        if (it == m.units.end()) units.failAt(quantity, "required field is missing");
        if (it->second != si)
            units.failAt(quantity,
                         "'" + displayName(it->second) + "' is not supported (the player uses SI: '" + si + "')");
    }

    m.device = root["device"].anyObject().value();

    std::set<std::string, std::less<>> seenPaths;
    for (const sim::JsonField& f : root["files"].items()) {
        FileEntry entry = readFileEntry(f);
        if (!seenPaths.insert(entry.path).second) f.failAt("path", "'" + entry.path + "' is listed more than once");
        m.files.push_back(std::move(entry));
    }
    return m;
}

Manifest Manifest::parse(std::string_view text, std::string_view origin) {
    return fromJson(sim::parseJsonText(text, std::string(origin)), origin);
}

std::optional<int64_t> parseUtcTime(std::string_view text) {
    int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
    if (text.size() != 20 || text[4] != '-' || text[7] != '-' || text[10] != 'T' || text[13] != ':' ||
        text[16] != ':' || text[19] != 'Z')
        return std::nullopt;
    auto field = [&](size_t at, size_t n, int& out) {
        out = 0;
        for (size_t i = at; i < at + n; ++i) {
            if (text[i] < '0' || text[i] > '9') return false;
            out = out * 10 + (text[i] - '0');
        }
        return true;
    };
    if (!field(0, 4, year) || !field(5, 2, month) || !field(8, 2, day) || !field(11, 2, hour) ||
        !field(14, 2, minute) || !field(17, 2, second))
        return std::nullopt;
    const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (year < 1970 || month < 1 || month > 12 || day < 1 || day > kDays[month - 1] + (month == 2 && leap) ||
        hour > 23 || minute > 59 || second > 59)
        return std::nullopt;
    // Days from the civil date (H. Hinnant's algorithm), then seconds.
    const int y = year - (month <= 2);
    const int era = y / 400;
    const int yoe = y - era * 400;
    const int doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
    const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    const int64_t days = int64_t(era) * 146097 + doe - 719468;
    return days * 86400 + hour * 3600 + minute * 60 + second;
}

std::string formatUtcTime(int64_t t) {
    const int64_t days = t >= 0 ? t / 86400 : (t - 86399) / 86400;
    const int64_t secs = t - days * 86400;
    // Civil date from days (the inverse of the above).
    const int64_t z = days + 719468;
    const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
    const int64_t doe = z - era * 146097;
    const int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const int64_t mp = (5 * doy + 2) / 153;
    const int64_t day = doy - (153 * mp + 2) / 5 + 1;
    const int64_t month = mp < 10 ? mp + 3 : mp - 9;
    const int64_t year = yoe + era * 400 + (month <= 2);
    char buf[128];
    std::snprintf(buf, sizeof buf, "%04lld-%02lld-%02lldT%02lld:%02lld:%02lldZ", static_cast<long long>(year),
                  static_cast<long long>(month), static_cast<long long>(day), static_cast<long long>(secs / 3600),
                  static_cast<long long>(secs / 60 % 60), static_cast<long long>(secs % 60));
    return buf;
}

const FileEntry* Manifest::findFile(std::string_view path) const {
    auto it = std::find_if(files.begin(), files.end(), [&](const FileEntry& f) { return f.path == path; });
    return it == files.end() ? nullptr : &*it;
}

void checkPlayerCompatibility(const Manifest& manifest, std::string_view origin) {
    const std::string prefix = std::string(origin) + ": ";
    const int schemaVersion = manifest.schemaVersion;
    if (schemaVersion < 1)
        throw InputError(prefix + "schemaVersion " + std::to_string(schemaVersion) + " is not valid (must be >= 1)");
    if (schemaVersion > kSchemaVersion)
        throw InputError(prefix + "schemaVersion " + std::to_string(schemaVersion) +
                         " is newer than this player supports (" + std::to_string(kSchemaVersion) + ")");
    std::optional<SemVer> required = SemVer::parse(manifest.minPlayerVersion);
    if (!required)
        throw InputError(prefix + "minPlayerVersion: '" + displayName(manifest.minPlayerVersion) +
                         "' is not a semantic version");
    if (compare(*required, playerVersion()) > 0)
        throw InputError(prefix + "minPlayerVersion " + manifest.minPlayerVersion + " is newer than this player (" +
                         playerVersion().toString() + ")");
}

} // namespace viscera::vcase
