#pragma once
/// Publishing a case: the publisher's Ed25519 key (made, kept outside every project folder,
/// loaded) and the case's expiry. exportCase signs with it (CasePublishing); players trust the
/// public half (packaging/vcase-spec.md, "Signatures").
#include "case/signing.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace viscera::studio {

/// Where the studio looks for the publisher key when none is given:
/// $XDG_CONFIG_HOME/viscera/publisher-key.pem, else ~/.config/viscera/publisher-key.pem.
std::filesystem::path defaultPublisherKeyPath();

/// The key an export signs with when none is named (`viscera-studio export` without --sign-key,
/// File → Export case… in the studio): defaultPublisherKeyPath() where that file exists, else none
/// (the case then goes out unsigned, which the exporter says: unsignedCaseWarning).
std::optional<std::filesystem::path> defaultPublisherKey();

/// The signer a case names when no --signer is given: the stem of a named key file, "publisher"
/// for the default key.
std::string defaultSignerName(const std::optional<std::filesystem::path>& namedKey);

/// Why a case goes out unsigned when no key is named and none is at `missingKey`, and how to
/// sign it: "the case is not signed: no publisher key at <file> (make one with 'viscera-studio
/// keygen'); players refuse it without --allow-unsigned".
std::string unsignedCaseWarning(const std::filesystem::path& missingKey);

/// The public key file beside a private one: "key.pem" -> "key.pub.pem" ("key" -> "key.pub.pem").
std::filesystem::path publicKeyPathFor(const std::filesystem::path& privateFile);

struct NewPublisherKey {
    std::filesystem::path privateFile, publicFile;
    std::string keyId; ///< vcase::keyId
};

/// Makes a key pair: the private key at `privateFile` (mode 0600, its folder created 0700 when
/// missing) and the public key beside it (publicKeyPathFor, mode 0644), both written atomically.
/// Refuses, before writing anything, to replace an existing file (a lost key cannot sign updates
/// of the cases already published): InputError "<file>: already exists (…)".
NewPublisherKey makePublisherKey(const std::filesystem::path& privateFile);

/// Loads the key that signs the case of the project in `projectDir`. Refuses a key inside the
/// project folder (it would travel with the project): InputError "<key>: the publisher key must
/// be kept outside the project folder '<dir>'"; the rules of vcase::SigningKey::load.
vcase::SigningKey loadPublisherKey(const std::filesystem::path& keyFile, const std::filesystem::path& projectDir);

/// An --expires value: "YYYY-MM-DD" (the end of that day, UTC) or "YYYY-MM-DDTHH:MM:SSZ", after
/// `now` (seconds since the epoch). Returns the manifest form; throws InputError "--expires '…': …".
std::string parseExpiry(std::string_view text, int64_t now);

} // namespace viscera::studio
