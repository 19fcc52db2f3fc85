#include "case/run_state.hpp"

#include "case/manifest.hpp"
#include "case/semver.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <map>
#include <sys/file.h>
#include <unistd.h>

namespace viscera::vcase {
namespace {

using Versions = std::map<std::string, std::string>;

Versions readState(const std::filesystem::path& folder) {
    const std::filesystem::path file = folder / kRunStateName;
    std::error_code ec;
    const bool present = std::filesystem::exists(file, ec);
    if (ec) throw InputError(file.string() + ": cannot read the record of the versions run (" + ec.message() + ")");
    if (!present) return {};
    const std::string origin = file.string();
    const nlohmann::json j = sim::parseJsonText(readFile(file, 1 << 20), origin);
    const sim::JsonField root(j, "", origin);
    root.object({"schemaVersion", "cases"});
    const int version = root["schemaVersion"].integer();
    if (version != 1) root.failAt("schemaVersion", std::to_string(version) + " is not supported (this player reads 1)");
    Versions out;
    for (const auto& [id, value] : root["cases"].members())
        out[id] = readSemVer(value);
    return out;
}

/// Holds the state folder's lock (case-versions.lock, flock) for one read-modify-write, so that two
/// players recording at once cannot lower each other's record.
class StateLock {
public:
    explicit StateLock(const std::filesystem::path& folder) {
        const std::filesystem::path file = folder / "case-versions.lock";
        m_fd = ::open(file.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0600);
        if (m_fd < 0) throw InputError(file.string() + ": cannot open the state lock (" + std::strerror(errno) + ")");
        while (::flock(m_fd, LOCK_EX) != 0)
            if (errno != EINTR) {
                const int e = errno;
                ::close(m_fd);
                throw InputError(file.string() + ": cannot lock the state (" + std::strerror(e) + ")");
            }
    }
    ~StateLock() { ::close(m_fd); } // closing releases the lock
    StateLock(const StateLock&) = delete;
    StateLock& operator=(const StateLock&) = delete;

private:
    int m_fd = -1;
};

} // namespace

std::optional<std::string> highestVersionRun(const std::filesystem::path& folder, const std::string& caseId) {
    const Versions v = readState(folder);
    auto it = v.find(caseId);
    if (it == v.end()) return std::nullopt;
    return it->second;
}

void recordVersionRun(const std::filesystem::path& folder, const std::string& caseId, const std::string& version) {
    const StateLock lock(folder);
    Versions v = readState(folder);
    const std::optional<SemVer> next = SemVer::parse(version);
    auto it = v.find(caseId);
    if (it != v.end() && next && compare(*SemVer::parse(it->second), *next) >= 0) return;
    v[caseId] = version;
    nlohmann::json cases = nlohmann::json::object();
    for (const auto& [id, ver] : v)
        cases[id] = ver;
    writeFileAtomic(folder / kRunStateName, nlohmann::json{{"schemaVersion", 1}, {"cases", cases}}.dump(2) + "\n");
}

} // namespace viscera::vcase
