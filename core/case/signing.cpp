#include "case/signing.hpp"

#include "case/sha256.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>

#include <stdexcept>

namespace viscera::vcase {
namespace {

struct PkeyFree {
    void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
};
struct BioFree {
    void operator()(BIO* b) const { BIO_free(b); }
};
struct MdCtxFree {
    void operator()(EVP_MD_CTX* c) const { EVP_MD_CTX_free(c); }
};
using Pkey = std::unique_ptr<EVP_PKEY, PkeyFree>;
using Bio = std::unique_ptr<BIO, BioFree>;
using MdCtx = std::unique_ptr<EVP_MD_CTX, MdCtxFree>;

[[noreturn]] void opensslFailed(const char* what) {
    throw std::runtime_error(std::string("vcase: OpenSSL ") + what + " failed");
}

/// Never prompts: an encrypted PEM key is refused instead of asking on the terminal.
int noPassphrase(char*, int, int, void*) {
    return -1;
}

/// The key's type for a message ("RSA", "SM2", …); some keys have no name.
std::string typeName(EVP_PKEY* key) {
    const char* name = EVP_PKEY_get0_type_name(key);
    return name ? name : "an unknown type";
}

Bio readBio(std::string_view text) {
    Bio bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
    if (!bio) opensslFailed("BIO_new_mem_buf");
    return bio;
}

template <typename Write> std::string pemOf(Write write) {
    Bio bio(BIO_new(BIO_s_mem()));
    if (!bio || write(bio.get()) != 1) opensslFailed("PEM_write");
    char* data = nullptr;
    const long n = BIO_get_mem_data(bio.get(), &data);
    return std::string(data, static_cast<size_t>(n));
}

std::string rawPublicKey(EVP_PKEY* key) {
    std::string raw(kPublicKeyBytes, '\0');
    size_t n = raw.size();
    if (EVP_PKEY_get_raw_public_key(key, reinterpret_cast<unsigned char*>(raw.data()), &n) != 1 || n != kPublicKeyBytes)
        opensslFailed("EVP_PKEY_get_raw_public_key");
    return raw;
}

/// Lowercase hex of exactly `bytes` bytes, or the field's error.
std::string unhex(const sim::JsonField& f, size_t bytes) {
    const std::string text = f.string();
    auto digit = [](char c) { return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1; };
    bool ok = text.size() == 2 * bytes;
    std::string out(bytes, '\0');
    for (size_t i = 0; ok && i < bytes; ++i) {
        const int hi = digit(text[2 * i]), lo = digit(text[2 * i + 1]);
        ok = hi >= 0 && lo >= 0;
        out[i] = static_cast<char>(ok ? hi * 16 + lo : 0);
    }
    if (!ok) f.fail("must be " + std::to_string(2 * bytes) + " lowercase hex characters");
    return out;
}

} // namespace

struct SigningKey::Impl {
    Pkey key;
};

SigningKey::SigningKey(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SigningKey::SigningKey(SigningKey&&) noexcept = default;
SigningKey& SigningKey::operator=(SigningKey&&) noexcept = default;
SigningKey::~SigningKey() = default;

SigningKey SigningKey::generate() {
    std::unique_ptr<EVP_PKEY_CTX, decltype(&EVP_PKEY_CTX_free)> ctx(EVP_PKEY_CTX_new_id(EVP_PKEY_ED25519, nullptr),
                                                                    EVP_PKEY_CTX_free);
    EVP_PKEY* key = nullptr;
    if (!ctx || EVP_PKEY_keygen_init(ctx.get()) != 1 || EVP_PKEY_keygen(ctx.get(), &key) != 1)
        opensslFailed("Ed25519 key generation");
    return SigningKey(std::make_unique<Impl>(Impl{Pkey(key)}));
}

SigningKey SigningKey::load(const std::filesystem::path& pemFile) {
    const std::string origin = pemFile.string();
    const std::string text = readFile(pemFile, 16384, "a publisher key file");
    requirePrivateFile(pemFile, "the publisher key");
    Bio bio = readBio(text);
    Pkey key(PEM_read_bio_PrivateKey(bio.get(), nullptr, noPassphrase, nullptr));
    ERR_clear_error(); // a failed parse leaves its reasons queued; the message below says it
    if (!key) throw InputError(origin + ": not an unencrypted PEM private key (make one with 'viscera-studio keygen')");
    if (EVP_PKEY_get_id(key.get()) != EVP_PKEY_ED25519)
        throw InputError(origin + ": not an Ed25519 key (found " + typeName(key.get()) +
                         "; packages are signed with Ed25519)");
    return SigningKey(std::make_unique<Impl>(Impl{std::move(key)}));
}

std::string SigningKey::publicKey() const {
    return rawPublicKey(m_impl->key.get());
}

std::string SigningKey::privatePem() const {
    return pemOf(
        [&](BIO* b) { return PEM_write_bio_PrivateKey(b, m_impl->key.get(), nullptr, nullptr, 0, nullptr, nullptr); });
}

std::string SigningKey::publicPem() const {
    return pemOf([&](BIO* b) { return PEM_write_bio_PUBKEY(b, m_impl->key.get()); });
}

std::string SigningKey::sign(std::string_view message) const {
    MdCtx ctx(EVP_MD_CTX_new());
    std::string sig(kSignatureBytes, '\0');
    size_t n = sig.size();
    if (!ctx || EVP_DigestSignInit(ctx.get(), nullptr, nullptr, nullptr, m_impl->key.get()) != 1 ||
        EVP_DigestSign(ctx.get(), reinterpret_cast<unsigned char*>(sig.data()), &n,
                       reinterpret_cast<const unsigned char*>(message.data()), message.size()) != 1 ||
        n != kSignatureBytes)
        opensslFailed("Ed25519 signing");
    return sig;
}

std::string keyId(std::string_view raw) {
    return "ed25519:" + sha256Hex(raw).substr(0, 16);
}

std::string signedMessage(std::string_view manifestText) {
    static constexpr std::string_view kLabel{"viscera-vcase-manifest-signature-v1\0", 36};
    std::string m(kLabel);
    m += manifestText;
    return m;
}

bool verifySignature(std::string_view raw, std::string_view message, std::string_view signature) {
    if (raw.size() != kPublicKeyBytes || signature.size() != kSignatureBytes) return false;
    Pkey key(EVP_PKEY_new_raw_public_key(EVP_PKEY_ED25519, nullptr, reinterpret_cast<const unsigned char*>(raw.data()),
                                         raw.size()));
    MdCtx ctx(EVP_MD_CTX_new());
    if (!key || !ctx || EVP_DigestVerifyInit(ctx.get(), nullptr, nullptr, nullptr, key.get()) != 1) return false;
    return EVP_DigestVerify(ctx.get(), reinterpret_cast<const unsigned char*>(signature.data()), signature.size(),
                            reinterpret_cast<const unsigned char*>(message.data()), message.size()) == 1;
}

std::string parsePublicKeyPem(std::string_view text, const std::string& origin) {
    Bio bio = readBio(text);
    Pkey key(PEM_read_bio_PUBKEY(bio.get(), nullptr, noPassphrase, nullptr));
    ERR_clear_error();
    if (!key) throw InputError(origin + ": not a PEM public key ('-----BEGIN PUBLIC KEY-----')");
    if (EVP_PKEY_get_id(key.get()) != EVP_PKEY_ED25519)
        throw InputError(origin + ": not an Ed25519 public key (found " + typeName(key.get()) + ")");
    return rawPublicKey(key.get());
}

std::string PackageSignature::toJsonText() const {
    nlohmann::json j = {{"schemaVersion", 1},
                        {"algorithm", "ed25519"},
                        {"signer", signer},
                        {"publicKey", hexText(publicKey)},
                        {"signature", hexText(signature)}};
    return j.dump(2) + "\n";
}

PackageSignature PackageSignature::parse(std::string_view text, const std::string& origin) {
    const nlohmann::json j = sim::parseJsonText(text, origin);
    const sim::JsonField root(j, "", origin);
    root.object({"schemaVersion", "algorithm", "signer", "publicKey", "signature"});
    const int version = root["schemaVersion"].integer();
    if (version != 1) root.failAt("schemaVersion", std::to_string(version) + " is not supported (this player reads 1)");
    root["algorithm"].choice({"ed25519"}, "a supported signature algorithm");
    PackageSignature s;
    s.signer = root["signer"].displayText(kMaxSignerBytes);
    s.publicKey = unhex(root["publicKey"], kPublicKeyBytes);
    s.signature = unhex(root["signature"], kSignatureBytes);
    return s;
}

std::string signManifest(const SigningKey& key, std::string_view signer, std::string_view manifestText) {
    PackageSignature s;
    s.signer = std::string(signer);
    s.publicKey = key.publicKey();
    s.signature = key.sign(signedMessage(manifestText));
    return s.toJsonText();
}

} // namespace viscera::vcase
