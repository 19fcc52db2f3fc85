#pragma once
/// Whether a verified package may run here: its publisher's signature against the keys this
/// player trusts, its expiry, and no rollback to an older version of a case already run (the
/// state folder, on by default). The player's `verify`, `run` and `soak` apply it as the package's
/// admission (CasePackage::open's Admission): on manifest.json and signature.json, before any other
/// entry is inflated and before the scene is read.
#include "case/case_package.hpp"
#include "sim/util/error.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::vcase {

/// Why checkProvenance refused a package, for tools that show it as a state rather than a message
/// (the launcher's tiles). what() is the one-line message.
class TrustRefusal : public InputError {
public:
    enum class Kind { Unsigned, Tampered, Untrusted, Expired, RolledBack };
    TrustRefusal(Kind kind, const std::string& message) : InputError(message), m_kind(kind) {}
    Kind kind() const { return m_kind; }
    /// A few words for the kind: "not signed", "tampered", "untrusted key", "expired", ...
    static const char* label(Kind kind);

private:
    Kind m_kind;
};

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
    /// Where the highest version run of each case is kept (the player always sets it, stateFolder());
    /// empty: no rollback check (tools that only read a package).
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
/// Applied to a package's head (CasePackage::open's admission, readPackageHead) it needs nothing
/// but manifest.json and signature.json: an untrusted package is refused before its payload is
/// inflated.
Provenance checkProvenance(const PackageHead& package, const TrustPolicy& policy);
Provenance checkProvenance(const CasePackage& package, const TrustPolicy& policy);

/// A kiosk station's state folder: used when it exists and the account running the player may
/// read and write it (the administrator makes it for the station's trainee account, mode 0700).
inline constexpr std::string_view kSystemStateFolder = "/var/lib/viscera/state";

/// Where the player keeps the versions run when no --state-dir is given: kSystemStateFolder when
/// usable, else $XDG_STATE_HOME/viscera, else ~/.local/state/viscera; nullopt when none can be
/// named (no XDG_STATE_HOME and no HOME).
std::optional<std::filesystem::path> defaultStateFolder();

/// What the state folder is for: `Check` (verify, soak: read a record where one exists) or
/// `Record` (run: the folder is made, 0700 with 0755 parents, when missing).
enum class StateUse { Check, Record };

/// The state folder to use: `given` (--state-dir) or defaultStateFolder(). Rollback protection is
/// always on: a run records, every check reads. nullopt only for `Check` when the folder does not
/// exist or none can be named (no record can exist). Throws viscera::InputError, one line naming
/// the folder, when it is a symbolic link, it or a folder it passes through is writable by others
/// than root and the user (requireSafeAnchor), or (`Record`) it cannot be made or written.
std::optional<std::filesystem::path> stateFolder(const std::optional<std::filesystem::path>& given, StateUse use);

} // namespace viscera::vcase
