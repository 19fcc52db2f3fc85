#pragma once
/// 8-bit RGBA images (rows top to bottom) and the comparisons golden-image tests use.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace viscera::render {

struct Image {
    int width = 0, height = 0;
    std::vector<uint8_t> rgba; ///< width·height·4 bytes, row-major, first row at the top
    bool empty() const { return rgba.empty(); }
    const uint8_t* pixel(int x, int y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

struct ImageDifference {
    double rmse = 0;      ///< over RGB of the compared pixels, in 8-bit units
    int maxChannel = 0;   ///< largest |a − b| of one RGB channel
    size_t pixels = 0;    ///< pixels compared
    size_t differing = 0; ///< pixels with any RGB channel different
};

/// Compares RGB of two images of the same size; `mask` (width·height, non-zero = compared) may be
/// empty. Throws std::invalid_argument when sizes differ.
ImageDifference compareImages(const Image& a, const Image& b, const std::vector<uint8_t>& mask = {});

/// Writes an 8-bit RGBA PNG (libpng, zlib-compressed). Throws std::runtime_error naming the path.
void writePng(const std::filesystem::path& path, const Image& image);
/// Reads any PNG as 8-bit RGBA. Throws std::runtime_error naming the path.
Image readPng(const std::filesystem::path& path);
/// An 8-bit RGBA PNG in memory. Throws std::invalid_argument for an empty or inconsistent image.
std::string encodePng(const Image& image);
/// Decodes PNG bytes (a case's texture entry) as 8-bit RGBA (16-bit samples are rounded). The
/// size is checked against `maxSide` before anything is allocated. Throws viscera::InputError
/// "<origin>: <rule>" for data that is not a PNG, is truncated or is too large.
Image decodePng(std::string_view bytes, const std::string& origin, int maxSide = 8192);
/// Width and height of PNG bytes from the header alone (nothing decoded). Throws
/// viscera::InputError "<origin>: not a PNG image (...)" as decodePng does.
std::pair<uint32_t, uint32_t> pngSize(std::string_view bytes, const std::string& origin);

} // namespace viscera::render
