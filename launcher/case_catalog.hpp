#pragma once
/// The launcher's case discovery: the *.vcase packages of the case folders, each with what its
/// manifest says. No Qt, no simulation: a package is opened and verified with
/// vcase::CasePackage::open() (its manifest, every file's size and SHA-256) and nothing of the case
/// is run; trust, expiry and the version rules are the player's to check when it starts the case.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::launcher {

/// One case package as the picker shows it.
struct CaseInfo {
    std::filesystem::path path;         ///< the package file
    std::string title;                  ///< the manifest's title, else the file name without ".vcase"
    std::string caseId;                 ///< manifest caseId (empty when the package cannot be read)
    std::string caseVersion;            ///< manifest caseVersion
    std::vector<std::string> features;  ///< manifest features ("xpbd", "fem", ...)
    std::optional<std::string> expires; ///< manifest expires, UTC "YYYY-MM-DDTHH:MM:SSZ"
    std::string signer;                 ///< signature.json's signer name; empty: not signed
    std::string problem;                ///< one line: why the package cannot be read; empty: it can be started

    bool usable() const { return problem.empty(); }
    /// One line for the tile: "xpbd, gravity · signed by Viscera samples · expires 2027-12-31".
    std::string description() const;
};

/// Where cases are looked for, in this order: `samples` (the viscera-samples package's folder),
/// the user's case folder, then the folders named on the command line.
struct CaseFolders {
    std::vector<std::filesystem::path> folders;

    /// /usr/share/viscera/samples (or <prefix>/share/viscera/samples beside this program when that
    /// exists), $XDG_DATA_HOME/viscera/cases (or ~/.local/share/viscera/cases), then `extra`.
    static CaseFolders standard(const std::vector<std::filesystem::path>& extra);
};

/// The user's case folder: $XDG_DATA_HOME/viscera/cases, else $HOME/.local/share/viscera/cases.
std::filesystem::path userCaseFolder();

/// Reads one package's manifest and signer. Never throws: a package that cannot be read is
/// returned with `problem` set (the reader's one-line message). Cost: one read and one SHA-256 pass
/// of the package, one parse of each mesh (CasePackage::open).
CaseInfo readCaseInfo(const std::filesystem::path& file);

/// Every "*.vcase" regular file directly in the folders (not their subfolders), sorted by title
/// then path; a folder that does not exist is skipped, a file reached twice (the same folder named
/// twice, a link) is listed once.
std::vector<CaseInfo> findCases(const CaseFolders& where);

} // namespace viscera::launcher
