#pragma once
/// The launcher's case discovery: the *.vcase packages of the case folders, each with what its
/// manifest says and what verified. No Qt, no simulation. A package's head (manifest.json and
/// signature.json) is checked as the player would (vcase::checkProvenance: signature, trusted key,
/// expiry, rollback) before anything else is inflated, so an unsigned or untrusted package costs
/// one read and one SHA-256 pass of its file, never the inflation of its payload; a package that
/// verified is then checked whole once (every file's size and SHA-256, the meshes, on the same
/// bytes) and the outcome remembered (VerifyCache).
#include "case/trust.hpp"
#include "verify_cache.hpp"

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
    std::string signer;                 ///< the trusted key's name when verified, else the name claimed
    std::string keyId;                  ///< "ed25519:…" of the signing key; empty: not signed
    /// Why it cannot run, in a few words ("tampered", "untrusted key", "expired", "not signed",
    /// "cannot be read"); empty: verified.
    std::string refusal;
    std::string problem; ///< one line: the reader's or the trust check's message; empty: it can be started

    bool usable() const { return problem.empty(); }
    /// The tile's verdict line: "verified: signed by viscera-samples (ed25519:…)" or
    /// "cannot run — untrusted key: signed by …".
    std::string verdict() const;
    /// The problem without the package's path (which the tile shows); empty when verified.
    std::string reason() const;
    /// The tile's facts: "xpbd, gravity · expires 2027-12-31".
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

/// What a package is checked against: the player's trust rules, and the cache of whole checks.
struct Verification {
    vcase::TrustPolicy trust;     ///< the system trust folders and --trust keys; the state folder; now
    VerifyCache* cache = nullptr; ///< null: every verified package is checked whole again
};

/// The policy the player applies with the same --trust keys: the system trust folders, the keys,
/// the user's state folder (when it can be named), the clock now. Throws viscera::InputError for
/// a key or trust folder the player would refuse.
vcase::TrustPolicy launcherTrust(const std::vector<std::filesystem::path>& keyFiles);

/// Reads one package's manifest and checks it. Never throws: a package that cannot be read or
/// cannot run is returned with `refusal` and `problem` set. Cost: one read and one SHA-256 pass of
/// the package; for a verified package not in the cache, one decompression and SHA-256 pass of
/// every entry and one parse of each mesh.
CaseInfo readCaseInfo(const std::filesystem::path& file, const Verification& check);

/// Every "*.vcase" regular file directly in the folders (not their subfolders), sorted by title
/// then path; a folder that does not exist is skipped, a file reached twice (the same folder named
/// twice, a link) is listed once.
std::vector<CaseInfo> findCases(const CaseFolders& where, const Verification& check);

} // namespace viscera::launcher
