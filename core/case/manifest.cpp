#include "case/manifest.hpp"

#include "case/entry_name.hpp"
#include "case/semver.hpp"
#include "case/sha256.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <initializer_list>
#include <set>

namespace viscera::vcase {
namespace {

using nlohmann::json;

constexpr size_t kMaxIdLength = 64;

/// SI units the player assumes for the quantities a manifest must state.
const std::map<std::string, std::string>& requiredUnits() {
    static const std::map<std::string, std::string> units = {
        {"length", "m"}, {"mass", "kg"}, {"time", "s"}};
    return units;
}

bool isLowerId(std::string_view s, std::string_view extra) {
    if (s.empty() || s.size() > kMaxIdLength) return false;
    auto lowerAlnum = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); };
    if (!lowerAlnum(s[0])) return false;
    return std::all_of(s.begin(), s.end(), [&](char c) {
        return lowerAlnum(c) || extra.find(c) != std::string_view::npos;
    });
}

/// Reads one JSON object field by field; every failure names origin and field path.
class FieldReader {
  public:
    explicit FieldReader(std::string_view origin) : m_origin(origin) {}

    [[noreturn]] void fail(std::string_view field, std::string_view rule) const {
        throw InputError(m_origin + ": " + std::string(field) + ": " + std::string(rule));
    }

    const json& require(const json& object, const char* key, const std::string& field) const {
        auto it = object.find(key);
        if (it == object.end()) fail(field, "missing required field");
        return *it;
    }

    void expectType(const json& value, json::value_t type, const char* typeName,
                    const std::string& field) const {
        if (value.type() != type)
            fail(field, std::string("must be ") + typeName + " (found " + value.type_name() + ")");
    }

    std::string string(const json& value, const std::string& field) const {
        expectType(value, json::value_t::string, "a string", field);
        return value.get<std::string>();
    }

    void rejectUnknown(const json& object, std::initializer_list<std::string_view> known,
                       const std::string& prefix) const {
        for (auto it = object.begin(); it != object.end(); ++it)
            if (std::find(known.begin(), known.end(), it.key()) == known.end())
                fail(prefix + displayName(it.key()), "unknown field");
    }

  private:
    std::string m_origin;
};

int readSchemaVersion(const FieldReader& r, const json& value) {
    if (!value.is_number_integer()) // true for signed and unsigned integers, false for 1.0
        r.fail("schemaVersion",
               std::string("must be an integer (found ") + value.type_name() + ")");
    bool inRange = value.is_number_unsigned()
                       ? value.get<uint64_t>() <= uint64_t(INT32_MAX)
                       : value.get<int64_t>() >= INT32_MIN && value.get<int64_t>() <= INT32_MAX;
    if (!inRange) r.fail("schemaVersion", "integer out of range");
    return static_cast<int>(value.get<int64_t>());
}

std::string readSemVer(const FieldReader& r, const json& value, const std::string& field) {
    std::string text = r.string(value, field);
    if (!SemVer::parse(text))
        r.fail(field, "'" + displayName(text) +
                          "' is not a semantic version (MAJOR.MINOR.PATCH[-PRERELEASE][+BUILD])");
    return text;
}

FileEntry readFileEntry(const FieldReader& r, const json& value, const std::string& field) {
    r.expectType(value, json::value_t::object, "an object", field);
    FileEntry entry;
    entry.path = r.string(r.require(value, "path", field + ".path"), field + ".path");
    if (auto problem = entryNameProblem(entry.path)) r.fail(field + ".path", *problem);
    if (entry.path == kManifestName) r.fail(field + ".path", "manifest.json must not list itself");
    const json& size = r.require(value, "size", field + ".size");
    if (!size.is_number_unsigned())
        r.fail(field + ".size",
               std::string("must be a non-negative integer (found ") +
                   (size.is_number_integer() ? "a negative integer" : size.type_name()) + ")");
    entry.size = size.get<uint64_t>();
    entry.sha256 = r.string(r.require(value, "sha256", field + ".sha256"), field + ".sha256");
    if (!isSha256Hex(entry.sha256))
        r.fail(field + ".sha256", "must be 64 lowercase hex characters");
    r.rejectUnknown(value, {"path", "size", "sha256"}, field + ".");
    return entry;
}

} // namespace

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
    FieldReader r(origin);
    if (!j.is_object())
        throw InputError(std::string(origin) + ": must be a JSON object (found " + j.type_name() +
                         ")");
    Manifest m;
    m.schemaVersion = readSchemaVersion(r, r.require(j, "schemaVersion", "schemaVersion"));

    m.caseId = r.string(r.require(j, "caseId", "caseId"), "caseId");
    if (!isLowerId(m.caseId, "._-"))
        r.fail("caseId", "'" + displayName(m.caseId) +
                             "' must match [a-z0-9][a-z0-9._-]* (at most 64 characters)");

    m.caseVersion = readSemVer(r, r.require(j, "caseVersion", "caseVersion"), "caseVersion");
    m.minPlayerVersion =
        readSemVer(r, r.require(j, "minPlayerVersion", "minPlayerVersion"), "minPlayerVersion");

    if (auto it = j.find("title"); it != j.end()) m.title = r.string(*it, "title");

    const json& features = r.require(j, "features", "features");
    r.expectType(features, json::value_t::array, "an array", "features");
    std::set<std::string> seenFeatures;
    for (size_t i = 0; i < features.size(); ++i) {
        std::string field = "features[" + std::to_string(i) + "]";
        std::string name = r.string(features[i], field);
        if (!isLowerId(name, "_-"))
            r.fail(field, "'" + displayName(name) + "' must match [a-z0-9][a-z0-9_-]*");
        if (!seenFeatures.insert(name).second) r.fail(field, "duplicate feature '" + name + "'");
        m.features.push_back(std::move(name));
    }

    const json& units = r.require(j, "units", "units");
    r.expectType(units, json::value_t::object, "an object", "units");
    m.units.clear();
    for (auto it = units.begin(); it != units.end(); ++it)
        m.units[it.key()] = r.string(it.value(), "units." + displayName(it.key()));
    for (const auto& [quantity, si] : requiredUnits()) {
        auto it = m.units.find(quantity);
        if (it == m.units.end()) r.fail("units." + quantity, "missing required field");
        if (it->second != si)
            r.fail("units." + quantity, "'" + displayName(it->second) +
                                            "' is not supported (the player uses SI: '" + si +
                                            "')");
    }

    m.device = r.require(j, "device", "device");
    r.expectType(m.device, json::value_t::object, "an object", "device");

    const json& files = r.require(j, "files", "files");
    r.expectType(files, json::value_t::array, "an array", "files");
    std::set<std::string, std::less<>> seenPaths;
    for (size_t i = 0; i < files.size(); ++i) {
        std::string field = "files[" + std::to_string(i) + "]";
        FileEntry entry = readFileEntry(r, files[i], field);
        if (!seenPaths.insert(entry.path).second)
            r.fail(field + ".path", "'" + entry.path + "' is listed more than once");
        m.files.push_back(std::move(entry));
    }

    r.rejectUnknown(j,
                    {"schemaVersion", "caseId", "caseVersion", "minPlayerVersion", "title",
                     "features", "units", "device", "files"},
                    "");
    return m;
}

Manifest Manifest::parse(std::string_view text, std::string_view origin) {
    // nlohmann::json keeps the last of repeated keys; a manifest must not be read differently by
    // different parsers, so repeated keys are an error.
    std::vector<std::set<std::string>> openObjects;
    std::optional<std::string> duplicateKey;
    json::parser_callback_t track = [&](int, json::parse_event_t event, json& parsed) {
        switch (event) {
        case json::parse_event_t::object_start:
            openObjects.emplace_back();
            break;
        case json::parse_event_t::object_end:
            openObjects.pop_back();
            break;
        case json::parse_event_t::key:
            if (!openObjects.back().insert(parsed.get<std::string>()).second && !duplicateKey)
                duplicateKey = parsed.get<std::string>();
            break;
        default:
            break;
        }
        return true;
    };
    json j;
    try {
        j = json::parse(text.begin(), text.end(), track);
    } catch (const json::parse_error& e) {
        throw InputError(std::string(origin) + ": invalid JSON (" + e.what() + ")");
    }
    if (duplicateKey)
        throw InputError(std::string(origin) + ": invalid JSON (duplicate object key \"" +
                         displayName(*duplicateKey) + "\")");
    return fromJson(j, origin);
}

const FileEntry* Manifest::findFile(std::string_view path) const {
    auto it = std::find_if(files.begin(), files.end(),
                           [&](const FileEntry& f) { return f.path == path; });
    return it == files.end() ? nullptr : &*it;
}

void checkPlayerCompatibility(const Manifest& manifest, std::string_view origin) {
    const std::string prefix = std::string(origin) + ": ";
    const int schemaVersion = manifest.schemaVersion;
    if (schemaVersion < 1)
        throw InputError(prefix + "schemaVersion " + std::to_string(schemaVersion) +
                         " is not valid (must be >= 1)");
    if (schemaVersion > kSchemaVersion)
        throw InputError(prefix + "schemaVersion " + std::to_string(schemaVersion) +
                         " is newer than this player supports (" + std::to_string(kSchemaVersion) +
                         ")");
    std::optional<SemVer> required = SemVer::parse(manifest.minPlayerVersion);
    if (!required)
        throw InputError(prefix + "minPlayerVersion: '" + displayName(manifest.minPlayerVersion) +
                         "' is not a semantic version");
    if (compare(*required, playerVersion()) > 0)
        throw InputError(prefix + "minPlayerVersion " + manifest.minPlayerVersion +
                         " is newer than this player (" + playerVersion().toString() + ")");
}

} // namespace viscera::vcase
