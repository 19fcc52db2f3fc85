#include "case/manifest.hpp"

#include "case/semver.hpp"
#include "case/sha256.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <algorithm>
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
    root.object({"schemaVersion", "caseId", "caseVersion", "minPlayerVersion", "title", "features", "units", "device",
                 "files"});
    Manifest m;
    m.schemaVersion = root["schemaVersion"].integer();

    m.caseId = readCaseId(root["caseId"]);

    m.caseVersion = readSemVer(root["caseVersion"]);
    m.minPlayerVersion = readSemVer(root["minPlayerVersion"]);
    if (auto t = root.find("title")) m.title = t->displayText(kMaxTitleBytes);

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
