// Procedural tissue texture [A §6.2]: ms to generate a 2048² map set (quadtree mask, then diffuse,
// roughness, height and normal), and to encode it as PNG (8 and 16 bits, the four maps concurrently).
// The spec is a 7-level quadtree with tiles on a coarse level and the last two levels, after
// [A Fig. 6.4]. Columns: phase, median and min over the runs (ms).
// Run: ./build/bench/bench_texture [runs] [size]     (defaults 5, 2048)
#include "bake/texture.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace viscera::bake;

namespace {

std::string specText(int size) {
    return R"({"name": "bench", "size": )" + std::to_string(size) + R"(, "seed": 17, "levels": 7,
  "patterns": [
    {"level": 2, "tile": {"shape": "gaussian", "sigma": 0.5}, "offset": {"radius": [0, 0.4]},
     "scale": {"uniform": [1, 1.6]}, "opacity": [0.3, 0.6], "blend": "add"},
    {"level": 5, "tile": {"shape": "gaussian", "sigma": 0.4}, "rotation_deg": [0, 360],
     "offset": {"radius": [0, 0.5], "angle_deg": [0, 360]}, "scale": {"width": [0.8, 1.6], "height": [0.6, 1.2]},
     "opacity": [0.4, 0.9], "blend": "add"},
    {"level": 6, "tile": {"shape": "bell"}, "offset": {"radius": [0, 0.6]}, "scale": {"uniform": [0.6, 1.4]},
     "opacity": [0.2, 0.7], "probability": 0.8, "blend": "max"}
  ],
  "palette": {"colors": ["#7a1f24", "#b8474a", "#e8a890"]},
  "maps": {"diffuse": {}, "roughness": {"values": [0.55, 0.3]}, "height": {"blur_px": 1.5},
           "normal": {"depth": 0.01}}})";
}

double ms(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Row {
    const char* name;
    std::vector<double> times;
};

} // namespace

int main(int argc, char** argv) {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
    const int size = argc > 2 ? std::atoi(argv[2]) : 2048;
    const TextureSpec spec = parseTextureSpec(specText(size), "bench_texture", ".");
    Row mask{"mask", {}}, maps{"maps (diffuse, roughness, height, normal)", {}}, set{"set = mask + maps", {}},
        png8{"encode PNG, 8-bit", {}}, png16{"encode PNG, 16-bit", {}};
    size_t bytes8 = 0, bytes16 = 0;
    for (int r = 0; r < runs; ++r) {
        using Clock = std::chrono::steady_clock;
        const auto t0 = Clock::now();
        const GrayImage m = generateMask(spec.quadtree);
        const auto t1 = Clock::now();
        MaterialParams material = spec.material;
        material.diffuseColors = spec.palette->colors;
        const MaterialMaps out = generateMaps(m, material, {true, true, false, true, true});
        const auto t2 = Clock::now();
        mask.times.push_back(ms(t0, t1));
        maps.times.push_back(ms(t1, t2));
        set.times.push_back(ms(t0, t2));
        // As viscera-studio texture encodes them: the maps concurrently (encodeTextureSet).
        TextureSet made;
        made.mask = m;
        made.maps = out;
        for (int bits : {8, 16}) {
            TextureSpec at = spec;
            for (MapRequest& req : at.maps)
                req.bits = bits;
            const auto e0 = Clock::now();
            size_t n = 0;
            for (const EncodedFile& f : encodeTextureSet(at, made))
                n += f.bytes.size();
            (bits == 8 ? png8 : png16).times.push_back(ms(e0, Clock::now()));
            (bits == 8 ? bytes8 : bytes16) = n;
        }
    }
    std::printf("texture map set %dx%d, %zu patterned levels of 7, %d runs\n", size, size,
                spec.quadtree.patterns.size(), runs);
    std::printf("%-44s %10s %10s\n", "phase", "median ms", "min ms");
    for (Row* row : {&mask, &maps, &set, &png8, &png16}) {
        std::vector<double> t = row->times;
        std::sort(t.begin(), t.end());
        std::printf("%-44s %10.1f %10.1f\n", row->name, t[t.size() / 2], t.front());
    }
    std::printf("PNG bytes of the 4 maps: 8-bit %zu, 16-bit %zu\n", bytes8, bytes16);
    return 0;
}
