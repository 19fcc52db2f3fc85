#pragma once
/// Message authentication of the console link (protocol version 2, packaging/console-protocol.md):
/// HMAC-SHA256 (RFC 2104 over OpenSSL's SHA-256) truncated to 128 bits. A pairing key shared by
/// the player and the console authenticates the handshake; each handshake derives a fresh session
/// key from it and both sides' nonces, which authenticates every state and command of that session.
///
/// Real-time safe after construction: signing, verifying, setting a key, deriving a session key
/// and drawing a nonce from a NonceSource neither allocate, lock nor throw (the servo thread calls
/// them at 1 kHz); constructors and loadPairingKey may.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace viscera::haptics {

constexpr size_t kLinkKeySize = 32; ///< bytes of a pairing or session key
constexpr size_t kLinkTagSize = 16; ///< bytes of a packet's MAC (HMAC-SHA256, first 16 bytes)
constexpr size_t kNonceSize = 16;
using LinkKey = std::array<uint8_t, kLinkKeySize>;
using Nonce = std::array<uint8_t, kNonceSize>;

/// HMAC-SHA256 under one key: the inner and outer hash states of the key are computed once
/// (setKey) and copied for every message. Without a key nothing verifies.
class LinkMac {
public:
    LinkMac();
    explicit LinkMac(const LinkKey& key);
    ~LinkMac();
    LinkMac(const LinkMac&) = delete;
    LinkMac& operator=(const LinkMac&) = delete;

    void setKey(const LinkKey& key);
    bool hasKey() const { return m_hasKey; }
    /// HMAC-SHA256(key, data[0, size)), all 32 bytes, into out.
    void digest(const uint8_t* data, size_t size, uint8_t* out) const;
    /// The first kLinkTagSize bytes of the HMAC into tag.
    void sign(const uint8_t* data, size_t size, uint8_t* tag) const;
    /// True when tag (kLinkTagSize bytes) is the MAC of data[0, size); constant time.
    bool verify(const uint8_t* data, size_t size, const uint8_t* tag) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
    bool m_hasKey = false;
};

/// Fresh, unpredictable nonces without a system call per nonce: HMAC-SHA256 under a random seed
/// (OpenSSL RAND_bytes at construction) of a counter. Construction throws std::runtime_error when
/// no random bytes can be had.
class NonceSource {
public:
    NonceSource();
    Nonce next();

private:
    LinkMac m_mac;
    uint64_t m_counter = 0;
};

/// Reads a pairing key file: 64 hexadecimal digits (a trailing newline allowed), a regular file
/// that other users can neither read nor write. Throws viscera::InputError "<path>: <rule>".
LinkKey loadPairingKey(const std::string& path);
/// The key as the file holds it: 64 lowercase hex digits and a newline.
std::string formatPairingKey(const LinkKey& key);
/// Fresh random bytes (OpenSSL RAND_bytes); throws std::runtime_error when none can be had.
LinkKey randomKey();
Nonce randomNonce();
/// The session key of one handshake: HMAC-SHA256(pairing key, "viscera console session v2" ‖
/// client ‖ server); `pairing` holds the pairing key.
LinkKey sessionKey(const LinkMac& pairing, const Nonce& client, const Nonce& server);
LinkKey sessionKey(const LinkKey& pairing, const Nonce& client, const Nonce& server);

} // namespace viscera::haptics
