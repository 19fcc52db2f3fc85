#include "case/trust.hpp"

#include "case/anchor_check.hpp"
#include "case/run_state.hpp"
#include "case/semver.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sys/stat.h>
#include <unistd.h>

namespace viscera::vcase {
namespace {

std::string trustHint() {
    std::string folders;
    for (const std::filesystem::path& f : systemTrustFolders())
        folders += (folders.empty() ? "" : " or ") + f.string();
    return "add it with --trust KEY.pem or to " + folders;
}

/// Signature: verified over manifest.json, then looked up among the trusted keys.
void checkSignature(const PackageHead& package, const TrustPolicy& policy, Provenance& p) {
    const std::string& name = package.name;
    const std::optional<PackageSignature>& sig = package.signature;
    if (!sig) {
        if (!policy.allowUnsigned)
            throw TrustRefusal(TrustRefusal::Kind::Unsigned,
                               name + ": not signed (no " + std::string(kSignatureName) +
                                   "); a case runs only when a trusted publisher signed it, or with --allow-unsigned");
        p.signature = "unsigned";
        return;
    }
    p.keyId = keyId(sig->publicKey);
    if (!verifySignature(sig->publicKey, signedMessage(package.manifestText), sig->signature))
        throw TrustRefusal(TrustRefusal::Kind::Tampered,
                           name + ": " + std::string(kSignatureName) + ": the signature by " + p.keyId +
                               " does not match manifest.json (the package was changed after it was signed)");
    if (const TrustedKey* key = policy.trusted.find(sig->publicKey)) {
        p.signature = "trusted";
        p.signer = key->name;
        return;
    }
    if (!policy.allowUnsigned)
        throw TrustRefusal(TrustRefusal::Kind::Untrusted,
                           name + ": " + std::string(kSignatureName) + ": signed by " + p.keyId + " ('" + sig->signer +
                               "'), a key this player does not trust (" + trustHint() + ")");
    p.signature = "untrusted";
    p.signer = sig->signer;
}

void checkExpiry(const PackageHead& package, const TrustPolicy& policy) {
    const Manifest& m = package.manifest;
    if (!m.expires) return;
    const std::optional<int64_t> at = parseUtcTime(*m.expires); // valid: Manifest::parse checked it
    if (at && policy.now > *at)
        throw TrustRefusal(TrustRefusal::Kind::Expired, package.name + ": " + std::string(kManifestName) +
                                                            ": expires: the case expired at " + *m.expires + " (now " +
                                                            formatUtcTime(policy.now) + ")");
}

void checkRollback(const PackageHead& package, const TrustPolicy& policy) {
    if (!policy.stateFolder) return;
    const Manifest& m = package.manifest;
    const std::optional<std::string> highest = highestVersionRun(*policy.stateFolder, m.caseId);
    if (!highest) return;
    const std::optional<SemVer> ran = SemVer::parse(*highest), now = SemVer::parse(m.caseVersion);
    if (ran && now && compare(*now, *ran) < 0)
        throw TrustRefusal(TrustRefusal::Kind::RolledBack, package.name + ": " + std::string(kManifestName) +
                                                               ": caseVersion " + m.caseVersion + " is older than " +
                                                               *highest + ", already run for case '" + m.caseId +
                                                               "' (state folder " + policy.stateFolder->string() + ")");
}

} // namespace

const char* TrustRefusal::label(Kind kind) {
    switch (kind) {
    case Kind::Unsigned:
        return "not signed";
    case Kind::Tampered:
        return "tampered";
    case Kind::Untrusted:
        return "untrusted key";
    case Kind::Expired:
        return "expired";
    case Kind::RolledBack:
        return "older than a version already run";
    }
    return "refused";
}

void TrustStore::addKeyFile(const std::filesystem::path& pemFile) {
    const std::string origin = pemFile.string();
    TrustedKey key;
    // Checked before a byte of it is read, and read where the check resolved it to.
    const std::filesystem::path real = requireSafeAnchor(pemFile, "a trusted publisher key");
    const std::string text = readFile(real, 16384, "a public key file");
    key.publicKey = parsePublicKeyPem(text, origin);
    key.name = pemFile.stem().string(); // "hospital.pem" and "hospital.pub.pem" name "hospital"
    if (key.name.size() > 4 && key.name.ends_with(".pub")) key.name.resize(key.name.size() - 4);
    key.name = sim::displayName(key.name); // printed on one summary line
    key.source = origin;
    m_keys.push_back(std::move(key));
}

void TrustStore::addFolder(const std::filesystem::path& folder) {
    struct stat st {};
    if (::lstat(folder.c_str(), &st) != 0) return; // a folder that does not exist adds nothing
    const std::filesystem::path real = requireSafeAnchor(folder, "a trust folder"); // a link is refused
    std::error_code ec;
    if (!std::filesystem::is_directory(real, ec)) return;
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(real, ec))
        if (e.path().extension() == ".pem") files.push_back(folder / e.path().filename());
    if (ec) throw InputError(folder.string() + ": cannot list the trusted publisher keys (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    for (const std::filesystem::path& f : files)
        addKeyFile(f);
}

const TrustedKey* TrustStore::find(std::string_view publicKey) const {
    auto it = std::find_if(m_keys.begin(), m_keys.end(), [&](const TrustedKey& k) { return k.publicKey == publicKey; });
    return it == m_keys.end() ? nullptr : &*it;
}

Provenance checkProvenance(const CasePackage& package, const TrustPolicy& policy) {
    return checkProvenance(package.head(), policy);
}

std::vector<std::filesystem::path> systemTrustFolders() {
    std::vector<std::filesystem::path> out{"/etc/viscera/trusted-publishers"};
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) out.push_back((exe.parent_path().parent_path() / "share/viscera/trusted-publishers").lexically_normal());
    return out;
}

Provenance checkProvenance(const PackageHead& package, const TrustPolicy& policy) {
    Provenance p;
    p.file = package.name;
    p.sha256 = package.sha256;
    p.bytes = package.bytes;
    p.expires = package.manifest.expires.value_or("");
    p.allowUnsigned = policy.allowUnsigned;
    checkSignature(package, policy, p);
    checkExpiry(package, policy);
    checkRollback(package, policy);
    return p;
}

namespace {

/// Creates `folder` (0700) and its missing parents (0755, whatever the umask: a group-writable
/// parent would make the folder unsafe).
void createStateFolder(const std::filesystem::path& folder) {
    std::vector<std::filesystem::path> missing;
    for (std::filesystem::path p = folder; !p.empty() && p != p.parent_path(); p = p.parent_path()) {
        struct stat st {};
        if (::lstat(p.c_str(), &st) == 0) break;
        missing.push_back(p);
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        const mode_t mode = *it == folder ? 0700 : 0755;
        if (::mkdir(it->c_str(), mode) != 0 && errno != EEXIST)
            throw InputError(folder.string() + ": cannot create the state folder (" + it->string() + ": " +
                             std::strerror(errno) + ")");
        ::chmod(it->c_str(), mode); // the umask may have taken bits away; never adds any others may use
    }
}

/// The kiosk folder, when it exists and this account may use it.
bool usableKioskFolder() {
    std::error_code ec;
    return std::filesystem::is_directory(kSystemStateFolder, ec) &&
           ::access(std::string(kSystemStateFolder).c_str(), R_OK | W_OK | X_OK) == 0;
}

} // namespace

std::optional<std::filesystem::path> defaultStateFolder() {
    if (usableKioskFolder()) return std::filesystem::path(kSystemStateFolder);
    if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg == '/')
        return std::filesystem::path(xdg) / "viscera";
    if (const char* home = std::getenv("HOME"); home && *home == '/')
        return std::filesystem::path(home) / ".local/state/viscera";
    return std::nullopt;
}

std::optional<std::filesystem::path> stateFolder(const std::optional<std::filesystem::path>& given, StateUse use) {
    const std::optional<std::filesystem::path> folder = given ? given : defaultStateFolder();
    if (!folder) {
        if (use == StateUse::Check) return std::nullopt; // nothing recorded can be found
        throw InputError("the state folder: neither XDG_STATE_HOME nor HOME names a folder, so the case versions "
                         "run cannot be kept; give --state-dir DIR");
    }
    requireSafeAnchor(*folder, "the state folder"); // a link or a folder others may write: refused
    struct stat st {};
    if (::lstat(folder->c_str(), &st) != 0) {
        if (use == StateUse::Check) return std::nullopt; // no version was ever recorded there
        createStateFolder(*folder);
        requireSafeAnchor(*folder, "the state folder");
    }
    std::error_code ec;
    if (!std::filesystem::is_directory(*folder, ec))
        throw InputError(folder->string() + ": cannot use it as the state folder (not a folder" +
                         (ec ? ", " + ec.message() : std::string()) + ")");
    if (use == StateUse::Record && ::access(folder->c_str(), R_OK | W_OK | X_OK) != 0)
        throw InputError(folder->string() + ": cannot use it as the state folder (" + std::strerror(errno) +
                         "); give --state-dir DIR");
    return folder;
}

} // namespace viscera::vcase
