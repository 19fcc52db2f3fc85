#pragma once
/// Opens a device from the player's --device SPEC:
///   replay:<file>        a recorded trajectory (trajectory.hpp), deterministic clock
///   scripted:<name>      a named procedural motion (scripted_device.hpp)
///   console:<host:port>  the bimanual console over UDP (console_device.hpp)
///   keyboard             keys and mouse in the trainee window (keyboard_device.hpp)
#include "haptics/device.hpp"

#include <memory>
#include <string>

namespace viscera::haptics {

struct DeviceSpec {
    enum class Kind { Replay, Scripted, Console, Keyboard } kind = Kind::Scripted;
    std::string argument; ///< file, script name or host:port
    std::string text;     ///< the spec as given
};

/// Throws viscera::InputError "--device '<spec>': <rule>" for an unknown backend or an empty or
/// malformed argument.
DeviceSpec parseDeviceSpec(const std::string& spec);

struct DeviceOpenOptions {
    double maxForce = 15.0; ///< N, the device's capability where the backend has none
    int64_t consoleTimeout_ns = 100'000'000;
    /// console: the pairing key file shared with the console (64 hex digits); required.
    std::string pairingKeyFile;
    bool loopReplay = false;
};

/// Opens the device (reads the trajectory or the pairing key, binds the socket). Throws
/// viscera::InputError naming the file or address and the rule.
std::unique_ptr<Device> openDevice(const DeviceSpec& spec, const DeviceOpenOptions& options = {});

} // namespace viscera::haptics
