#pragma once
/// Whether a verified package may run here: its publisher's signature against the keys this
/// player trusts, its expiry, and (where a state folder exists) no rollback to an older version
/// of a case already run. The player's `verify`, `run` and `soak` apply it after
/// CasePackage::open() and before the scene is read.
#include "case/case_package.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::vcase {

/// A publisher key the player trusts: its name is the key file's name without ".pem" (or ".pub.pem").
struct TrustedKey {
    std::string name;
    std::string publicKey; ///< raw, kPublicKeyBytes
    std::string source;    ///< the file it was read from
};

class TrustStore {
public:
    /// Adds the Ed25519 public key of a PEM file (--trust FILE). Throws viscera::InputError naming
    /// the file when it is missing, not a regular file or not an Ed25519 PEM public key.
    void addKeyFile(const std::filesystem::path& pemFile);
    /// Adds every "*.pem" file of `folder`, in name order; a folder that does not exist adds
    /// nothing. A file there that is not a key is an error naming it (a broken trust folder is
    /// never half read).
    void addFolder(const std::filesystem::path& folder);
    /// The trusted key with this raw public key, or nullptr. O(#keys).
    const TrustedKey* find(std::string_view publicKey) const;
    const std::vector<TrustedKey>& keys() const { return m_keys; }

private:
    std::vector<TrustedKey> m_keys;
};

/// The system's trust folders: /etc/viscera/trusted-publishers (the administrator's) and
/// <prefix>/share/viscera/trusted-publishers (keys installed by packages, e.g. the samples').
std::vector<std::filesystem::path> systemTrustFolders();

struct TrustPolicy {
    TrustStore trusted;
    /// Run a package with no signature, or one by a key not trusted here (never one whose
    /// signature does not verify). Noted in the summary and the report.
    bool allowUnsigned = false;
    /// Where the highest version run of each case is kept; empty: no rollback check.
    std::optional<std::filesystem::path> stateFolder;
    /// Seconds since the epoch, UTC: the time the expiry is checked against.
    int64_t now = 0;
};

/// Which bytes ran and who signed them (the report's "package" block).
struct Provenance {
    std::string file;   ///< the package as named
    std::string sha256; ///< of the whole package file
    uint64_t bytes = 0;
    /// "trusted": a valid signature by a trusted key; "untrusted": a valid signature by another
    /// key; "unsigned". The last two only run with allowUnsigned.
    std::string signature;
    std::string signer;  ///< the trusted key's name; for an untrusted key the name it claims
    std::string keyId;   ///< keyId() of the signing key; empty when unsigned
    std::string expires; ///< manifest's expiry, empty when none
    bool allowUnsigned = false;
};

/// Checks `package` against `policy`; throws viscera::InputError, one line each:
///   "<package>: signature.json: the signature does not match manifest.json (the package was changed after it was
///   signed)"
///   "<package>: not signed (no signature.json); run it only with --allow-unsigned"
///   "<package>: signature.json: signed by ed25519:… ('name'), a key this player does not trust (add it with --trust
///   KEY.pem or to /etc/viscera/trusted-publishers)"
///   "<package>: manifest.json: expires: the case expired at 2020-01-01T00:00:00Z (now …)"
///   "<package>: manifest.json: caseVersion 1.0.0 is older than 1.2.0, already run for case 'x' (state folder …)"
Provenance checkProvenance(const CasePackage& package, const TrustPolicy& policy);

/// The state folder to use: `given` (created when missing), else $XDG_STATE_HOME/viscera or
/// ~/.local/state/viscera when that folder exists; nullopt otherwise.
std::optional<std::filesystem::path> stateFolder(const std::optional<std::filesystem::path>& given);

} // namespace viscera::vcase
