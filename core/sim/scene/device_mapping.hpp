#pragma once
/// How a haptic master drives something of a scene (an instrument's or the needle's "device"
/// block): the fields every such block has. Read and written by readDeviceMapping /
/// writeDeviceMapping (sim/scene/scene_json.hpp).
#include <string>

namespace viscera::sim {

struct DeviceMapping {
    bool declared = false;     ///< the block is present
    std::string hand = "any";  ///< "left", "right" or "any": which master drives it
    double motionScale = 0.25; ///< scene metres per device metre
    double forceScale = 1.0;   ///< device newtons per scene newton
    double maxForceN = 15.0;   ///< N, the case's maximum device force
};

} // namespace viscera::sim
