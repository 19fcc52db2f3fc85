#include "verify_cache.hpp"

#include "sim/util/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <exception>
#include <sys/stat.h>
#include <tuple>

namespace viscera::launcher {
namespace {

constexpr int kSchema = 1;

} // namespace

bool PackageStamp::operator<(const PackageStamp& o) const {
    return std::tie(path, size, mtimeNs, sha256) < std::tie(o.path, o.size, o.mtimeNs, o.sha256);
}

VerifyCache::VerifyCache(std::filesystem::path file) : m_file(std::move(file)) {
    if (m_file.empty()) return;
    try {
        const nlohmann::json j = nlohmann::json::parse(readFile(m_file, 4 << 20, "the launcher's cache"));
        if (j.value("schemaVersion", 0) != kSchema) return;
        for (const nlohmann::json& e : j.at("packages")) {
            PackageStamp s{e.at("path").get<std::string>(), e.at("size").get<uint64_t>(),
                           e.at("mtimeNs").get<int64_t>(), e.at("sha256").get<std::string>()};
            m_entries[s] = e.at("problem").get<std::string>();
        }
    } catch (const std::exception&) {
        m_entries.clear(); // missing or malformed: start afresh
    }
}

std::optional<std::string> VerifyCache::find(const PackageStamp& stamp) const {
    auto it = m_entries.find(stamp);
    if (it == m_entries.end()) return std::nullopt;
    return it->second;
}

void VerifyCache::store(const PackageStamp& stamp, std::string problem) {
    for (auto it = m_entries.begin(); it != m_entries.end();) // one record per path
        it = it->first.path == stamp.path ? m_entries.erase(it) : std::next(it);
    while (m_entries.size() >= kMaxEntries)
        m_entries.erase(m_entries.begin());
    m_entries[stamp] = std::move(problem);
    m_dirty = true;
}

void VerifyCache::save() const {
    if (m_file.empty() || !m_dirty) return;
    nlohmann::json packages = nlohmann::json::array();
    for (const auto& [s, problem] : m_entries)
        packages.push_back(
            {{"path", s.path}, {"size", s.size}, {"mtimeNs", s.mtimeNs}, {"sha256", s.sha256}, {"problem", problem}});
    try {
        std::filesystem::create_directories(m_file.parent_path());
        writeFileAtomic(m_file, nlohmann::json{{"schemaVersion", kSchema}, {"packages", packages}}.dump(1) + "\n",
                        0600);
        m_dirty = false;
    } catch (const std::exception&) {
        // A cache that cannot be written only costs the next start its checks again.
    }
}

std::filesystem::path defaultVerifyCacheFile() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg == '/')
        return std::filesystem::path(xdg) / "viscera/launcher-verified.json";
    if (const char* home = std::getenv("HOME"); home && *home == '/')
        return std::filesystem::path(home) / ".cache/viscera/launcher-verified.json";
    return {};
}

std::optional<PackageStamp> stampOf(const std::filesystem::path& file, const std::string& sha256) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) return std::nullopt;
    return PackageStamp{std::filesystem::absolute(file).lexically_normal().string(), uint64_t(st.st_size),
                        int64_t(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec, sha256};
}

} // namespace viscera::launcher
