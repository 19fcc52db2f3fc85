// The SHA-256 compression state is copied per message (RFC 2104 with precomputed pads): the only
// way through OpenSSL 3.0 that neither allocates nor locks per message (EVP_MAC and EVP_MD_CTX
// copies allocate), so the low-level SHA-256 interface is used on purpose.
#define OPENSSL_SUPPRESS_DEPRECATED
#include "haptics/link_auth.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <openssl/crypto.h>
#include <openssl/rand.h>
#include <openssl/sha.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace viscera::haptics {

struct LinkMac::Impl {
    SHA256_CTX inner{}, outer{}; ///< after the key's ipad / opad block
};

LinkMac::LinkMac() : m_impl(std::make_unique<Impl>()) {}

LinkMac::LinkMac(const LinkKey& key) : LinkMac() {
    setKey(key);
}

LinkMac::~LinkMac() = default;

void LinkMac::setKey(const LinkKey& key) {
    uint8_t ipad[SHA256_CBLOCK], opad[SHA256_CBLOCK];
    std::fill(ipad, ipad + SHA256_CBLOCK, uint8_t(0x36));
    std::fill(opad, opad + SHA256_CBLOCK, uint8_t(0x5c));
    for (size_t i = 0; i < key.size(); ++i) { // a 32-byte key is shorter than the block: padded with zeros
        ipad[i] ^= key[i];
        opad[i] ^= key[i];
    }
    SHA256_Init(&m_impl->inner);
    SHA256_Update(&m_impl->inner, ipad, sizeof ipad);
    SHA256_Init(&m_impl->outer);
    SHA256_Update(&m_impl->outer, opad, sizeof opad);
    OPENSSL_cleanse(ipad, sizeof ipad);
    OPENSSL_cleanse(opad, sizeof opad);
    m_hasKey = true;
}

void LinkMac::digest(const uint8_t* data, size_t size, uint8_t* out) const {
    uint8_t inner[SHA256_DIGEST_LENGTH];
    SHA256_CTX c = m_impl->inner;
    SHA256_Update(&c, data, size);
    SHA256_Final(inner, &c);
    c = m_impl->outer;
    SHA256_Update(&c, inner, sizeof inner);
    SHA256_Final(out, &c);
}

void LinkMac::sign(const uint8_t* data, size_t size, uint8_t* tag) const {
    uint8_t full[SHA256_DIGEST_LENGTH];
    digest(data, size, full);
    std::copy(full, full + kLinkTagSize, tag);
}

bool LinkMac::verify(const uint8_t* data, size_t size, const uint8_t* tag) const {
    if (!m_hasKey) return false;
    uint8_t full[SHA256_DIGEST_LENGTH];
    digest(data, size, full);
    return CRYPTO_memcmp(full, tag, kLinkTagSize) == 0;
}

NonceSource::NonceSource() {
    m_mac.setKey(randomKey());
}

Nonce NonceSource::next() {
    uint8_t counter[8], full[SHA256_DIGEST_LENGTH];
    for (int k = 0; k < 8; ++k)
        counter[k] = uint8_t(m_counter >> (8 * k));
    ++m_counter;
    m_mac.digest(counter, sizeof counter, full);
    Nonce n{};
    std::copy(full, full + kNonceSize, n.begin());
    return n;
}

LinkKey loadPairingKey(const std::string& path) {
    const std::string text = readFile(path, 4096, "a pairing key file");
    requirePrivateFile(path, "the pairing key");
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

LinkKey sessionKey(const LinkMac& pairing, const Nonce& client, const Nonce& server) {
    static const char label[] = "viscera console session v2";
    uint8_t msg[sizeof label - 1 + 2 * kNonceSize];
    std::copy(label, label + sizeof label - 1, msg);
    std::copy(client.begin(), client.end(), msg + sizeof label - 1);
    std::copy(server.begin(), server.end(), msg + sizeof label - 1 + kNonceSize);
    LinkKey k{};
    pairing.digest(msg, sizeof msg, k.data());
    return k;
}

LinkKey sessionKey(const LinkKey& pairing, const Nonce& client, const Nonce& server) {
    return sessionKey(LinkMac(pairing), client, server);
}

} // namespace viscera::haptics
