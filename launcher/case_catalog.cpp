#include "case_catalog.hpp"

#include "case/case_package.hpp"
#include "case/trust.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <set>
#include <system_error>

namespace viscera::launcher {
namespace {

namespace fs = std::filesystem;

/// <prefix>/share/viscera/samples for the prefix this program runs from (/usr/bin → /usr).
fs::path samplesFolder() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path beside = (exe.parent_path().parent_path() / "share/viscera/samples").lexically_normal();
        if (fs::is_directory(beside, ec)) return beside;
    }
    return "/usr/share/viscera/samples";
}

std::string dateOf(const std::string& utc) {
    return utc.substr(0, 10); // "YYYY-MM-DD" of "YYYY-MM-DDTHH:MM:SSZ"
}

} // namespace

std::string CaseInfo::verdict() const {
    if (usable()) return "verified: signed by " + signer + (keyId.empty() ? std::string() : " (" + keyId + ")");
    return "cannot run — " + refusal + ": " + reason();
}

std::string CaseInfo::reason() const {
    const std::string prefix = path.string() + ": "; // the tile names the file already
    return problem.rfind(prefix, 0) == 0 ? problem.substr(prefix.size()) : problem;
}

std::string CaseInfo::description() const {
    std::string out;
    for (size_t i = 0; i < features.size(); ++i)
        out += (i ? ", " : "") + features[i];
    if (expires) out += (out.empty() ? "" : " · ") + std::string("expires ") + dateOf(*expires);
    return out;
}

fs::path userCaseFolder() {
    const char* xdg = std::getenv("XDG_DATA_HOME");
    if (xdg && *xdg && fs::path(xdg).is_absolute()) return fs::path(xdg) / "viscera/cases";
    const char* home = std::getenv("HOME");
    return fs::path(home && *home ? home : "/nonexistent") / ".local/share/viscera/cases";
}

CaseFolders CaseFolders::standard(const std::vector<fs::path>& extra) {
    CaseFolders c;
    c.folders.push_back(samplesFolder());
    c.folders.push_back(userCaseFolder());
    c.folders.insert(c.folders.end(), extra.begin(), extra.end());
    return c;
}

vcase::TrustPolicy launcherTrust(const std::vector<fs::path>& keyFiles) {
    vcase::TrustPolicy p;
    for (const fs::path& folder : vcase::systemTrustFolders())
        p.trusted.addFolder(folder);
    for (const fs::path& f : keyFiles)
        p.trusted.addKeyFile(f);
    try {
        p.stateFolder = vcase::stateFolder(std::nullopt, vcase::StateUse::Check); // versions this account ran
    } catch (const InputError&) {
        p.stateFolder.reset(); // the player will say why when a case is started
    }
    p.now =
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    return p;
}

namespace {

/// The whole package (every file's size and SHA-256, the meshes), once per package bytes: `bytes`
/// are the ones whose head was admitted and whose SHA-256 is `sha256`.
void checkPayload(const fs::path& file, std::string_view bytes, const std::string& sha256, const Verification& check,
                  CaseInfo& info) {
    const std::optional<PackageStamp> stamp = stampOf(file, sha256);
    std::optional<std::string> problem = stamp && check.cache ? check.cache->find(*stamp) : std::nullopt;
    if (!problem) {
        try {
            (void)vcase::CasePackage::fromBytes(bytes, file.string());
            problem = "";
        } catch (const std::exception& e) {
            problem = e.what();
        }
        if (stamp && check.cache) check.cache->store(*stamp, *problem);
    }
    if (problem->empty()) return;
    // The signed manifest was admitted: what fails now is bytes that are not the ones signed.
    info.refusal = "tampered";
    info.problem = *problem;
}

} // namespace

CaseInfo readCaseInfo(const fs::path& file, const Verification& check) {
    CaseInfo info;
    info.path = file;
    info.title = file.stem().string();
    std::string bytes, sha256;
    try {
        // One read: the head admitted, the payload checked and the cache keyed are the same bytes.
        bytes = readFile(file, vcase::Limits{}.maxPackageBytes, "a case package");
        vcase::readPackageHead(bytes, file.string(), [&](const vcase::PackageHead& head) {
            const vcase::Manifest& m = head.manifest;
            if (m.title && !m.title->empty()) info.title = *m.title;
            info.caseId = m.caseId;
            info.caseVersion = m.caseVersion;
            info.features = m.features;
            info.expires = m.expires;
            if (head.signature) info.signer = head.signature->signer;
            sha256 = head.sha256;
            const vcase::Provenance p = vcase::checkProvenance(head, check.trust);
            info.signer = p.signer;
            info.keyId = p.keyId;
        });
    } catch (const vcase::TrustRefusal& e) {
        info.refusal = vcase::TrustRefusal::label(e.kind());
        info.problem = e.what();
        return info;
    } catch (const std::exception& e) {
        info.refusal = "cannot be read";
        info.problem = e.what();
        return info;
    }
    checkPayload(file, bytes, sha256, check, info);
    return info;
}

std::vector<CaseInfo> findCases(const CaseFolders& where, const Verification& check) {
    std::vector<CaseInfo> cases;
    std::set<fs::path> seen;
    for (const fs::path& folder : where.folders) {
        std::error_code ec;
        fs::directory_iterator it(folder, ec), end;
        for (; !ec && it != end; it.increment(ec)) {
            const fs::path& p = it->path();
            std::error_code fileEc;
            if (p.extension() != ".vcase" || !it->is_regular_file(fileEc)) continue;
            const fs::path canonical = fs::weakly_canonical(p, fileEc);
            if (!seen.insert(fileEc ? p : canonical).second) continue;
            cases.push_back(readCaseInfo(p, check));
        }
    }
    if (check.cache) check.cache->save();
    std::sort(cases.begin(), cases.end(), [](const CaseInfo& a, const CaseInfo& b) {
        return a.title != b.title ? a.title < b.title : a.path < b.path;
    });
    return cases;
}

} // namespace viscera::launcher
