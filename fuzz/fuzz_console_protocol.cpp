// The console protocol decoder (protocol v2, authenticated): a UDP datagram as a state, command,
// hello and welcome packet, the MAC checked under a fixed key (fuzz_link_key.hpp; never throws:
// a decode error is its answer). The first byte picks the mode, the rest is the datagram:
//   even  the datagram as received: the frame checks and the MAC refusal (the seeds are signed
//         with the fixed key, so their mutations reach the MAC check)
//   odd   the datagram re-signed with the fixed key first (its last 16 bytes replaced by the MAC of
//         the rest), so that the fuzzer gets past the MAC to the field checks
// Then the properties of the decoder: no packet decodes under a keyless LinkMac or under another
// key; a decoded packet encodes again to a datagram that decodes (byte for byte the same one for
// commands, hellos and welcomes; a state's quaternion is normalized when decoded).
#include "fuzz_link_key.hpp"
#include "haptics/console_protocol.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

using namespace viscera::haptics;

const LinkMac& fixedMac() {
    static const LinkMac mac(viscera::fuzz::kFuzzLinkKey);
    return mac;
}

const LinkMac& otherMac() {
    static const LinkMac mac([] {
        LinkKey k = viscera::fuzz::kFuzzLinkKey;
        k[0] ^= 1;
        return k;
    }());
    return mac;
}

void require(bool ok) {
    if (!ok) std::abort();
}

template <class Packet> void check(const std::vector<uint8_t>& datagram, bool exactReencode) {
    Packet p;
    const DecodeError e = decode(datagram.data(), datagram.size(), p, fixedMac());
    require(decodeErrorName(e) != nullptr);
    static const LinkMac keyless;
    Packet q;
    require(decode(datagram.data(), datagram.size(), q, keyless) != DecodeError::None);
    require(decode(datagram.data(), datagram.size(), q, otherMac()) != DecodeError::None);
    if (e != DecodeError::None) return;
    std::array<uint8_t, kMaxPacketSize> again{};
    const size_t n = encode(p, again.data(), again.size(), fixedMac());
    require(n == datagram.size());
    require(decode(again.data(), n, q, fixedMac()) == DecodeError::None);
    if (exactReencode) require(std::equal(again.begin(), again.begin() + n, datagram.begin()));
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    std::vector<uint8_t> datagram(data + 1, data + size);
    if ((data[0] & 1) && datagram.size() >= kLinkTagSize)
        fixedMac().sign(datagram.data(), datagram.size() - kLinkTagSize,
                        datagram.data() + datagram.size() - kLinkTagSize);
    (void)peekType(datagram.data(), datagram.size());
    check<StatePacket>(datagram, false);
    check<CommandPacket>(datagram, true);
    check<HelloPacket>(datagram, true);
    check<WelcomePacket>(datagram, true);
    return 0;
}
