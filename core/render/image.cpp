#include "render/image.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace viscera::render {

ImageDifference compareImages(const Image& a, const Image& b, const std::vector<uint8_t>& mask) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("render::compareImages(): sizes differ (" + std::to_string(a.width) + "x" +
                                    std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                                    std::to_string(b.height) + ")");
    const size_t n = size_t(a.width) * a.height;
    if (!mask.empty() && mask.size() != n)
        throw std::invalid_argument("render::compareImages(): mask has " + std::to_string(mask.size()) +
                                    " entries, image has " + std::to_string(n) + " pixels");
    ImageDifference d;
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!mask.empty() && !mask[i]) continue;
        ++d.pixels;
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            const int e = std::abs(int(a.rgba[4 * i + c]) - int(b.rgba[4 * i + c]));
            sum += double(e) * e;
            d.maxChannel = std::max(d.maxChannel, e);
            differs |= e != 0;
        }
        d.differing += differs;
    }
    d.rmse = d.pixels ? std::sqrt(sum / (3.0 * double(d.pixels))) : 0.0;
    return d;
}

} // namespace viscera::render
