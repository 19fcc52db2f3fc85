#include "project/sample_atlas.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::studio {

bake::Rgb8Image sampleAtlas(int size, std::span<const AtlasRegion> regions) {
    bake::Rgb8Image img;
    img.width = img.height = size;
    img.pixels.assign(size_t(size) * size_t(size) * 3, 40);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double u = (x + 0.5) / size, v = 1.0 - (y + 0.5) / size; // first row is v = 1
            uint8_t* p = &img.pixels[(size_t(y) * size_t(size) + size_t(x)) * 3];
            for (const AtlasRegion& r : regions) {
                if (u < r.x0 || u > r.x1 || v < r.y0 || v > r.y1) continue;
                const double s = 16 * (u - r.x0) / (r.x1 - r.x0), t = 16 * (v - r.y0) / (r.y1 - r.y0);
                const double line = std::min({std::abs(s - std::round(s)), std::abs(t - std::round(t))});
                const double k = line < 0.06 ? 0.7 : 1.0;
                p[0] = uint8_t(std::lround(k * r.colour.r));
                p[1] = uint8_t(std::lround(k * r.colour.g));
                p[2] = uint8_t(std::lround(k * r.colour.b));
            }
        }
    return img;
}

} // namespace viscera::studio
