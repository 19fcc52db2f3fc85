#pragma once
// The texture tests' spec (test_texture.cpp, test_texture_spec_writer.cpp): one fixture for both.
#include <string>

namespace viscera::test {

/// A 7-level quadtree with tiles on two levels (after [A Fig. 6.4]) and every map; `extra`
/// members are spliced into the root object.
inline std::string specText(int seed, const std::string& extra = "") {
    return R"({
  "name": "layer", "size": 128, "seed": )" +
           std::to_string(seed) + R"(, "levels": 6, "bit_depth": 8,
  "patterns": [
    {"level": 3, "tile": {"shape": "gaussian", "sigma": 0.45}, "rotation_deg": [0, 360],
     "offset": {"radius": [0, 0.5], "angle_deg": [0, 360]}, "scale": {"width": [0.8, 1.8], "height": [0.6, 1.4]},
     "opacity": [0.5, 1], "blend": "add"},
    {"level": 5, "tile": {"shape": "bell"}, "offset": {"radius": [0, 0.6]}, "scale": {"uniform": [0.6, 1.6]},
     "opacity": [0.2, 0.6], "probability": 0.7, "blend": "max"}
  ],
  "palette": {"colors": ["#7a1f24", "#c65a4f", "#efc1a8"]},
  "maps": {"mask": {"bit_depth": 16}, "diffuse": {}, "roughness": {"values": [0.6, 0.3]}, "metallic": {"values": [0, 0.1]},
           "height": {"blur_px": 1}, "normal": {"depth": 0.02}, "palette": {"swatch_px": 8}})" +
           extra + "}";
}

} // namespace viscera::test
