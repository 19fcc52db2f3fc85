#pragma once
/// The launcher's record of the packages whose every file it has verified (each entry's size and
/// SHA-256 against the signed manifest, each mesh parsed): a package's full check costs a
/// decompression of everything it holds, so it is done once per package bytes and remembered.
///
/// Keyed by the package's path, size, modification time and SHA-256: a file rewritten in place,
/// even with the same size and time stamp, is checked again. The file is a cache: one that is
/// missing, unreadable or malformed is ignored and rewritten (atomically, mode 0600); the player
/// checks every package again when it starts one, so nothing here is trusted with a decision.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace viscera::launcher {

struct PackageStamp {
    std::string path;
    uint64_t size = 0;
    int64_t mtimeNs = 0;
    std::string sha256;

    bool operator<(const PackageStamp& o) const;
};

class VerifyCache {
public:
    /// The cache at `file` (empty: in memory only). Never throws.
    explicit VerifyCache(std::filesystem::path file = {});

    /// The remembered outcome: "" verified, else the one-line problem; nullopt when unknown.
    std::optional<std::string> find(const PackageStamp& stamp) const;
    void store(const PackageStamp& stamp, std::string problem);
    /// Writes the cache when it changed. Never throws (a cache that cannot be written is skipped).
    void save() const;

    /// At most this many packages are remembered (the oldest entries of a full cache are dropped).
    static constexpr size_t kMaxEntries = 512;

private:
    std::filesystem::path m_file;
    std::map<PackageStamp, std::string> m_entries;
    mutable bool m_dirty = false;
};

/// $XDG_CACHE_HOME/viscera/launcher-verified.json, else ~/.cache/viscera/launcher-verified.json.
std::filesystem::path defaultVerifyCacheFile();

/// The stamp of `file` with its SHA-256 `sha256`; nullopt when it cannot be stat'ed.
std::optional<PackageStamp> stampOf(const std::filesystem::path& file, const std::string& sha256);

} // namespace viscera::launcher
