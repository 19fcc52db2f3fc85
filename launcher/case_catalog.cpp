#include "case_catalog.hpp"

#include "case/case_package.hpp"

#include <algorithm>
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

std::string CaseInfo::description() const {
    if (!usable()) { // the reader's message names the file, which the tile shows already
        const std::string prefix = path.string() + ": ";
        return problem.rfind(prefix, 0) == 0 ? problem.substr(prefix.size()) : problem;
    }
    std::string out;
    for (size_t i = 0; i < features.size(); ++i)
        out += (i ? ", " : "") + features[i];
    out += out.empty() ? "" : " · ";
    out += signer.empty() ? "not signed" : "signed by " + signer;
    if (expires) out += " · expires " + dateOf(*expires);
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

CaseInfo readCaseInfo(const fs::path& file) {
    CaseInfo info;
    info.path = file;
    info.title = file.stem().string();
    try {
        const auto package = vcase::CasePackage::open(file);
        const vcase::Manifest& m = package->manifest();
        if (m.title && !m.title->empty()) info.title = *m.title;
        info.caseId = m.caseId;
        info.caseVersion = m.caseVersion;
        info.features = m.features;
        info.expires = m.expires;
        if (package->signature()) info.signer = package->signature()->signer;
    } catch (const std::exception& e) {
        info.problem = e.what();
    }
    return info;
}

std::vector<CaseInfo> findCases(const CaseFolders& where) {
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
            cases.push_back(readCaseInfo(p));
        }
    }
    std::sort(cases.begin(), cases.end(), [](const CaseInfo& a, const CaseInfo& b) {
        return a.title != b.title ? a.title < b.title : a.path < b.path;
    });
    return cases;
}

} // namespace viscera::launcher
