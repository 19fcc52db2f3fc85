#pragma once
/// manifest.json of a .vcase package (schema version 1):
///
///   {
///     "schemaVersion": 1,                       integer >= 1
///     "caseId": "liver-resection-01",           [a-z0-9][a-z0-9._-]*, at most 64 characters
///     "caseVersion": "1.2.0",                   semantic version
///     "minPlayerVersion": "0.1.0",              semantic version: oldest player that runs it
///     "title": "Liver resection",               optional string
///     "expires": "2027-12-31T23:59:59Z",        optional UTC time: the player refuses the case after it
///     "features": ["xpbd", "gravity"],          unique [a-z0-9][a-z0-9_-]* subsystem names
///     "units": {"length": "m", "mass": "kg", "time": "s"},
///     "device": {},                             device requirements (any JSON object)
///     "files": [{"path": "meshes/liver.vtet", "size": 1234, "sha256": "<64 lowercase hex>"}]
///   }
///
/// Parsing is strict: a missing required field, a wrong JSON type, an unknown field, a duplicate
/// object key or a value breaking its rule throws viscera::InputError naming the origin, the field
/// and the rule, e.g. "case.vcase: manifest.json: files[2].sha256: must be 64 lowercase hex
/// characters". units must give length, mass and time in SI ("m", "kg", "s"); further
/// quantities are kept as given. files[].path follows entryNameProblem() and is unique.
/// Compatibility with this player (schemaVersion, minPlayerVersion) is a separate check,
/// checkPlayerCompatibility(), so that the package verification order stays explicit.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {
class JsonField;
}

namespace viscera::vcase {

/// The manifest schema this player reads and writes.
inline constexpr int kSchemaVersion = 1;
/// The manifest's entry name at the package root.
inline constexpr std::string_view kManifestName = "manifest.json";

struct FileEntry {
    std::string path;   ///< entry name inside the package
    uint64_t size = 0;  ///< uncompressed size, bytes
    std::string sha256; ///< of the uncompressed bytes, 64 lowercase hex characters

    friend bool operator==(const FileEntry&, const FileEntry&) = default;
};

/// A case title: printable UTF-8 text of at most this many bytes (JsonField::displayText), so that
/// a summary line it is printed on cannot be broken or pushed off screen.
inline constexpr size_t kMaxTitleBytes = 200;

struct Manifest {
    int schemaVersion = kSchemaVersion;
    std::string caseId;
    std::string caseVersion;      ///< semantic version of the case content
    std::string minPlayerVersion; ///< semantic version
    std::optional<std::string> title;
    /// UTC time "YYYY-MM-DDTHH:MM:SSZ" after which the player refuses the case; none: no expiry.
    std::optional<std::string> expires;
    std::vector<std::string> features; ///< subsystems the case needs ("xpbd", "fem", "needle")
    std::map<std::string, std::string> units = {{"length", "m"}, {"mass", "kg"}, {"time", "s"}};
    nlohmann::json device = nlohmann::json::object(); ///< requirements; an object, may be empty
    std::vector<FileEntry> files;                     ///< every packaged file but manifest.json

    /// JSON form; object keys come out sorted, so the text form is deterministic.
    nlohmann::json toJson() const;
    /// toJson() dumped with a 2-space indent and a final newline (the bytes that get packaged).
    std::string toJsonText() const;

    /// Strict conversion from JSON; `origin` prefixes every message ("case.vcase: manifest.json").
    static Manifest fromJson(const nlohmann::json& json, std::string_view origin);
    /// Parses JSON text (duplicate object keys rejected), then fromJson(). O(text length).
    static Manifest parse(std::string_view text, std::string_view origin);

    /// The files[] entry for `path`, or nullptr. O(#files).
    const FileEntry* findFile(std::string_view path) const;

    friend bool operator==(const Manifest&, const Manifest&) = default;
};

/// Throws viscera::InputError ("<origin>: schemaVersion 99 is newer than this player supports
/// (1)") unless 1 <= schemaVersion <= kSchemaVersion and minPlayerVersion <= playerVersion().
void checkPlayerCompatibility(const Manifest& manifest, std::string_view origin);

/// The rules of "caseId" and of a semantic version ("caseVersion", "minPlayerVersion") for
/// every file that carries them (manifest.json, the studio's project.json). Throw InputError.
std::string readCaseId(const sim::JsonField& field);
std::string readSemVer(const sim::JsonField& field);

/// Seconds since 1970-01-01T00:00:00Z of a UTC time written "YYYY-MM-DDTHH:MM:SSZ" (a real date
/// and time of day, year 1970..9999), or nullopt for any other text. formatUtcTime is its inverse.
std::optional<int64_t> parseUtcTime(std::string_view text);
std::string formatUtcTime(int64_t secondsSinceEpoch);

} // namespace viscera::vcase
