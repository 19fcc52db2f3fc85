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
    requireSafeAnchor(pemFile, "a trusted publisher key"); // before a byte of it is read
    const std::string text = readFile(pemFile, 16384, "a public key file");
    key.publicKey = parsePublicKeyPem(text, origin);
    key.name = pemFile.stem().string(); // "hospital.pem" and "hospital.pub.pem" name "hospital"
    if (key.name.size() > 4 && key.name.ends_with(".pub")) key.name.resize(key.name.size() - 4);
    key.name = sim::displayName(key.name); // printed on one summary line
    key.source = origin;
    m_keys.push_back(std::move(key));
}

void TrustStore::addFolder(const std::filesystem::path& folder) {
    requireSafeAnchor(folder, "a trust folder"); // a link is refused, not followed
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) return;
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(folder, ec))
        if (e.path().extension() == ".pem") files.push_back(e.path());
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

/// Creates `folder` (its parents as the umask says, itself 0700) when missing.
void createStateFolder(const std::filesystem::path& folder) {
    std::error_code ec;
    if (::mkdir(folder.c_str(), 0700) == 0 || errno == EEXIST) return;
    std::filesystem::create_directories(folder.parent_path(), ec);
    if (::mkdir(folder.c_str(), 0700) != 0 && errno != EEXIST)
        throw InputError(folder.string() + ": cannot create the state folder (" + std::strerror(errno) + ")");
}

} // namespace

std::filesystem::path defaultStateFolder() {
    std::error_code ec;
    if (std::filesystem::is_directory(kSystemStateFolder, ec)) return kSystemStateFolder;
    if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg == '/')
        return std::filesystem::path(xdg) / "viscera";
    if (const char* home = std::getenv("HOME"); home && *home == '/')
        return std::filesystem::path(home) / ".local/state/viscera";
    throw InputError("the state folder: neither XDG_STATE_HOME nor HOME names a folder, so the versions run "
                     "cannot be kept; give --state-dir DIR");
}

std::filesystem::path stateFolder(const std::optional<std::filesystem::path>& given) {
    const std::filesystem::path folder = given ? *given : defaultStateFolder();
    requireSafeAnchor(folder, "the state folder"); // a link or a folder others may write: refused
    createStateFolder(folder);
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
        throw InputError(folder.string() + ": cannot use it as the state folder (not a folder" +
                         (ec ? ", " + ec.message() : std::string()) + ")");
    requireSafeAnchor(folder, "the state folder");
    return folder;
}

} // namespace viscera::vcase
