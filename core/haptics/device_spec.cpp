#include "haptics/device_spec.hpp"

#include "haptics/console_device.hpp"
#include "haptics/keyboard_device.hpp"
#include "haptics/replay_device.hpp"
#include "haptics/scripted_device.hpp"
#include "sim/util/error.hpp"

namespace viscera::haptics {

DeviceSpec parseDeviceSpec(const std::string& spec) {
    DeviceSpec d;
    d.text = spec;
    const std::string what = "--device '" + spec + "'";
    if (spec == "keyboard") {
        d.kind = DeviceSpec::Kind::Keyboard;
        return d;
    }
    const size_t colon = spec.find(':');
    const std::string kind = spec.substr(0, colon);
    d.argument = colon == std::string::npos ? "" : spec.substr(colon + 1);
    if (kind == "replay")
        d.kind = DeviceSpec::Kind::Replay;
    else if (kind == "scripted")
        d.kind = DeviceSpec::Kind::Scripted;
    else if (kind == "console")
        d.kind = DeviceSpec::Kind::Console;
    else
        throw InputError(
            what +
            ": unknown device backend (expected replay:<file>, scripted:<name>, console:<host:port> or keyboard)");
    if (d.argument.empty()) throw InputError(what + ": " + kind + " needs an argument after ':'");
    if (d.kind == DeviceSpec::Kind::Console) parseEndpoint(d.argument, what); // validates early
    return d;
}

std::unique_ptr<Device> openDevice(const DeviceSpec& spec, const DeviceOpenOptions& options) {
    switch (spec.kind) {
    case DeviceSpec::Kind::Replay: {
        ReplayOptions o;
        o.loop = options.loopReplay;
        o.maxForce = options.maxForce;
        o.name = "replay:" + spec.argument;
        return std::make_unique<ReplayDevice>(Trajectory::load(spec.argument), o);
    }
    case DeviceSpec::Kind::Scripted:
        return std::make_unique<ScriptedDevice>(spec.argument, options.maxForce);
    case DeviceSpec::Kind::Console: {
        ConsoleDeviceOptions o;
        if (options.pairingKeyFile.empty())
            throw InputError("--device '" + spec.text +
                             "': the console link needs the pairing key shared with the console: --pairing-key FILE "
                             "(viscera-console-sim --make-pairing-key FILE makes one)");
        o.pairingKey = loadPairingKey(options.pairingKeyFile);
        o.timeout_ns = options.consoleTimeout_ns;
        o.maxForce = options.maxForce;
        return std::make_unique<ConsoleDevice>(parseEndpoint(spec.argument, "--device '" + spec.text + "'"), o);
    }
    case DeviceSpec::Kind::Keyboard:
        return std::make_unique<KeyboardDevice>();
    }
    return nullptr;
}

const char* handName(Hand h) {
    switch (h) {
    case Hand::Left:
        return "left";
    case Hand::Right:
        return "right";
    case Hand::Either:
        return "either";
    }
    return "?";
}

} // namespace viscera::haptics
