#pragma once
/// Publisher signatures of .vcase packages: Ed25519 (OpenSSL) over manifest.json.
///
/// A signed package holds `signature.json` beside `manifest.json` (packaging/vcase-spec.md):
///
///   {"schemaVersion": 1, "algorithm": "ed25519", "signer": "Viscera samples",
///    "publicKey": "<64 lowercase hex: the raw 32-byte key>",
///    "signature": "<128 lowercase hex: Ed25519 over signedMessage(manifest.json's bytes)>"}
///
/// The manifest binds the case id, its version, its expiry and the size and SHA-256 of every other
/// file, so one signature over its exact bytes covers the whole package. No OpenSSL type appears
/// here; keys are PEM files (PKCS#8 private key, SubjectPublicKeyInfo public key).
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace viscera::vcase {

/// The signature's entry name at the package root (never listed in the manifest).
inline constexpr std::string_view kSignatureName = "signature.json";
inline constexpr size_t kPublicKeyBytes = 32; ///< raw Ed25519 public key
inline constexpr size_t kSignatureBytes = 64; ///< raw Ed25519 signature
/// signature.json is small; a larger entry is refused before it is read.
inline constexpr uint64_t kMaxSignatureBytes = 4096;
/// A signer's display name: printable text of at most this many bytes.
inline constexpr size_t kMaxSignerBytes = 100;

/// How a key is named to people: "ed25519:" and the first 16 hex digits of the SHA-256 of the raw
/// public key (`raw`: kPublicKeyBytes bytes).
std::string keyId(std::string_view raw);

/// What a package signature covers: a fixed label that no other Viscera signature uses, then the
/// exact bytes of manifest.json.
std::string signedMessage(std::string_view manifestText);

/// True when `signature` (kSignatureBytes) is the Ed25519 signature of `message` under the raw
/// public key `raw` (kPublicKeyBytes). False for keys or signatures of the wrong size.
bool verifySignature(std::string_view raw, std::string_view message, std::string_view signature);

/// A publisher's Ed25519 private key. Move-only; the key material lives in OpenSSL.
class SigningKey {
public:
    /// A fresh key from OpenSSL's random generator.
    static SigningKey generate();
    /// Reads a PEM private key. Throws viscera::InputError, one line naming the file: not found,
    /// not a regular file, open to other users ("chmod 600 it"), not PEM, encrypted, not Ed25519.
    static SigningKey load(const std::filesystem::path& pemFile);

    SigningKey(SigningKey&&) noexcept;
    SigningKey& operator=(SigningKey&&) noexcept;
    ~SigningKey();

    std::string publicKey() const;  ///< raw, kPublicKeyBytes
    std::string privatePem() const; ///< PKCS#8 PEM text (a secret: write it with mode 0600)
    std::string publicPem() const;  ///< SubjectPublicKeyInfo PEM text, what players trust
    /// The Ed25519 signature of `message` (kSignatureBytes). Deterministic.
    std::string sign(std::string_view message) const;

private:
    struct Impl;
    explicit SigningKey(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

/// The raw public key of a PEM public key (`text` read from `origin`). Throws viscera::InputError
/// "<origin>: not a PEM public key" or "<origin>: not an Ed25519 public key (…)".
std::string parsePublicKeyPem(std::string_view text, const std::string& origin);

/// signature.json, parsed and formatted here only (one reader and writer).
struct PackageSignature {
    std::string signer;    ///< display name the publisher chose (the player names the key it trusts)
    std::string publicKey; ///< raw, kPublicKeyBytes
    std::string signature; ///< raw, kSignatureBytes

    std::string toJsonText() const;
    /// Strict: unknown or missing fields, another algorithm, wrong hex lengths throw
    /// viscera::InputError "<origin>: <field>: <rule>".
    static PackageSignature parse(std::string_view text, const std::string& origin);
};

/// Signs manifest.json's bytes: the signature.json text for them.
std::string signManifest(const SigningKey& key, std::string_view signer, std::string_view manifestText);

} // namespace viscera::vcase
