// PNG through libpng's simplified API (zlib compression and CRCs are libpng's).
#include "render/image.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <png.h>

#include <cstring>
#include <stdexcept>
#include <string>

namespace viscera::render {

namespace {

/// libpng's description of `image` for writing, into `png`; false when the image is empty or its
/// size is inconsistent (each caller throws its own error).
bool writeHeader(const Image& image, png_image& png) {
    if (image.width <= 0 || image.height <= 0 || image.rgba.size() != size_t(image.width) * image.height * 4)
        return false;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = png_uint_32(image.width);
    png.height = png_uint_32(image.height);
    png.format = PNG_FORMAT_RGBA;
    return true;
}

} // namespace

void writePng(const std::filesystem::path& path, const Image& image) {
    png_image png;
    if (!writeHeader(image, png))
        throw std::runtime_error(path.string() + ": render::writePng(): image is empty or its size is inconsistent");
    // Encoded in memory, then written atomically: a failed or killed write leaves the old file.
    writeFileAtomic(path, encodePng(image));
}

Image readPng(const std::filesystem::path& path) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.string().c_str()))
        throw std::runtime_error(path.string() + ": cannot read PNG: " + png.message);
    png.format = PNG_FORMAT_RGBA;
    Image image;
    image.width = int(png.width);
    image.height = int(png.height);
    image.rgba.resize(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) {
        const std::string why = png.message;
        png_image_free(&png);
        throw std::runtime_error(path.string() + ": cannot decode PNG: " + why);
    }
    return image;
}

std::string encodePng(const Image& image) {
    png_image png;
    if (!writeHeader(image, png))
        throw std::invalid_argument("render::encodePng(): image is empty or its size is inconsistent");
    png_alloc_size_t size = 0;
    if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.rgba.data(), 0, nullptr))
        throw std::runtime_error(std::string("render::encodePng(): ") + png.message);
    std::string out(size, '\0');
    if (!png_image_write_to_memory(&png, out.data(), &size, 0, image.rgba.data(), 0, nullptr))
        throw std::runtime_error(std::string("render::encodePng(): ") + png.message);
    out.resize(size);
    return out;
}

std::pair<uint32_t, uint32_t> pngSize(std::string_view bytes, const std::string& origin) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (bytes.empty() || !png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
        throw InputError(origin + ": not a PNG image (" + std::string(bytes.empty() ? "empty" : png.message) + ")");
    const std::pair<uint32_t, uint32_t> size{png.width, png.height};
    png_image_free(&png);
    return size;
}

Image decodePng(std::string_view bytes, const std::string& origin, int maxSide) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (bytes.empty() || !png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
        throw InputError(origin + ": not a PNG image (" + std::string(bytes.empty() ? "empty" : png.message) + ")");
    if (png.width == 0 || png.height == 0 || png.width > png_uint_32(maxSide) || png.height > png_uint_32(maxSide)) {
        png_image_free(&png);
        throw InputError(origin + ": PNG is " + std::to_string(png.width) + " x " + std::to_string(png.height) +
                         " pixels (each side must be 1 to " + std::to_string(maxSide) + ")");
    }
    Image image;
    image.width = int(png.width);
    image.height = int(png.height);
    if (png.format & PNG_FORMAT_FLAG_LINEAR) {
        // 16-bit samples: read them as stored (libpng's 8-bit output would treat them as linear
        // light and re-encode them to sRGB, which a normal or roughness map must not be) and round
        png.format = PNG_FORMAT_LINEAR_RGB_ALPHA;
        std::vector<uint16_t> wide(PNG_IMAGE_SIZE(png) / 2);
        if (!png_image_finish_read(&png, nullptr, wide.data(), 0, nullptr)) {
            const std::string why = png.message;
            png_image_free(&png);
            throw InputError(origin + ": cannot decode PNG (" + why + ")");
        }
        image.rgba.resize(wide.size());
        for (size_t i = 0; i < wide.size(); ++i)
            image.rgba[i] = uint8_t((uint32_t(wide[i]) * 255u + 32767u) / 65535u);
        return image;
    }
    png.format = PNG_FORMAT_RGBA;
    image.rgba.resize(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) {
        const std::string why = png.message;
        png_image_free(&png);
        throw InputError(origin + ": cannot decode PNG (" + why + ")");
    }
    return image;
}

} // namespace viscera::render
