// The console link's message authentication (haptics/link_auth.hpp) against OpenSSL's HMAC: the
// input is a 32-byte key, a 16-byte tag, one byte that picks a bit to flip, then the message
// (shorter inputs are padded with zeros). Checks that
//   - digest() is HMAC-SHA256(key, message) and sign() its first 16 bytes;
//   - verify() accepts exactly the tag sign() makes: the given tag iff it is that MAC, never one
//     with a bit flipped (in the tag or the message), never under a keyless LinkMac, and a LinkMac
//     whose key was set again answers as a fresh one;
//   - sessionKey() is HMAC-SHA256(pairing key, "viscera console session v2" ‖ client ‖ server) for
//     nonces taken from the message, the same from the key and from its LinkMac.
#include "haptics/link_auth.hpp"

#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

namespace {

using namespace viscera::haptics;

void require(bool ok) {
    if (!ok) std::abort();
}

std::array<uint8_t, 32> hmacSha256(const LinkKey& key, const uint8_t* data, size_t size) {
    std::array<uint8_t, 32> out{};
    unsigned int n = 0;
    static const uint8_t empty = 0;
    require(HMAC(EVP_sha256(), key.data(), int(key.size()), size ? data : &empty, size, out.data(), &n) != nullptr);
    require(n == out.size());
    return out;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    constexpr size_t kHead = kLinkKeySize + kLinkTagSize + 1;
    std::vector<uint8_t> in(data, data + size);
    if (in.size() < kHead) in.resize(kHead, 0);
    LinkKey key{};
    std::copy_n(in.begin(), kLinkKeySize, key.begin());
    const uint8_t* tag = in.data() + kLinkKeySize;
    const uint8_t flip = in[kLinkKeySize + kLinkTagSize];
    std::vector<uint8_t> message(in.begin() + kHead, in.end());

    const LinkMac mac(key);
    require(mac.hasKey());
    const auto reference = hmacSha256(key, message.data(), message.size());
    std::array<uint8_t, 32> full{};
    mac.digest(message.data(), message.size(), full.data());
    require(full == reference);
    std::array<uint8_t, kLinkTagSize> mine{};
    mac.sign(message.data(), message.size(), mine.data());
    require(std::equal(mine.begin(), mine.end(), reference.begin()));

    const bool given = std::equal(mine.begin(), mine.end(), tag);
    require(mac.verify(message.data(), message.size(), tag) == given);
    require(mac.verify(message.data(), message.size(), mine.data()));
    std::array<uint8_t, kLinkTagSize> flipped = mine;
    flipped[(flip >> 3) % kLinkTagSize] ^= uint8_t(1u << (flip & 7));
    require(!mac.verify(message.data(), message.size(), flipped.data()));
    if (!message.empty()) {
        std::vector<uint8_t> altered = message;
        altered[flip % altered.size()] ^= uint8_t(1u << (flip & 7));
        require(!mac.verify(altered.data(), altered.size(), mine.data()));
    }
    const LinkMac keyless;
    require(!keyless.hasKey() && !keyless.verify(message.data(), message.size(), mine.data()));
    LinkMac rekeyed(LinkKey{});
    rekeyed.setKey(key);
    require(rekeyed.verify(message.data(), message.size(), mine.data()) &&
            rekeyed.verify(message.data(), message.size(), tag) == given);

    Nonce client{}, server{};
    for (size_t i = 0; i < kNonceSize; ++i) {
        client[i] = i < message.size() ? message[i] : 0;
        server[i] = kNonceSize + i < message.size() ? message[kNonceSize + i] : 0;
    }
    static constexpr std::string_view kLabel = "viscera console session v2";
    std::vector<uint8_t> derivation(kLabel.begin(), kLabel.end());
    derivation.insert(derivation.end(), client.begin(), client.end());
    derivation.insert(derivation.end(), server.begin(), server.end());
    const auto expected = hmacSha256(key, derivation.data(), derivation.size());
    const LinkKey session = sessionKey(key, client, server);
    require(std::equal(session.begin(), session.end(), expected.begin()));
    require(sessionKey(mac, client, server) == session);
    return 0;
}
