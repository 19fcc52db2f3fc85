#include "haptics/link_auth.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <openssl/core_names.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace viscera::haptics {

struct LinkMac::Impl {
    EVP_MAC* mac = nullptr;
    EVP_MAC_CTX* ctx = nullptr;
    ~Impl() {
        EVP_MAC_CTX_free(ctx);
        EVP_MAC_free(mac);
    }
};

LinkMac::LinkMac() : m_impl(std::make_unique<Impl>()) {}

LinkMac::LinkMac(const LinkKey& key) : LinkMac() {
    setKey(key);
}

LinkMac::~LinkMac() = default;

void LinkMac::setKey(const LinkKey& key) {
    if (!m_impl->mac) m_impl->mac = EVP_MAC_fetch(nullptr, "HMAC", nullptr);
    if (!m_impl->ctx && m_impl->mac) m_impl->ctx = EVP_MAC_CTX_new(m_impl->mac);
    char digest[] = "SHA256";
    const OSSL_PARAM params[] = {OSSL_PARAM_construct_utf8_string(OSSL_MAC_PARAM_DIGEST, digest, 0),
                                 OSSL_PARAM_construct_end()};
    if (!m_impl->ctx || EVP_MAC_init(m_impl->ctx, key.data(), key.size(), params) != 1)
        throw std::runtime_error("haptics::LinkMac: OpenSSL cannot make an HMAC-SHA256");
    m_hasKey = true;
}

void LinkMac::sign(const uint8_t* data, size_t size, uint8_t* tag) const {
    uint8_t full[EVP_MAX_MD_SIZE];
    size_t n = 0;
    // Re-initialising with no key keeps the key set last (no allocation).
    if (!m_hasKey || EVP_MAC_init(m_impl->ctx, nullptr, 0, nullptr) != 1 ||
        EVP_MAC_update(m_impl->ctx, data, size) != 1 || EVP_MAC_final(m_impl->ctx, full, &n, sizeof full) != 1 ||
        n < kLinkTagSize) {
        std::fill(tag, tag + kLinkTagSize, 0); // never verifies: verify() recomputes and fails alike
        return;
    }
    std::copy(full, full + kLinkTagSize, tag);
}

bool LinkMac::verify(const uint8_t* data, size_t size, const uint8_t* tag) const {
    if (!m_hasKey) return false;
    uint8_t expected[kLinkTagSize];
    uint8_t full[EVP_MAX_MD_SIZE];
    size_t n = 0;
    if (EVP_MAC_init(m_impl->ctx, nullptr, 0, nullptr) != 1 || EVP_MAC_update(m_impl->ctx, data, size) != 1 ||
        EVP_MAC_final(m_impl->ctx, full, &n, sizeof full) != 1 || n < kLinkTagSize)
        return false;
    std::copy(full, full + kLinkTagSize, expected);
    return CRYPTO_memcmp(expected, tag, kLinkTagSize) == 0;
}

LinkKey loadPairingKey(const std::string& path) {
    const std::string text = readFile(path, 4096, "a pairing key file");
    std::string hex = text;
    while (!hex.empty() && (hex.back() == '\n' || hex.back() == '\r'))
        hex.pop_back();
    if (hex.size() != 2 * kLinkKeySize)
        throw InputError(path + ": a pairing key is 64 hexadecimal digits (this file has " +
                         std::to_string(hex.size()) + " characters)");
    LinkKey key{};
    for (size_t i = 0; i < hex.size(); ++i) {
        const char c = hex[i];
        if (!std::isxdigit(static_cast<unsigned char>(c)))
            throw InputError(path + ": a pairing key is 64 hexadecimal digits (character " + std::to_string(i + 1) +
                             " is not one)");
        const int v = std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : std::tolower(c) - 'a' + 10;
        key[i / 2] = static_cast<uint8_t>(key[i / 2] | (v << (i % 2 ? 0 : 4)));
    }
    return key;
}

std::string formatPairingKey(const LinkKey& key) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (uint8_t b : key) {
        s += digits[b >> 4];
        s += digits[b & 15];
    }
    return s + "\n";
}

namespace {
template <size_t N> std::array<uint8_t, N> randomBytes() {
    std::array<uint8_t, N> b{};
    if (RAND_bytes(b.data(), static_cast<int>(N)) != 1)
        throw std::runtime_error("haptics: OpenSSL has no random bytes (RAND_bytes failed)");
    return b;
}
} // namespace

LinkKey randomKey() {
    return randomBytes<kLinkKeySize>();
}

Nonce randomNonce() {
    return randomBytes<kNonceSize>();
}

LinkKey sessionKey(const LinkKey& pairing, const Nonce& client, const Nonce& server) {
    static const char label[] = "viscera console session v2";
    uint8_t msg[sizeof label - 1 + 2 * kNonceSize];
    std::copy(label, label + sizeof label - 1, msg);
    std::copy(client.begin(), client.end(), msg + sizeof label - 1);
    std::copy(server.begin(), server.end(), msg + sizeof label - 1 + kNonceSize);
    uint8_t full[EVP_MAX_MD_SIZE];
    unsigned n = 0;
    if (!HMAC(EVP_sha256(), pairing.data(), static_cast<int>(pairing.size()), msg, sizeof msg, full, &n) ||
        n != kLinkKeySize)
        throw std::runtime_error("haptics: OpenSSL cannot derive the session key (HMAC failed)");
    LinkKey k{};
    std::copy(full, full + kLinkKeySize, k.begin());
    return k;
}

} // namespace viscera::haptics
