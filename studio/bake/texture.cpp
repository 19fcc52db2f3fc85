// Quadtree pattern mask [A §6.2.1], material maps [A §6.2.2] and image files (OpenCV private).
#include "bake/texture.hpp"

#include "bake/texture_random.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace viscera::bake {
namespace {

using sim::formatNumber;

using detail::splitmix64;
using detail::uniform01;

double draw(std::mt19937_64& rng, const Range& r) {
    return r.lo + (r.hi - r.lo) * uniform01(rng);
}

// ---- parameter checks -----------------------------------------------------------------------

[[noreturn]] void badParam(const char* where, const std::string& field, const std::string& rule) {
    throw std::invalid_argument(std::string(where) + field + " " + rule);
}

void checkRange(const char* where, const std::string& field, const Range& r, double lo, double hi, bool loOpen) {
    auto inside = [&](double v) { return std::isfinite(v) && (loOpen ? v > lo : v >= lo) && v <= hi; };
    if (!inside(r.lo) || !inside(r.hi) || r.lo > r.hi)
        badParam(where, field,
                 std::string(1, '[') + formatNumber(r.lo) + ", " + formatNumber(r.hi) + "] must be an interval in " +
                     (loOpen ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) + "]");
}

void checkQuadtree(const QuadtreeParams& p) {
    const char* where = "bake::generateMask(): ";
    if (p.size < 8 || p.size > 4096 || !std::has_single_bit(static_cast<unsigned>(p.size)))
        badParam(where, "size", std::to_string(p.size) + " must be a power of two in [8, 4096]");
    const int maxLevels = std::countr_zero(static_cast<unsigned>(p.size)) + 1;
    if (p.levels < 1 || p.levels > maxLevels)
        badParam(where, "levels", std::to_string(p.levels) + " must be in [1, " + std::to_string(maxLevels) + "]");
    if (!(p.base >= 0 && p.base <= 1)) badParam(where, "base", "must be in [0, 1]");
    std::vector<bool> used(static_cast<size_t>(p.levels), false);
    for (size_t i = 0; i < p.patterns.size(); ++i) {
        const LevelPattern& l = p.patterns[i];
        const std::string f = "patterns[" + std::to_string(i) + "].";
        if (l.level < 0 || l.level >= p.levels)
            badParam(where, f + "level",
                     std::to_string(l.level) + " is not a level of a " + std::to_string(p.levels) + "-level quadtree");
        if (used[static_cast<size_t>(l.level)])
            badParam(where, f + "level", std::to_string(l.level) + " already has a pattern");
        used[static_cast<size_t>(l.level)] = true;
        checkRange(where, f + "rotationDeg", l.rotationDeg, -360, 360, false);
        checkRange(where, f + "offsetRadius", l.offsetRadius, 0, 2, false);
        checkRange(where, f + "offsetAngleDeg", l.offsetAngleDeg, -360, 360, false);
        checkRange(where, f + "width", l.width, 0, 4, true);
        if (!l.uniformScale) checkRange(where, f + "height", l.height, 0, 4, true);
        checkRange(where, f + "opacity", l.opacity, 0, 1, false);
        if (!(l.probability >= 0 && l.probability <= 1)) badParam(where, f + "probability", "must be in [0, 1]");
        if (l.tile.shape == TileShape::Gaussian && !(l.tile.sigma > 0 && l.tile.sigma <= 4))
            badParam(where, f + "tile.sigma", "must be in (0, 4]");
        if (l.tile.shape == TileShape::Image) {
            const GrayImage& im = l.tile.image;
            if (im.width < 1 || im.height < 1 || im.width > 4096 || im.height > 4096 ||
                im.pixels.size() != static_cast<size_t>(im.width) * im.height)
                badParam(where, f + "tile.image", "must be a non-empty image of at most 4096 x 4096 pixels");
        }
    }
}

// ---- tiles ----------------------------------------------------------------------------------

/// Where one node's tile lies: centre (pixels), half extents (pixels), rotation, opacity.
struct Placement {
    double cx = 0, cy = 0, halfW = 1, halfH = 1, cosR = 1, sinR = 0, alpha = 1;
};

/// Rasterizes `shape(u, v)` (tile coordinates: u, v in [-1, 1] across the tile) over the tile's
/// bounding box into `level` by maximum. With `wrap` the box continues across the borders.
template <class Shape> void rasterize(const Placement& p, int size, bool wrap, float* level, const Shape& shape) {
    const double ex = std::abs(p.cosR) * p.halfW + std::abs(p.sinR) * p.halfH + 1.0;
    const double ey = std::abs(p.sinR) * p.halfW + std::abs(p.cosR) * p.halfH + 1.0;
    int x0 = static_cast<int>(std::floor(p.cx - ex)), x1 = static_cast<int>(std::ceil(p.cx + ex));
    int y0 = static_cast<int>(std::floor(p.cy - ey)), y1 = static_cast<int>(std::ceil(p.cy + ey));
    if (!wrap) {
        x0 = std::max(x0, 0);
        y0 = std::max(y0, 0);
        x1 = std::min(x1, size - 1);
        y1 = std::min(y1, size - 1);
    }
    const double invW = 1.0 / p.halfW, invH = 1.0 / p.halfH;
    const int mask = size - 1; // size is a power of two: & mask is the toroidal wrap
    for (int y = y0; y <= y1; ++y) {
        const double dy = y + 0.5 - p.cy;
        float* row = level + static_cast<size_t>(y & mask) * size;
        for (int x = x0; x <= x1; ++x) {
            const double dx = x + 0.5 - p.cx;
            // u along (cos, -sin), v along (sin, cos): the tile turned counter-clockwise on screen
            const double u = (dx * p.cosR - dy * p.sinR) * invW;
            const double v = (dx * p.sinR + dy * p.cosR) * invH;
            const float value = static_cast<float>(shape(u, v) * p.alpha);
            float& cell = row[x & mask];
            if (value > cell) cell = value;
        }
    }
}

/// Mip chain of an image tile: level 0 the image, each next one half the size (area average).
std::vector<cv::Mat> mipChain(const GrayImage& image) {
    std::vector<cv::Mat> chain;
    chain.push_back(cv::Mat(image.height, image.width, CV_32F, const_cast<float*>(image.pixels.data())).clone());
    while (chain.back().cols > 1 || chain.back().rows > 1) {
        cv::Mat next;
        cv::resize(chain.back(), next, cv::Size(std::max(1, chain.back().cols / 2), std::max(1, chain.back().rows / 2)),
                   0, 0, cv::INTER_AREA);
        chain.push_back(next);
    }
    return chain;
}

/// Bilinear sample of `m` at tile coordinates (u, v) in [-1, 1]; texels outside are 0.
double sampleTile(const cv::Mat& m, double u, double v) {
    const double tx = (u + 1) * 0.5 * m.cols - 0.5, ty = (v + 1) * 0.5 * m.rows - 0.5;
    const int ix = static_cast<int>(std::floor(tx)), iy = static_cast<int>(std::floor(ty));
    const double fx = tx - ix, fy = ty - iy;
    auto at = [&](int x, int y) -> double {
        return x < 0 || y < 0 || x >= m.cols || y >= m.rows ? 0.0 : m.at<float>(y, x);
    };
    return (1 - fy) * ((1 - fx) * at(ix, iy) + fx * at(ix + 1, iy)) +
           fy * ((1 - fx) * at(ix, iy + 1) + fx * at(ix + 1, iy + 1));
}

void drawTile(const LevelPattern& pattern, const std::vector<cv::Mat>& mips, const Placement& p, int size, bool wrap,
              float* level) {
    switch (pattern.tile.shape) {
    case TileShape::Disc: {
        const double invW = 1.0 / p.halfW, invH = 1.0 / p.halfH;
        rasterize(p, size, wrap, level, [&](double u, double v) {
            const double rho = std::sqrt(u * u + v * v);
            if (rho >= 1.0 + 2.0 * std::max(invW, invH)) return 0.0;
            if (rho < 1e-12) return 1.0;
            // distance to the border in pixels: (1 - ρ) / |∇ρ|
            const double grad = std::sqrt(u * u * invW * invW + v * v * invH * invH) / rho;
            return std::clamp(0.5 + (1.0 - rho) / grad, 0.0, 1.0);
        });
        break;
    }
    case TileShape::Gaussian: {
        const double k = -1.0 / (2.0 * pattern.tile.sigma * pattern.tile.sigma);
        const double edge = std::exp(k), scale = 1.0 / (1.0 - edge);
        rasterize(p, size, wrap, level, [&](double u, double v) {
            const double r2 = u * u + v * v;
            return r2 >= 1.0 ? 0.0 : (std::exp(k * r2) - edge) * scale;
        });
        break;
    }
    case TileShape::Bell:
        rasterize(p, size, wrap, level, [&](double u, double v) {
            const double r2 = u * u + v * v;
            return r2 >= 1.0 ? 0.0 : 0.5 * (1.0 + std::cos(std::numbers::pi * std::sqrt(r2)));
        });
        break;
    case TileShape::Image: {
        // The mip whose texels are about one pixel of the tile.
        const double perPixel =
            std::max(pattern.tile.image.width / (2 * p.halfW), pattern.tile.image.height / (2 * p.halfH));
        const int mip = std::clamp(static_cast<int>(std::floor(std::log2(std::max(perPixel, 1.0)))), 0,
                                   static_cast<int>(mips.size()) - 1);
        const cv::Mat& m = mips[static_cast<size_t>(mip)];
        rasterize(p, size, wrap, level, [&](double u, double v) {
            return std::abs(u) > 1.0 || std::abs(v) > 1.0 ? 0.0 : sampleTile(m, u, v);
        });
        break;
    }
    }
}

float blend(BlendMode mode, float c, float l) {
    float r = c;
    switch (mode) {
    case BlendMode::Add:
        r = c + l;
        break;
    case BlendMode::Subtract:
        r = c - l;
        break;
    case BlendMode::Max:
        r = std::max(c, l);
        break;
    case BlendMode::Min:
        r = std::min(c, l);
        break;
    case BlendMode::Multiply:
        r = c * l;
        break;
    }
    return std::clamp(r, 0.0f, 1.0f);
}

// ---- maps -----------------------------------------------------------------------------------

/// Runs f(pixel index) over every pixel of a width × height image, rows in parallel. For
/// per-pixel work only: each pixel's result depends on its inputs alone, so the output does not
/// depend on the thread count.
template <class F> void forEachRow(int height, int width, const F& f) {
    cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < width; ++x)
                f(static_cast<size_t>(y) * width + x);
    });
}

GrayImage mapMask(const GrayImage& mask, const MaskMapping& m) {
    GrayImage out{mask.width, mask.height, std::vector<float>(mask.pixels.size())};
    const double span = m.atOne - m.atZero;
    for (size_t i = 0; i < mask.pixels.size(); ++i)
        out.pixels[i] = static_cast<float>(m.atZero + span * mask.pixels[i]);
    return out;
}

RgbImage gradientMap(const GrayImage& mask, const std::vector<Rgb8>& colors, const std::vector<double>& stopsIn) {
    std::vector<double> stops = stopsIn;
    if (stops.empty())
        for (size_t i = 0; i < colors.size(); ++i)
            stops.push_back(colors.size() == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(colors.size() - 1));
    RgbImage out{mask.width, mask.height, std::vector<float>(mask.pixels.size() * 3)};
    forEachRow(mask.height, mask.width, [&](size_t i) {
        const double m = mask.pixels[i];
        size_t k = 0; // the segment [stops[k], stops[k + 1]] holding m
        while (k + 1 < stops.size() && m > stops[k + 1])
            ++k;
        const Rgb8 a = colors[k], b = colors[std::min(k + 1, colors.size() - 1)];
        const double len = k + 1 < stops.size() ? stops[k + 1] - stops[k] : 0.0;
        const double t = len > 0 ? std::clamp((m - stops[k]) / len, 0.0, 1.0) : (m > stops[k] ? 1.0 : 0.0);
        out.pixels[3 * i + 0] = static_cast<float>((a.r + t * (b.r - a.r)) / 255.0);
        out.pixels[3 * i + 1] = static_cast<float>((a.g + t * (b.g - a.g)) / 255.0);
        out.pixels[3 * i + 2] = static_cast<float>((a.b + t * (b.b - a.b)) / 255.0);
    });
    return out;
}

void checkMaterial(const MaterialParams& p, bool diffuse) {
    const char* where = "bake::generateMaps(): ";
    if (diffuse && p.diffuseColors.empty()) badParam(where, "diffuseColors", "must not be empty");
    if (diffuse && !p.diffuseStops.empty()) {
        if (p.diffuseStops.size() != p.diffuseColors.size())
            badParam(where, "diffuseStops", "must have one stop per colour");
        for (size_t i = 0; i < p.diffuseStops.size(); ++i)
            if (!(p.diffuseStops[i] >= 0 && p.diffuseStops[i] <= 1) ||
                (i > 0 && p.diffuseStops[i] < p.diffuseStops[i - 1]))
                badParam(where, "diffuseStops", "must be non-decreasing in [0, 1]");
    }
    for (const auto& [name, m] : {std::pair{"roughness", p.roughness}, {"metallic", p.metallic}, {"height", p.height}})
        if (!(m.atZero >= 0 && m.atZero <= 1 && m.atOne >= 0 && m.atOne <= 1))
            badParam(where, name, "values must be in [0, 1]");
    if (!(p.heightBlurPx >= 0 && p.heightBlurPx <= 64)) badParam(where, "heightBlurPx", "must be in [0, 64]");
    if (!(p.normalDepth > 0 && p.normalDepth <= 1)) badParam(where, "normalDepth", "must be in (0, 1]");
}

// ---- PNG ------------------------------------------------------------------------------------

void checkBits(const char* where, int bits) {
    if (bits != 8 && bits != 16) throw std::invalid_argument(std::string(where) + "bits must be 8 or 16");
}

std::string pngBytes(const cv::Mat& m) {
    std::vector<uchar> buf;
    // zlib level 3: a 2048² RGB map encodes about 3x faster than at level 6, 10-20 % larger.
    if (!cv::imencode(".png", m, buf, {cv::IMWRITE_PNG_COMPRESSION, 3}))
        throw std::runtime_error("bake::encodePng(): OpenCV could not encode the image");
    return std::string(buf.begin(), buf.end());
}

/// [0, 1] floats as codes, channels in the order given (R G B reversed to OpenCV's B G R).
std::string encodeFloats(const std::vector<float>& px, int width, int height, int channels, int bits) {
    const double maxCode = bits == 8 ? 255.0 : 65535.0;
    cv::Mat m(height, width, CV_MAKETYPE(bits == 8 ? CV_8U : CV_16U, channels));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < channels; ++c) {
                const size_t i = (static_cast<size_t>(y) * width + x) * channels + c;
                const int dst = channels == 3 ? 2 - c : c;
                const auto code = std::lround(std::clamp(static_cast<double>(px[i]), 0.0, 1.0) * maxCode);
                if (bits == 8)
                    m.ptr<uint8_t>(y)[x * channels + dst] = static_cast<uint8_t>(code);
                else
                    m.ptr<uint16_t>(y)[x * channels + dst] = static_cast<uint16_t>(code);
            }
    return pngBytes(m);
}

cv::Mat decodeMat(std::string_view bytes, int flags, const std::string& label) {
    cv::Mat m;
    if (!bytes.empty()) {
        cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
        try {
            m = cv::imdecode(raw, flags);
        } catch (const cv::Exception&) {
            m.release();
        }
    }
    if (m.empty()) throw InputError(label + ": not a readable image");
    return m;
}

void checkSides(const cv::Mat& m, int maxSide, const std::string& label) {
    if (m.cols > maxSide || m.rows > maxSide)
        throw InputError(label + ": image is " + std::to_string(m.cols) + " x " + std::to_string(m.rows) +
                         " pixels, larger than the limit of " + std::to_string(maxSide) + " x " +
                         std::to_string(maxSide));
}

} // namespace

std::string hexColor(Rgb8 c) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string s = "#";
    for (uint8_t v : {c.r, c.g, c.b}) {
        s += kHex[v >> 4];
        s += kHex[v & 0xf];
    }
    return s;
}

std::optional<Rgb8> parseHexColor(std::string_view t) {
    if (t.size() != 7 || t[0] != '#') return std::nullopt;
    uint8_t v[3] = {};
    for (int i = 0; i < 6; ++i) {
        const char c = t[static_cast<size_t>(i) + 1];
        int d = c >= '0' && c <= '9'   ? c - '0'
                : c >= 'a' && c <= 'f' ? c - 'a' + 10
                : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                       : -1;
        if (d < 0) return std::nullopt;
        v[i / 2] = static_cast<uint8_t>(v[i / 2] * 16 + d);
    }
    return Rgb8{v[0], v[1], v[2]};
}

GrayImage generateMask(const QuadtreeParams& params) {
    checkQuadtree(params);
    const int size = params.size;
    const size_t count = static_cast<size_t>(size) * size;
    GrayImage canvas{size, size, std::vector<float>(count, static_cast<float>(params.base))};
    std::vector<const LevelPattern*> order;
    for (const LevelPattern& p : params.patterns)
        order.push_back(&p);
    std::sort(order.begin(), order.end(),
              [](const LevelPattern* a, const LevelPattern* b) { return a->level < b->level; });
    std::vector<float> level(count);
    for (const LevelPattern* pattern : order) {
        std::fill(level.begin(), level.end(), 0.0f);
        const std::vector<cv::Mat> mips =
            pattern->tile.shape == TileShape::Image ? mipChain(pattern->tile.image) : std::vector<cv::Mat>{};
        // One stream per level: adding or changing another level leaves this one's draws alone.
        std::mt19937_64 rng(splitmix64(params.seed ^ splitmix64(static_cast<uint64_t>(pattern->level) + 1)));
        const int nodes = 1 << pattern->level;
        const double nodeSize = static_cast<double>(size) / nodes;
        const double degree = std::numbers::pi / 180.0;
        for (int iy = 0; iy < nodes; ++iy)
            for (int ix = 0; ix < nodes; ++ix) {
                // Every node makes the same draws in the same order, whether it gets a tile or not.
                const bool present = uniform01(rng) < pattern->probability;
                const double radius = draw(rng, pattern->offsetRadius) * nodeSize;
                const double angle = draw(rng, pattern->offsetAngleDeg) * degree;
                const double w = draw(rng, pattern->width);
                const double h = draw(rng, pattern->height);
                const double rotation = draw(rng, pattern->rotationDeg) * degree;
                const double alpha = draw(rng, pattern->opacity);
                if (!present || alpha <= 0) continue;
                Placement p;
                p.cx = (ix + 0.5) * nodeSize + radius * std::cos(angle);
                p.cy = (iy + 0.5) * nodeSize - radius * std::sin(angle);
                p.halfW = 0.5 * w * nodeSize;
                p.halfH = 0.5 * (pattern->uniformScale ? w : h) * nodeSize;
                p.cosR = std::cos(rotation);
                p.sinR = std::sin(rotation);
                p.alpha = alpha;
                drawTile(*pattern, mips, p, size, params.tileable, level.data());
            }
        for (size_t i = 0; i < count; ++i)
            canvas.pixels[i] = blend(pattern->blend, canvas.pixels[i], level[i]);
    }
    return canvas;
}

GrayImage blurGaussian(const GrayImage& image, double sigmaPx, bool wrap) {
    if (!(sigmaPx >= 0) || !std::isfinite(sigmaPx))
        throw std::invalid_argument("bake::blurGaussian(): sigma must be >= 0");
    if (sigmaPx == 0 || image.pixels.empty()) return image;
    const int radius = static_cast<int>(std::ceil(3 * sigmaPx));
    std::vector<double> kernel(static_cast<size_t>(2 * radius + 1));
    double sum = 0;
    for (int k = -radius; k <= radius; ++k)
        sum += kernel[static_cast<size_t>(k + radius)] = std::exp(-k * k / (2 * sigmaPx * sigmaPx));
    for (double& k : kernel)
        k /= sum;
    // One pass along rows of `n` samples spaced `stride` apart, `lines` of them `lineStride` apart.
    // Lines run in parallel, each through its own padded copy (no line depends on another).
    auto pass = [&](const std::vector<float>& in, std::vector<float>& out, int n, int stride, int lines,
                    int lineStride) {
        cv::parallel_for_(cv::Range(0, lines), [&](const cv::Range& range) {
            std::vector<float> line(static_cast<size_t>(n + 2 * radius));
            for (int l = range.start; l < range.end; ++l) {
                const size_t base = static_cast<size_t>(l) * lineStride;
                for (int i = -radius; i < n + radius; ++i) {
                    const int j = wrap ? ((i % n) + n) % n : std::clamp(i, 0, n - 1);
                    line[static_cast<size_t>(i + radius)] = in[base + static_cast<size_t>(j) * stride];
                }
                for (int i = 0; i < n; ++i) {
                    double acc = 0;
                    for (size_t k = 0; k < kernel.size(); ++k)
                        acc += kernel[k] * line[static_cast<size_t>(i) + k];
                    out[base + static_cast<size_t>(i) * stride] = static_cast<float>(acc);
                }
            }
        });
    };
    GrayImage tmp = image, out = image;
    pass(image.pixels, tmp.pixels, image.width, 1, image.height, image.width);
    pass(tmp.pixels, out.pixels, image.height, image.width, image.width, 1);
    return out;
}

RgbImage normalsFromHeight(const GrayImage& h, double depth, bool wrap) {
    if (h.width < 2 || h.height < 2)
        throw std::invalid_argument("bake::normalsFromHeight(): image must be at least 2 x 2");
    const int w = h.width, ht = h.height;
    const double s = depth * w;
    RgbImage out{w, ht, std::vector<float>(static_cast<size_t>(w) * ht * 3)};
    // Central difference of samples a (before) and b (after) 2 apart, or 1 apart at a clamped border.
    auto index = [wrap](int i, int n) { return wrap ? (i + n) % n : std::clamp(i, 0, n - 1); };
    forEachRow(ht, w, [&](size_t i) {
        const int y = static_cast<int>(i / w), x = static_cast<int>(i % w);
        const int ya = index(y - 1, ht), yb = index(y + 1, ht), xa = index(x - 1, w), xb = index(x + 1, w);
        const double gx = (h.at(xb, y) - h.at(xa, y)) / (wrap ? 2.0 : static_cast<double>(xb - xa));
        const double gRow = (h.at(x, yb) - h.at(x, ya)) / (wrap ? 2.0 : static_cast<double>(yb - ya));
        const double nx = -s * gx, ny = s * gRow, len = std::sqrt(nx * nx + ny * ny + 1.0);
        out.pixels[3 * i + 0] = static_cast<float>(nx / len);
        out.pixels[3 * i + 1] = static_cast<float>(ny / len);
        out.pixels[3 * i + 2] = static_cast<float>(1.0 / len);
    });
    return out;
}

MaterialMaps generateMaps(const GrayImage& mask, const MaterialParams& params, const MapSelection& which) {
    if (mask.width < 2 || mask.height < 2 || mask.pixels.size() != static_cast<size_t>(mask.width) * mask.height)
        throw std::invalid_argument("bake::generateMaps(): mask must be an image of at least 2 x 2 pixels");
    checkMaterial(params, which.diffuse);
    MaterialMaps maps;
    if (which.diffuse) maps.diffuse = gradientMap(mask, params.diffuseColors, params.diffuseStops);
    if (which.roughness) maps.roughness = mapMask(mask, params.roughness);
    if (which.metallic) maps.metallic = mapMask(mask, params.metallic);
    if (which.height || which.normal) {
        GrayImage height = blurGaussian(mapMask(mask, params.height), params.heightBlurPx, params.tileable);
        if (which.normal) maps.normal = normalsFromHeight(height, params.normalDepth, params.tileable);
        if (which.height) maps.height = std::move(height);
    }
    return maps;
}

void compositeLayer(MaterialMaps& below, const MaterialMaps& layer, const GrayImage& alpha, const MapSelection& which) {
    const size_t n = static_cast<size_t>(alpha.width) * alpha.height;
    auto blend = [&](std::vector<float>& c, const std::vector<float>& l, size_t channels, const char* name) {
        if (c.size() != n * channels || l.size() != n * channels)
            throw std::invalid_argument(std::string("bake::compositeLayer(): the ") + name +
                                        " maps must both have the coverage's size");
        for (size_t i = 0; i < c.size(); ++i) {
            const float a = alpha.pixels[i / channels];
            c[i] += a * (l[i] - c[i]);
        }
    };
    if (alpha.pixels.size() != n)
        throw std::invalid_argument("bake::compositeLayer(): coverage has a wrong pixel count");
    if (which.diffuse) blend(below.diffuse.pixels, layer.diffuse.pixels, 3, "diffuse");
    if (which.roughness) blend(below.roughness.pixels, layer.roughness.pixels, 1, "roughness");
    if (which.metallic) blend(below.metallic.pixels, layer.metallic.pixels, 1, "metallic");
    if (which.height) blend(below.height.pixels, layer.height.pixels, 1, "height");
}

std::string encodePng(const GrayImage& image, int bits) {
    checkBits("bake::encodePng(): ", bits);
    return encodeFloats(image.pixels, image.width, image.height, 1, bits);
}

std::string encodePng(const RgbImage& image, int bits) {
    checkBits("bake::encodePng(): ", bits);
    return encodeFloats(image.pixels, image.width, image.height, 3, bits);
}

std::string encodePng(const Rgb8Image& image) {
    cv::Mat m(image.height, image.width, CV_8UC3);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c)
                m.ptr<uint8_t>(y)[3 * x + 2 - c] = image.pixels[3 * (static_cast<size_t>(y) * image.width + x) + c];
    return pngBytes(m);
}

std::array<uint8_t, 3> encodeUnitNormal8(double nx, double ny, double nz) {
    const double n[3] = {nx, ny, nz};
    auto code = [](double v) { return static_cast<int>(std::lround(std::clamp((v + 1) * 127.5, 0.0, 255.0))); };
    auto decode = [](int c) { return c / 127.5 - 1.0; };
    auto result = [](const int c[3]) {
        return std::array<uint8_t, 3>{static_cast<uint8_t>(c[0]), static_cast<uint8_t>(c[1]),
                                      static_cast<uint8_t>(c[2])};
    };
    const int nearest[3] = {code(nx), code(ny), code(nz)};
    // A margin under the tolerance for the reader's own arithmetic.
    constexpr double tol = 0.9 * kNormalLengthTolerance;
    const double nearestLength =
        std::sqrt(decode(nearest[0]) * decode(nearest[0]) + decode(nearest[1]) * decode(nearest[1]) +
                  decode(nearest[2]) * decode(nearest[2]));
    if (std::abs(nearestLength - 1.0) <= tol) return result(nearest);
    // Search codes around the nearest one in square rings of growing radius r over the two
    // largest components a and b, solving for the smallest one s so that the length lands in
    // the tolerance band (|s| small: the band is widest there in codes). Keep the best angle to
    // n. A code r steps from the nearest one in a or b is at least r steps minus the nearest
    // code's own offset off n there, which bounds the chord of every candidate of ring r from
    // below: stop once that exceeds the best chord found.
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int i, int j) { return std::abs(n[i]) > std::abs(n[j]); });
    const int a = order[0], b = order[1], s = order[2];
    const double sign = n[s] < 0 ? -1.0 : 1.0, step = 2.0 / 255.0;
    int best[3] = {nearest[0], nearest[1], nearest[2]};
    double bestCos = -2;
    auto consider = [&](int ca, int cb) {
        if (ca < 0 || ca > 255 || cb < 0 || cb > 255) return;
        const double va = decode(ca), vb = decode(cb), rest = va * va + vb * vb;
        const double lo2 = (1 - tol) * (1 - tol) - rest, hi2 = (1 + tol) * (1 + tol) - rest;
        if (hi2 < 0) return;
        // The same sign as n[s] is always at least as close as the opposite one.
        const double target = sign * std::clamp(sign * n[s], lo2 > 0 ? std::sqrt(lo2) : 0.0, std::sqrt(hi2));
        const int cs0 = code(target);
        for (int cs = std::max(cs0 - 1, 0); cs <= std::min(cs0 + 1, 255); ++cs) {
            const double vs = decode(cs), len = std::sqrt(rest + vs * vs);
            if (std::abs(len - 1.0) > tol) continue;
            const double cosine = (n[a] * va + n[b] * vb + n[s] * vs) / len;
            if (cosine > bestCos) {
                bestCos = cosine;
                best[a] = ca;
                best[b] = cb;
                best[s] = cs;
            }
        }
    };
    const double offset = std::max(std::abs(decode(nearest[a]) - n[a]), std::abs(decode(nearest[b]) - n[b]));
    for (int r = 0; r <= 32; ++r) {
        if (bestCos > -2 && r * step - offset - tol > std::sqrt(std::max(0.0, 2.0 - 2.0 * bestCos))) break;
        for (int d = -r; d <= r; ++d) {
            consider(nearest[a] + d, nearest[b] - r);
            if (r > 0) consider(nearest[a] + d, nearest[b] + r);
            if (std::abs(d) != r) {
                consider(nearest[a] - r, nearest[b] + d);
                consider(nearest[a] + r, nearest[b] + d);
            }
        }
    }
    return result(best);
}

std::string encodeNormalPng(const RgbImage& normals, int bits) {
    checkBits("bake::encodeNormalPng(): ", bits);
    if (bits == 16) {
        RgbImage unit = normals;
        for (float& v : unit.pixels)
            v = 0.5f * (v + 1.0f);
        return encodeFloats(unit.pixels, unit.width, unit.height, 3, 16);
    }
    cv::Mat m(normals.height, normals.width, CV_8UC3);
    // Rows in parallel: every pixel's code depends on its normal only, so the result does not
    // depend on the thread count.
    cv::parallel_for_(cv::Range(0, normals.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y)
            for (int x = 0; x < normals.width; ++x) {
                const float* n = &normals.pixels[3 * (static_cast<size_t>(y) * normals.width + x)];
                const std::array<uint8_t, 3> c = encodeUnitNormal8(n[0], n[1], n[2]);
                uint8_t* dst = m.ptr<uint8_t>(y) + 3 * x;
                dst[0] = c[2];
                dst[1] = c[1];
                dst[2] = c[0];
            }
    });
    return pngBytes(m);
}

DecodedImage decodeImage(std::string_view bytes, const std::string& label) {
    cv::Mat m = decodeMat(bytes, cv::IMREAD_UNCHANGED, label);
    if (m.depth() != CV_8U && m.depth() != CV_16U) throw InputError(label + ": image samples must be 8 or 16 bits");
    if (m.channels() == 3) cv::cvtColor(m, m, cv::COLOR_BGR2RGB);
    if (m.channels() == 4) cv::cvtColor(m, m, cv::COLOR_BGRA2RGBA);
    if (m.channels() == 2) throw InputError(label + ": gray + alpha images are not supported");
    DecodedImage d{m.cols, m.rows, m.channels(), m.depth() == CV_8U ? 8 : 16, {}};
    d.samples.reserve(m.total() * m.channels());
    for (int y = 0; y < m.rows; ++y)
        for (int i = 0; i < m.cols * m.channels(); ++i)
            d.samples.push_back(d.bits == 8 ? m.ptr<uint8_t>(y)[i] : m.ptr<uint16_t>(y)[i]);
    return d;
}

Rgb8Image readRgb8Image(const std::filesystem::path& file, int maxSide) {
    const std::string label = file.string();
    cv::Mat m = decodeMat(readFile(file), cv::IMREAD_COLOR, label);
    checkSides(m, maxSide, label);
    cv::cvtColor(m, m, cv::COLOR_BGR2RGB);
    Rgb8Image out{m.cols, m.rows, {}};
    out.pixels.reserve(m.total() * 3);
    for (int y = 0; y < m.rows; ++y)
        out.pixels.insert(out.pixels.end(), m.ptr<uint8_t>(y), m.ptr<uint8_t>(y) + 3 * m.cols);
    return out;
}

GrayImage readGrayImage(const std::filesystem::path& file, int maxSide) {
    const std::string label = file.string();
    cv::Mat m = decodeMat(readFile(file), cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH, label);
    checkSides(m, maxSide, label);
    if (m.depth() != CV_8U && m.depth() != CV_16U) throw InputError(label + ": image samples must be 8 or 16 bits");
    cv::Mat f;
    m.convertTo(f, CV_32F, m.depth() == CV_8U ? 1.0 / 255.0 : 1.0 / 65535.0);
    GrayImage out{f.cols, f.rows, {}};
    out.pixels.reserve(f.total());
    for (int y = 0; y < f.rows; ++y)
        out.pixels.insert(out.pixels.end(), f.ptr<float>(y), f.ptr<float>(y) + f.cols);
    return out;
}

} // namespace viscera::bake
