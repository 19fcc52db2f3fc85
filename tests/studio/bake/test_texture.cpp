// Procedural tissue textures [A §6.2]: the quadtree mask (determinism, seamless tiling, blend
// modes, tile placement), the palette (threshold grouping and k-means), the material maps (normal
// length after quantization) and the texture spec's refusals. Fixtures are written at run time.
#include "bake/texture.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"
#include "texture_spec_fixture.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;
using namespace viscera;
using namespace viscera::bake;

namespace {

using viscera::test::specText;

TextureSpec parse(const std::string& text, const fs::path& folder = ".") {
    return parseTextureSpec(text, "spec.json", folder);
}

/// Largest |difference| across the wrap seam (column N-1 to 0, row N-1 to 0) and between
/// neighbouring pixels inside the image.
struct SeamFigures {
    double seam = 0, interior = 0;
};
SeamFigures seamFigures(const GrayImage& m) {
    SeamFigures f;
    const int n = m.width;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            if (x + 1 < n) f.interior = std::max(f.interior, double(std::abs(m.at(x + 1, y) - m.at(x, y))));
            if (y + 1 < n) f.interior = std::max(f.interior, double(std::abs(m.at(x, y + 1) - m.at(x, y))));
        }
    for (int i = 0; i < n; ++i) {
        f.seam = std::max(f.seam, double(std::abs(m.at(n - 1, i) - m.at(0, i))));
        f.seam = std::max(f.seam, double(std::abs(m.at(i, n - 1) - m.at(i, 0))));
    }
    return f;
}

// CIE L*a*b* (D65) of an 8-bit sRGB colour, and ΔE*ab (CIE 1976).
std::array<double, 3> lab(Rgb8 c) {
    auto linear = [](uint8_t v) {
        const double s = v / 255.0;
        return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
    };
    const double r = linear(c.r), g = linear(c.g), b = linear(c.b);
    const double x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
    const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
    const double z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883;
    auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16) / 116; };
    return {116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))};
}
double deltaE(Rgb8 a, Rgb8 b) {
    const auto p = lab(a), q = lab(b);
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

/// Angle between two vectors in degrees (atan2 of |a × b| and a · b: accurate near 0).
double angleDeg(const double a[3], const double b[3]) {
    const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
    const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 180 / std::numbers::pi;
}

/// 100 × 60 pixels: three flat colours on 50 %, 30 % and 20 % of the image (columns 0-49, 50-79,
/// 80-99), each pixel's channels moved by a deterministic -3..+4.
const Rgb8 kFlat[3] = {{180, 60, 70}, {230, 190, 160}, {90, 20, 30}};
Rgb8Image threeColours() {
    Rgb8Image im{100, 60, {}};
    uint32_t state = 12345;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const Rgb8 c = kFlat[x < 50 ? 0 : x < 80 ? 1 : 2];
            for (uint8_t v : {c.r, c.g, c.b}) {
                state = state * 1664525u + 1013904223u;
                im.pixels.push_back(static_cast<uint8_t>(v + static_cast<int>(state >> 29) - 3));
            }
        }
    return im;
}

/// A smooth two-dimensional colour field with noise: many distinct colours for k-means.
Rgb8Image gradientImage() {
    Rgb8Image im{80, 80, {}};
    uint32_t state = 99;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            state = state * 1664525u + 1013904223u;
            const int noise = static_cast<int>(state >> 28) - 8;
            im.pixels.push_back(static_cast<uint8_t>(std::clamp(40 + 2 * x + noise, 0, 255)));
            im.pixels.push_back(static_cast<uint8_t>(std::clamp(30 + y + noise, 0, 255)));
            im.pixels.push_back(static_cast<uint8_t>(std::clamp(200 - x - y / 2, 0, 255)));
        }
    return im;
}

/// One pattern covering the whole image with a constant `value`: discs 4 × their node, whose
/// borders lie outside the image (level 0) or beyond the next node's centre (level 1).
LevelPattern flatLevel(int level, double value, BlendMode blend) {
    LevelPattern p;
    p.level = level;
    p.tile.shape = TileShape::Disc;
    p.width = p.height = {4, 4};
    p.opacity = {value, value};
    p.blend = blend;
    return p;
}

} // namespace

// ---- quadtree mask ----------------------------------------------------------------------------

TEST(TextureMask, SameSpecAndSeedGiveIdenticalPngBytesAndAnotherSeedDiffers) {
    const TextureSpec a = parse(specText(7));
    const std::vector<EncodedFile> first = encodeTextureSet(a, generateTextureSet(a));
    const std::vector<EncodedFile> second = encodeTextureSet(a, generateTextureSet(parse(specText(7))));
    ASSERT_EQ(first.size(), 8u); // mask, diffuse, roughness, metallic, height, normal, palette png + json
    ASSERT_EQ(first.size(), second.size());
    for (size_t i = 0; i < first.size(); ++i) {
        EXPECT_EQ(first[i].fileName, second[i].fileName);
        EXPECT_TRUE(first[i].bytes == second[i].bytes) << first[i].fileName;
    }
    EXPECT_EQ(first[0].fileName, "layer_mask.png");
    const TextureSpec b = parse(specText(8));
    const std::vector<EncodedFile> other = encodeTextureSet(b, generateTextureSet(b));
    for (size_t i = 0; i < 6; ++i) // every map depends on the mask
        EXPECT_FALSE(first[i].bytes == other[i].bytes) << first[i].fileName;
    // The mask itself, not only its encoding: equal floats for a seed, different for another.
    EXPECT_EQ(generateMask(a.quadtree).pixels, generateMask(a.quadtree).pixels);
    EXPECT_NE(generateMask(a.quadtree).pixels, generateMask(b.quadtree).pixels);
}

TEST(TextureMask, TileableMaskHasNoSeamAndAClippedOneHas) {
    // Tiles larger than their nodes with polar offsets: many cross the borders.
    QuadtreeParams q = parse(specText(3)).quadtree;
    q.size = 256;
    const GrayImage wrapped = generateMask(q);
    const SeamFigures t = seamFigures(wrapped);
    RecordProperty("tileable_seam_max_diff", std::to_string(t.seam));
    RecordProperty("tileable_interior_max_diff", std::to_string(t.interior));
    EXPECT_GT(t.interior, 0.01); // the mask is not flat
    EXPECT_LE(t.seam, t.interior) << "seam " << t.seam << ", interior " << t.interior;

    q.tileable = false;
    const SeamFigures c = seamFigures(generateMask(q));
    RecordProperty("clipped_seam_max_diff", std::to_string(c.seam));
    RecordProperty("clipped_interior_max_diff", std::to_string(c.interior));
    EXPECT_GT(c.seam, c.interior) << "seam " << c.seam << ", interior " << c.interior;
}

TEST(TextureMask, BlendModesCombineLevelsAndClamp) {
    QuadtreeParams q;
    q.size = 16;
    q.levels = 2;
    q.base = 0.2;
    const struct {
        BlendMode mode;
        float expected; // canvas 0.2 + 0.6 = 0.8, then the mode with 0.5
    } cases[] = {{BlendMode::Add, 1.0f},
                 {BlendMode::Subtract, 0.3f},
                 {BlendMode::Max, 0.8f},
                 {BlendMode::Min, 0.5f},
                 {BlendMode::Multiply, 0.4f}};
    for (const auto& c : cases) {
        q.patterns = {flatLevel(1, 0.5, c.mode), flatLevel(0, 0.6, BlendMode::Add)}; // applied coarse to fine
        for (float v : generateMask(q).pixels)
            ASSERT_NEAR(v, c.expected, 1e-6) << static_cast<int>(c.mode);
    }
    q.patterns = {flatLevel(0, 0.6, BlendMode::Add)};
    q.patterns[0].probability = 0;
    for (float v : generateMask(q).pixels)
        ASSERT_FLOAT_EQ(v, 0.2f);
    q.patterns = {flatLevel(0, 0.6, BlendMode::Add), flatLevel(1, 0.5, BlendMode::Add)};
    q.patterns[1].level = 0;
    EXPECT_THAT([&] { generateMask(q); }, testing::ThrowsMessage<std::invalid_argument>(testing::StrEq(
                                              "bake::generateMask(): patterns[1].level 0 already has a pattern")));
}

TEST(TextureMask, PolarOffsetMovesTheTileAndWrapsAroundTheBorder) {
    QuadtreeParams q;
    q.size = 64;
    q.levels = 1;
    LevelPattern p;
    p.tile.shape = TileShape::Disc;
    p.width = p.height = {0.25, 0.25}; // radius 8 px
    p.offsetRadius = {0.25, 0.25};
    p.offsetAngleDeg = {90, 90}; // counter-clockwise from +x as displayed: up
    q.patterns = {p};
    const GrayImage up = generateMask(q);
    double sx = 0, sy = 0, sum = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            sum += up.at(x, y);
            sx += up.at(x, y) * (x + 0.5);
            sy += up.at(x, y) * (y + 0.5);
        }
    EXPECT_NEAR(sx / sum, 32.0, 0.05);
    EXPECT_NEAR(sy / sum, 16.0, 0.05);          // 0.25 × 64 above the centre
    EXPECT_NEAR(sum, std::numbers::pi * 64, 2); // the disc's area

    q.patterns[0].offsetRadius = {0.5, 0.5};
    q.patterns[0].offsetAngleDeg = {0, 0}; // centre on the right border: half on each side
    const GrayImage split = generateMask(q);
    EXPECT_FLOAT_EQ(split.at(0, 32), 1.0f);
    EXPECT_FLOAT_EQ(split.at(63, 32), 1.0f);
    EXPECT_FLOAT_EQ(split.at(32, 32), 0.0f);
    for (int y = 0; y < 64; ++y)
        for (int d = 0; d < 10; ++d)
            EXPECT_FLOAT_EQ(split.at(d, y), split.at(63 - d, y)) << d << ", " << y;
}

TEST(TextureMask, ImageTileIsStretchedOverTheTileAndRotated) {
    GrayImage ramp{32, 32, {}};
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            ramp.pixels.push_back((x + 0.5f) / 32.0f);
    QuadtreeParams q;
    q.size = 64;
    q.levels = 1;
    LevelPattern p;
    p.tile.shape = TileShape::Image;
    p.tile.image = ramp;
    q.patterns = {p};
    const GrayImage flat = generateMask(q); // the ramp at twice its size
    for (int x = 2; x < 62; ++x)
        EXPECT_NEAR(flat.at(x, 30), (x + 0.5) / 64.0, 0.02) << x;
    q.patterns[0].rotationDeg = {90, 90}; // image x now points up the screen
    const GrayImage turned = generateMask(q);
    for (int y = 2; y < 62; ++y)
        EXPECT_NEAR(turned.at(30, y), 1.0 - (y + 0.5) / 64.0, 0.02) << y;
}

// ---- palette ----------------------------------------------------------------------------------

TEST(TexturePalette, ThreeFlatColoursAreFoundSortedByShare) {
    const Rgb8Image im = threeColours();
    PaletteParams threshold;
    threshold.threshold = 24;
    PaletteParams kmeans;
    kmeans.method = PaletteMethod::KMeans;
    kmeans.k = 3;
    kmeans.seed = 5;
    for (const PaletteParams& params : {threshold, kmeans}) {
        const std::vector<PaletteColor> p = extractPalette(im, params);
        ASSERT_EQ(p.size(), 3u);
        const double shares[3] = {0.5, 0.3, 0.2};
        double worst = 0;
        for (size_t i = 0; i < 3; ++i) {
            worst = std::max(worst, deltaE(p[i].color, kFlat[i]));
            EXPECT_LT(deltaE(p[i].color, kFlat[i]), 2.0) << hexColor(p[i].color) << " vs " << hexColor(kFlat[i]);
            EXPECT_DOUBLE_EQ(p[i].share, shares[i]);
        }
        RecordProperty(params.method == PaletteMethod::Threshold ? "threshold_max_delta_e" : "kmeans_max_delta_e",
                       std::to_string(worst));
    }
    // A threshold larger than the colours' distances merges them; the proportional map's bars
    // follow the shares.
    threshold.threshold = 256;
    const std::vector<PaletteColor> one = extractPalette(im, threshold);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_DOUBLE_EQ(one[0].share, 1.0);
    const Rgb8Image bars = proportionalMap(extractPalette(im, PaletteParams{}), 100, 4);
    EXPECT_EQ(bars.width, 100);
    auto at = [&](int x) {
        return Rgb8{bars.pixels[3 * size_t(x)], bars.pixels[3 * size_t(x) + 1], bars.pixels[3 * size_t(x) + 2]};
    };
    EXPECT_LT(deltaE(at(49), kFlat[0]), 2.0);
    EXPECT_LT(deltaE(at(50), kFlat[1]), 2.0);
    EXPECT_LT(deltaE(at(79), kFlat[1]), 2.0);
    EXPECT_LT(deltaE(at(80), kFlat[2]), 2.0);
    EXPECT_EQ(hexColor({0x7a, 0x1f, 0x24}), "#7a1f24");
    EXPECT_EQ(parseHexColor("#7A1F24"), (Rgb8{0x7a, 0x1f, 0x24}));
    EXPECT_FALSE(parseHexColor("#7a1f2"));
    EXPECT_FALSE(parseHexColor("7a1f24x"));
}

TEST(TexturePalette, KMeansWithAFixedSeedIsReproducible) {
    const Rgb8Image im = gradientImage();
    PaletteParams p;
    p.method = PaletteMethod::KMeans;
    p.k = 5;
    p.seed = 42;
    const std::vector<PaletteColor> a = extractPalette(im, p), b = extractPalette(im, p);
    ASSERT_EQ(a.size(), 5u);
    double shares = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].color, b[i].color);
        EXPECT_EQ(a[i].pixels, b[i].pixels);
        if (i > 0) {
            EXPECT_GE(a[i - 1].pixels, a[i].pixels);
        }
        shares += a[i].share;
    }
    EXPECT_NEAR(shares, 1.0, 1e-12);
    // The threshold grouping of the same image: every pixel in exactly one group.
    PaletteParams t;
    t.maxColors = 256;
    uint64_t pixels = 0;
    for (const PaletteColor& c : extractPalette(im, t))
        pixels += c.pixels;
    EXPECT_EQ(pixels, 80u * 80u);
}

// ---- material maps ----------------------------------------------------------------------------

TEST(TextureMaps, NormalsFollowTheHeightByCentralDifferences) {
    // h = 0.5 + 0.25 sin(2πx/N): n_x = -s (h(x+1) - h(x-1)) / 2 / |(...)|, n_y = 0; wrap at x = 0.
    const int n = 32;
    GrayImage h{n, n, {}};
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            h.pixels.push_back(static_cast<float>(0.5 + 0.25 * std::sin(2 * std::numbers::pi * x / n)));
    const double depth = 0.05, s = depth * n;
    const RgbImage normals = normalsFromHeight(h, depth, true);
    for (int x = 0; x < n; ++x) {
        const double g = (h.at((x + 1) % n, 3) - h.at((x + n - 1) % n, 3)) / 2.0;
        const double len = std::sqrt(s * s * g * g + 1);
        const float* v = &normals.pixels[3 * (size_t(3) * n + x)];
        EXPECT_NEAR(v[0], -s * g / len, 1e-6) << x;
        EXPECT_NEAR(v[1], 0.0, 1e-6);
        EXPECT_NEAR(v[2], 1.0 / len, 1e-6);
    }
    // Height rising down the rows tilts the normal up the image (+y, OpenGL convention).
    GrayImage rows{4, 4, {}};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
            rows.pixels.push_back(y / 3.0f);
    EXPECT_GT(normalsFromHeight(rows, 0.1, false).pixels[3 * 5 + 1], 0.1f);
}

TEST(TextureMaps, NormalMapsAreUnitLengthAfter8And16BitDecoding) {
    const TextureSpec spec = parse(specText(11));
    const TextureSet set = generateTextureSet(spec);
    const RgbImage& normals = set.maps.normal;
    ASSERT_EQ(normals.width, 128);
    for (int bits : {8, 16}) {
        const DecodedImage d = decodeImage(encodeNormalPng(normals, bits), "normal.png");
        ASSERT_EQ(d.bits, bits);
        ASSERT_EQ(d.channels, 3);
        const double maxCode = bits == 8 ? 255.0 : 65535.0;
        double lengthError = 0, angle = 0, tilt = 0;
        for (size_t i = 0; i < d.samples.size(); i += 3) {
            double v[3], n[3], len = 0;
            for (int c = 0; c < 3; ++c) {
                v[c] = 2.0 * d.samples[i + size_t(c)] / maxCode - 1.0;
                n[c] = normals.pixels[i + size_t(c)];
                len += v[c] * v[c];
            }
            lengthError = std::max(lengthError, std::abs(std::sqrt(len) - 1.0));
            angle = std::max(angle, angleDeg(v, n));
            tilt = std::max(tilt, std::acos(double(normals.pixels[i + 2])) * 180 / std::numbers::pi);
        }
        RecordProperty("normal" + std::to_string(bits) + "_max_length_error", std::to_string(lengthError));
        RecordProperty("normal" + std::to_string(bits) + "_max_angle_error_deg", std::to_string(angle));
        EXPECT_LE(lengthError, kNormalLengthTolerance) << bits << " bits";
        EXPECT_GT(tilt, 10.0); // the map has real slopes
        EXPECT_LT(angle, bits == 8 ? 3.5 : 0.01) << bits << " bits";
    }
}

TEST(TextureMaps, EightBitNormalCodesStayUnitLengthOverAllDirections) {
    // Directions over the upper hemisphere, dense near the pole where the codes are coarsest in
    // length, and the plain nearest code's error for comparison.
    double worstLength = 0, worstAngle = 0, nearestLength = 0;
    for (int i = 0; i < 200; ++i)
        for (int j = 0; j < 90; ++j) {
            const double theta = std::pow(i / 199.0, 2) * 1.45, phi = j * 2 * std::numbers::pi / 90;
            const double n[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
            const std::array<uint8_t, 3> c = encodeUnitNormal8(n[0], n[1], n[2]);
            double v[3], len = 0, lenNearest = 0;
            for (int k = 0; k < 3; ++k) {
                v[k] = c[size_t(k)] / 127.5 - 1;
                const double r = std::round((n[k] + 1) * 127.5) / 127.5 - 1;
                len += v[k] * v[k];
                lenNearest += r * r;
            }
            worstLength = std::max(worstLength, std::abs(std::sqrt(len) - 1));
            worstAngle = std::max(worstAngle, angleDeg(v, n));
            nearestLength = std::max(nearestLength, std::abs(std::sqrt(lenNearest) - 1));
        }
    RecordProperty("unit8_max_length_error", std::to_string(worstLength));
    RecordProperty("unit8_max_angle_error_deg", std::to_string(worstAngle));
    RecordProperty("nearest8_max_length_error", std::to_string(nearestLength));
    EXPECT_LE(worstLength, kNormalLengthTolerance);
    EXPECT_GT(nearestLength, kNormalLengthTolerance); // why the search is needed
    EXPECT_LT(worstAngle, 3.5); // the price of unit length in 8 bits (nearest codes: under 0.4 degrees)
}

TEST(TextureMaps, MapsFollowTheMaskAndThePaletteGradient) {
    GrayImage mask{4, 2, {0.0f, 0.25f, 0.5f, 1.0f, 0.75f, 0.1f, 0.9f, 0.6f}};
    MaterialParams p;
    p.diffuseColors = {{0, 0, 0}, {255, 128, 0}, {255, 255, 255}};
    p.roughness = {0.8, 0.2};
    p.metallic = {0, 0};
    const MaterialMaps m = generateMaps(mask, p);
    ASSERT_EQ(m.diffuse.width, 4);
    const float at25[3] = {0.5f, 128.0f / 255 / 2, 0.0f};
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m.diffuse.pixels[3 + size_t(c)], at25[c], 1e-6);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m.diffuse.pixels[9 + size_t(c)], 1.0f, 1e-6);
    EXPECT_NEAR(m.roughness.pixels[2], 0.5f, 1e-6);
    EXPECT_NEAR(m.roughness.pixels[3], 0.2f, 1e-6);
    EXPECT_EQ(m.metallic.pixels, std::vector<float>(8, 0.0f));
    EXPECT_EQ(m.height.pixels, mask.pixels);
    EXPECT_EQ(m.normal.pixels.size(), 8u * 3u);
    p.diffuseStops = {0.0, 0.9, 1.0};
    EXPECT_NEAR(generateMaps(mask, p).diffuse.pixels[3 * 6], 1.0f, 1e-6); // mask 0.9 → the middle colour's red
}

// ---- spec -------------------------------------------------------------------------------------

namespace {

std::string refusal(const std::string& text, const fs::path& folder = ".") {
    try {
        parse(text, folder);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

} // namespace

TEST(TextureSpec, BadSpecsAreRefusedWithOneLineNamingTheField) {
    const std::string good = specText(1);
    EXPECT_EQ(refusal(good), "(accepted)");
    EXPECT_EQ(refusal(specText(1, R"(, "colour": 3)")), "spec.json: colour: unknown field");
    // Each case: a piece of the good spec, what replaces it, the message.
    const struct {
        const char *from, *to, *message;
    } cases[] = {
        {R"("shape": "bell")", R"("shape": "bell", "sigma": 0.3)", "patterns[1].tile.sigma: unknown field"},
        {R"("opacity": [0.5, 1])", R"("opacity": [0.5, 1.5])", "patterns[0].opacity[1]: must be in [0, 1]"},
        {R"("opacity": [0.5, 1])", R"("opacity": [0.9, 0.5])",
         "patterns[0].opacity: [0.9, 0.5] is not an interval (lower bound above upper)"},
        {R"("size": 128)", R"("size": 1000)", "size: must be a power of two (1000 is not)"},
        {R"("size": 128)", R"("size": 8192)", "size: must be an integer in [8, 4096]"},
        {R"("levels": 6)", R"("levels": 9)", "levels: must be an integer in [1, 8]"},
        {R"("level": 5)", R"("level": 3)", "patterns[1].level: level 3 already has a pattern (patterns[0])"},
        {R"("blend": "max")", R"("blend": "screen")",
         "patterns[1].blend: 'screen' is not a blend mode (add, subtract, max, min, multiply)"},
        {R"("bit_depth": 8)", R"("bit_depth": 12)", "bit_depth: must be 8 or 16"},
        {R"("#c65a4f")", R"("#c65a4")", "palette.colors[1]: '#c65a4' is not a colour (#rrggbb)"},
        {R"("diffuse": {})", R"("diffuse": {"colors": [0, 3]})",
         "maps.diffuse.colors[1]: palette index 3 is out of range (the palette has 3 colours)"},
        {R"("normal": {"depth": 0.02})", R"("normal": {"depth": 0})", "maps.normal.depth: must be in (0, 1]"},
        {R"("scale": {"uniform": [0.6, 1.6]})", R"("scale": {"uniform": [0.6, 5]})",
         "patterns[1].scale.uniform[1]: must be in (0, 4]"},
        {R"("seed": 1)", R"("seed": -1)", "seed: must not be negative"},
        {R"("palette": {"colors": ["#7a1f24", "#c65a4f", "#efc1a8"]},)", "",
         "palette: required field is missing (maps.diffuse uses it)"},
    };
    for (const auto& c : cases)
        EXPECT_EQ(refusal(replaced(good, c.from, c.to)), std::string("spec.json: ") + c.message);
    EXPECT_EQ(refusal("{\"size\": 64, \"size\": 32}"), "spec.json: invalid JSON (duplicate object key \"size\")");
}

TEST(TextureSpec, FilesMustStayInsideTheSpecsFolder) {
    test::Scratch scratch("viscera-texture");
    const fs::path folder = scratch.dir / "spec";
    writeFileAtomic(folder / "refs" / "liver.png", encodePng(threeColours()));
    writeFileAtomic(scratch.dir / "outside.png", encodePng(threeColours()));
    auto withImage = [](const std::string& path, const std::string& extra = "") {
        return replaced(specText(1), R"("colors": ["#7a1f24", "#c65a4f", "#efc1a8"])",
                        "\"image\": \"" + path + "\"" + extra);
    };
    EXPECT_EQ(refusal(withImage("../outside.png"), folder),
              "spec.json: palette.image: '../outside.png' escapes the spec's folder ('..' component)");
    EXPECT_EQ(refusal(withImage("refs/../../outside.png"), folder),
              "spec.json: palette.image: 'refs/../../outside.png' escapes the spec's folder ('..' component)");
    EXPECT_EQ(refusal(withImage((scratch.dir / "outside.png").string()), folder),
              "spec.json: palette.image: '" + (scratch.dir / "outside.png").string() +
                  "' is an absolute path (files are named relative to the spec's folder)");
    fs::create_symlink(scratch.dir / "outside.png", folder / "link.png");
    EXPECT_EQ(refusal(withImage("link.png"), folder),
              "spec.json: palette.image: 'link.png' resolves outside the spec's folder (symbolic link)");
    EXPECT_EQ(refusal(withImage("refs/missing.png"), folder),
              "spec.json: palette.image: " + (folder / "refs/missing.png").string() +
                  ": cannot open for reading (file not found)");
    EXPECT_EQ(refusal(withImage("refs/liver.png", R"(, "threshold": 40, "prominent_threshold": 30)"), folder),
              "spec.json: palette.prominent_threshold: must be at least the threshold (40)");
    EXPECT_EQ(refusal(withImage("refs/liver.png", R"(, "k": 4)"), folder), "spec.json: palette.k: unknown field");

    // Accepted: the palette of the reference image, the prominent-colour map, all written.
    const TextureSpec spec =
        parse(replaced(withImage("refs/liver.png", R"(, "method": "kmeans", "k": 3)"), R"("palette": {"swatch_px": 8})",
                       R"("palette": {"swatch_px": 8}, "prominent": {"width": 100, "height": 10})"),
              folder);
    const fs::path out = scratch.dir / "out";
    const BakeTextureResult r = bakeTexture(spec, out);
    ASSERT_EQ(r.files.size(), 9u);
    for (const WrittenFile& f : r.files) {
        EXPECT_EQ(fs::file_size(f.path), f.bytes) << f.path;
        if (f.path.extension() != ".png") continue;
        const DecodedImage d = decodeImage(readFile(f.path), f.path.string());
        const std::string stem = f.path.stem().string();
        if (stem == "layer_palette") {
            EXPECT_EQ(d.width, 3 * 8);
        } else if (stem == "layer_prominent") {
            EXPECT_EQ(d.width, 100);
        } else {
            EXPECT_EQ(d.width, 128) << stem;
            EXPECT_EQ(d.bits, stem == "layer_mask" ? 16 : 8) << stem;
        }
    }
    const nlohmann::json j = nlohmann::json::parse(readFile(out / "layer_palette.json"));
    ASSERT_EQ(j["palette"].size(), 3u);
    for (size_t i = 0; i < 3; ++i)
        EXPECT_LT(deltaE(*parseHexColor(j["palette"][i]["color"].get<std::string>()), kFlat[i]), 2.0);
    EXPECT_DOUBLE_EQ(j["palette"][0]["share"].get<double>(), 0.5);
    EXPECT_EQ(j["source"], "refs/liver.png");
    EXPECT_EQ(r.set.prominent.size(), 3u); // threshold 64 keeps the three colours apart

    // The output folder is checked before any work.
    EXPECT_THAT([&] { bakeTexture(spec, out / "layer_mask.png"); },
                testing::ThrowsMessage<InputError>(
                    testing::StrEq((out / "layer_mask.png").string() + ": the output folder is a file, not a folder")));
}

// ---- synthetic reference photograph -------------------------------------------------------------

namespace {

const Rgb8 kTissue[3] = {{0x8a, 0x2b, 0x24}, {0xc9, 0x64, 0x5a}, {0xf0, 0xd2, 0xc4}};
const double kTissueShares[3] = {0.6, 0.3, 0.1};

/// The spec's example reference: 256 px, seed 3, three tissue colours on 60 / 30 / 10 %.
const char* kReference =
    R"({"size": 256, "seed": 3, "colors": ["#8a2b24", "#c9645a", "#f0d2c4"], "shares": [0.6, 0.3, 0.1],)"
    R"( "noise": 6, "blur_px": 1.5})";

/// specText() with the palette taken from the synthetic reference (`extra` members added to the
/// palette) and maps.reference requested.
std::string referenceSpecText(int seed, const std::string& reference = kReference, const std::string& extra = "") {
    std::string text = replaced(specText(seed), R"({"colors": ["#7a1f24", "#c65a4f", "#efc1a8"]})",
                                R"({"reference": )" + reference + extra + "}");
    return replaced(text, R"("palette": {"swatch_px": 8})", R"("palette": {"swatch_px": 8}, "reference": {})");
}

Rgb8 pixel(const Rgb8Image& im, size_t i) {
    return {im.pixels[3 * i], im.pixels[3 * i + 1], im.pixels[3 * i + 2]};
}

/// Share of the pixels nearest (RGB) to each of `colors`.
std::vector<double> nearestShares(const Rgb8Image& im, const std::vector<Rgb8>& colors) {
    std::vector<double> shares(colors.size(), 0.0);
    const size_t n = static_cast<size_t>(im.width) * im.height;
    for (size_t i = 0; i < n; ++i) {
        const Rgb8 p = pixel(im, i);
        size_t best = 0;
        int bestD = INT32_MAX;
        for (size_t c = 0; c < colors.size(); ++c) {
            const int dr = p.r - colors[c].r, dg = p.g - colors[c].g, db = p.b - colors[c].b;
            if (dr * dr + dg * dg + db * db < bestD) {
                bestD = dr * dr + dg * dg + db * db;
                best = c;
            }
        }
        shares[best] += 1.0 / double(n);
    }
    return shares;
}

} // namespace

TEST(TextureReference, SameSpecGivesIdenticalPngBytesAndAnotherSeedDiffers) {
    const TextureSpec a = parse(referenceSpecText(1));
    ASSERT_TRUE(a.palette && a.palette->reference);
    EXPECT_TRUE(a.palette->imageFile.empty());
    EXPECT_TRUE(a.palette->image.pixels.empty());
    const std::vector<EncodedFile> first = encodeTextureSet(a, generateTextureSet(a));
    const std::vector<EncodedFile> second = encodeTextureSet(a, generateTextureSet(parse(referenceSpecText(1))));
    ASSERT_EQ(first.size(), 9u); // mask, diffuse, roughness, metallic, height, normal, palette png + json, reference
    ASSERT_EQ(first.back().fileName, "layer_reference.png");
    for (size_t i = 0; i < first.size(); ++i)
        EXPECT_TRUE(first[i].bytes == second[i].bytes) << first[i].fileName;
    const DecodedImage d = decodeImage(first.back().bytes, "layer_reference.png");
    EXPECT_EQ(d.width, 256);
    EXPECT_EQ(d.channels, 3);
    EXPECT_EQ(d.bits, 8);
    const nlohmann::json j = nlohmann::json::parse(first[7].bytes);
    EXPECT_EQ(j["source"], "reference");
    EXPECT_EQ(j["reference"]["colors"][2], "#f0d2c4");

    // The reference's own seed, not the mask's, moves it; equal bytes from the API directly.
    ReferenceSpec r = *a.palette->reference;
    EXPECT_EQ(encodePng(generateReferenceImage(r)), first.back().bytes);
    r.seed = 4;
    EXPECT_NE(generateReferenceImage(r).pixels, generateReferenceImage(*a.palette->reference).pixels);
    const TextureSpec otherMask = parse(referenceSpecText(2));
    EXPECT_EQ(encodeTextureSet(otherMask, generateTextureSet(otherMask)).back().bytes, first.back().bytes);

    // Not flat: noise inside the regions, many distinct colours, and blur: colours between regions.
    const Rgb8Image im = generateReferenceImage(*a.palette->reference);
    PaletteParams all;
    all.threshold = 1;
    all.maxColors = 256;
    double within = 0; // mean |Δ| of the pixels nearest colour 0 from it, 8-bit units
    size_t count = 0, between = 0;
    for (size_t i = 0; i < 256u * 256u; ++i) {
        const Rgb8 p = pixel(im, i);
        const double d0 = deltaE(p, kTissue[0]), d1 = deltaE(p, kTissue[1]);
        if (d0 < 6) {
            within +=
                (std::abs(p.r - kTissue[0].r) + std::abs(p.g - kTissue[0].g) + std::abs(p.b - kTissue[0].b)) / 3.0;
            ++count;
        } else if (d0 > 12 && d1 > 12 && deltaE(p, kTissue[2]) > 12) {
            ++between;
        }
    }
    within /= double(count);
    RecordProperty("reference_mean_abs_noise", std::to_string(within));
    RecordProperty("reference_between_share", std::to_string(double(between) / (256.0 * 256.0)));
    EXPECT_GT(within, 1.0);
    EXPECT_LT(within, 6.0);
    EXPECT_GT(between, 100u);
    EXPECT_EQ(extractPalette(im, all).size(), 256u); // at least 256 distinct colours
}

TEST(TextureReference, RegionSharesFollowTheRequestedShares) {
    const ReferenceSpec example = *parse(referenceSpecText(1)).palette->reference;
    ReferenceSpec five;
    five.size = 128;
    five.seed = 11;
    five.colors = {{0x5c, 0x14, 0x1c}, {0x9e, 0x3a, 0x3a}, {0xc8, 0x78, 0x6e}, {0xe6, 0xb4, 0xa0}, {0xf8, 0xe8, 0xe0}};
    five.shares = {0.35, 0.25, 0.2, 0.15, 0.05};
    five.noise = 10;
    five.blurPx = 3;
    // five: at 128 px, σ = 3 px shrinks the thin and small regions by up to 0.07 of the area
    // before the bound correction. large: 512 px, the noise field upsampled from 256 px.
    ReferenceSpec large = example;
    large.size = 512;
    ReferenceSpec sharp = example; // no blur, no noise: the label image itself meets the shares to the pixel
    sharp.noise = 0;
    sharp.blurPx = 0;
    for (const auto& [name, spec, tolerance] :
         {std::tuple{"example", example, 0.02}, std::tuple{"five", five, 0.02}, std::tuple{"large", large, 0.02},
          std::tuple{"sharp", sharp, 1.0 / (256.0 * 256.0)}}) {
        const std::vector<double> shares = nearestShares(generateReferenceImage(spec), spec.colors);
        double worst = 0;
        std::string figures;
        for (size_t i = 0; i < shares.size(); ++i) {
            worst = std::max(worst, std::abs(shares[i] - spec.shares[i]));
            figures += std::string(i ? " " : "") + std::to_string(shares[i]);
            EXPECT_NEAR(shares[i], spec.shares[i], tolerance) << name << " colour " << i;
        }
        RecordProperty(std::string("shares_") + name, figures);
        RecordProperty(std::string("shares_") + name + "_max_error", std::to_string(worst));
    }
}

TEST(TextureReference, ThresholdAndKMeansPalettesRecoverTheRequestedColours) {
    const std::string kmeans = R"(, "method": "kmeans", "k": 3)";
    for (const std::string& extra : {std::string(R"(, "threshold": 24)"), kmeans}) {
        const TextureSpec spec = parse(referenceSpecText(1, kReference, extra));
        const TextureSet set = generateTextureSet(spec);
        ASSERT_GE(set.palette.size(), 3u);
        const std::string method = extra == kmeans ? "kmeans" : "threshold";
        double worst = 0, worstShare = 0;
        std::string figures;
        for (size_t i = 0; i < 3; ++i) {
            const double e = deltaE(set.palette[i].color, kTissue[i]);
            worst = std::max(worst, e);
            worstShare = std::max(worstShare, std::abs(set.palette[i].share - kTissueShares[i]));
            figures += std::string(i ? ", " : "") + hexColor(set.palette[i].color) + " " +
                       std::to_string(set.palette[i].share) + " dE " + std::to_string(e);
            EXPECT_LT(e, 6.0) << method << ": " << hexColor(set.palette[i].color) << " vs " << hexColor(kTissue[i]);
        }
        RecordProperty(method + "_palette", figures);
        RecordProperty(method + "_max_delta_e", std::to_string(worst));
        RecordProperty(method + "_max_share_error", std::to_string(worstShare));
        // The diffuse gradient and the proportional map use the extracted colours.
        EXPECT_EQ(set.colors[0], set.palette[0].color);
        EXPECT_FALSE(set.maps.diffuse.pixels.empty());
    }
}

TEST(TextureReference, BadReferenceSpecsAreRefusedWithOneLineNamingTheField) {
    EXPECT_EQ(refusal(referenceSpecText(1)), "(accepted)");
    const std::string good = kReference;
    const struct {
        const char *from, *to, *message;
    } cases[] = {
        {R"("size": 256)", R"("size": 8)", "palette.reference.size: must be an integer in [16, 4096]"},
        {R"("size": 256)", R"("size": 8192)", "palette.reference.size: must be an integer in [16, 4096]"},
        {R"("size": 256)", R"("size": 100)", "palette.reference.size: must be a power of two (100 is not)"},
        {R"("size": 256)", R"("size": 256.5)", "palette.reference.size: must be an integer (found number)"},
        {R"("seed": 3)", R"("seed": -3)", "palette.reference.seed: must not be negative"},
        {R"("seed": 3)", R"("seed": 1.5)", "palette.reference.seed: must be an integer (found number)"},
        {R"("colors": ["#8a2b24", "#c9645a", "#f0d2c4"])", R"("colors": [])",
         "palette.reference.colors: must have 1 to 16 elements"},
        {R"("colors": ["#8a2b24", "#c9645a", "#f0d2c4"])",
         R"("colors": ["#8a2b24", "#c9645a", "#f0d2c4", "#000000", "#000000", "#000000", "#000000", "#000000",
                      "#000000", "#000000", "#000000", "#000000", "#000000", "#000000", "#000000", "#000000", "#000000"])",
         "palette.reference.colors: must have 1 to 16 elements"},
        {R"("#c9645a")", R"("#c9645g")", "palette.reference.colors[1]: '#c9645g' is not a colour (#rrggbb)"},
        {R"("shares": [0.6, 0.3, 0.1])", R"("shares": [0.6, 0.4])",
         "palette.reference.shares: must have one share per colour (3 colours, 2 shares)"},
        {R"("shares": [0.6, 0.3, 0.1])", R"("shares": [0.7, 0.3, 0])",
         "palette.reference.shares[2]: must be in (0, 1]"},
        {R"("shares": [0.6, 0.3, 0.1])", R"("shares": [0.6, 0.5, -0.1])",
         "palette.reference.shares[2]: must be in (0, 1]"},
        {R"("shares": [0.6, 0.3, 0.1])", R"("shares": [0.6, 0.3, 0.2])",
         "palette.reference.shares: must sum to 1 within 1e-6 (sum 1.1)"},
        {R"("shares": [0.6, 0.3, 0.1])", R"("shares": [0.6, 0.3, 0.100002])",
         "palette.reference.shares: must sum to 1 within 1e-6 (sum 1.000002)"},
        {R"("noise": 6)", R"("noise": 65)", "palette.reference.noise: must be in [0, 64]"},
        {R"("noise": 6)", R"("noise": -1)", "palette.reference.noise: must be in [0, 64]"},
        {R"("blur_px": 1.5)", R"("blur_px": 16.5)", "palette.reference.blur_px: must be in [0, 16]"},
        {R"("blur_px": 1.5)", R"("blur_px": 1.5, "file": "x.png")", "palette.reference.file: unknown field"},
        {R"("colors": ["#8a2b24", "#c9645a", "#f0d2c4"], )", "", "palette.reference.colors: required field is missing"},
    };
    for (const auto& c : cases)
        EXPECT_EQ(refusal(referenceSpecText(1, replaced(good, c.from, c.to))), std::string("spec.json: ") + c.message)
            << c.to;
    // Sums within 1e-6 of 1 are accepted.
    EXPECT_EQ(refusal(referenceSpecText(1, replaced(good, "0.1]", "0.1000009]"))), "(accepted)");

    // Exactly one palette source; the palette's extraction fields follow the method.
    EXPECT_EQ(refusal(referenceSpecText(1, good, R"(, "image": "refs/liver.png")")),
              "spec.json: palette: takes one of 'colors', 'image' and 'reference' (found 'image' and 'reference')");
    EXPECT_EQ(refusal(referenceSpecText(1, good, R"(, "colors": ["#000000"])")),
              "spec.json: palette: takes one of 'colors', 'image' and 'reference' (found 'colors' and 'reference')");
    EXPECT_EQ(refusal(referenceSpecText(1, good, R"(, "k": 4)")), "spec.json: palette.k: unknown field");
    EXPECT_EQ(
        refusal(replaced(specText(1), R"({"colors": ["#7a1f24", "#c65a4f", "#efc1a8"]})", R"({"method": "kmeans"})")),
        "spec.json: palette: needs 'colors' (a list of #rrggbb), 'image' (a reference image) or 'reference' (a "
        "synthetic reference photograph)");
    // maps.reference needs palette.reference and takes no fields.
    EXPECT_EQ(refusal(replaced(specText(1), R"("palette": {"swatch_px": 8})",
                               R"("palette": {"swatch_px": 8}, "reference": {})")),
              "spec.json: maps.reference: needs a synthetic reference photograph (palette.reference)");
    EXPECT_EQ(refusal(replaced(referenceSpecText(1), R"("reference": {})", R"("reference": {"bit_depth": 16})")),
              "spec.json: maps.reference.bit_depth: unknown field");

    // The API checks the same rules.
    ReferenceSpec r;
    r.colors = {kTissue[0], kTissue[1]};
    r.shares = {0.5, 0.4};
    EXPECT_THAT([&] { generateReferenceImage(r); },
                testing::ThrowsMessage<std::invalid_argument>(
                    testing::StrEq("bake::generateReferenceImage(): shares must sum to 1 within 1e-6 (sum 0.9)")));
    r.shares = {0.5, 0.5};
    r.size = 100;
    EXPECT_THAT([&] { generateReferenceImage(r); },
                testing::ThrowsMessage<std::invalid_argument>(
                    testing::StrEq("bake::generateReferenceImage(): size 100 must be a power of two in [16, 4096]")));
}

// ---- layers [A §6.2.2, Fig. 6.8] --------------------------------------------------------------

namespace {

/// specText() with one layer; `layer` members are spliced into the layer object.
std::string layeredSpec(int seed, const std::string& layer = "") {
    return specText(seed, R"(, "layers": [
    {"name": "granular", "levels": 6, "opacity": 0.8,
     "patterns": [{"level": 4, "tile": {"shape": "disc"}, "scale": {"uniform": [0.3, 0.7]},
                   "offset": {"radius": [0, 0.4]}, "probability": 0.6, "blend": "max"}],
     "palette": {"colors": ["#302010", "#f0f0f0"]},
     "maps": {"mask": {}, "diffuse": {"colors": [1], "write": true}, "roughness": {"values": [0.9, 0.9]},
              "height": {"values": [0, 1]}})" +
                              layer + "}]");
}

double maxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
    double d = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i)
        d = std::max(d, static_cast<double>(std::abs(a[i] - b[i])));
    return a.size() == b.size() ? d : 1e9;
}

} // namespace

TEST(TextureLayers, ALayerBlendsItsChannelsOverTheBaseByItsCoverage) {
    const TextureSpec plain = parse(specText(4));
    const TextureSpec layered = parse(layeredSpec(4));
    ASSERT_EQ(layered.layers.size(), 1u);
    EXPECT_EQ(layered.layers[0].quadtree.seed, 5u); // spec seed + 1 + index
    const TextureSet base = generateTextureSet(plain);
    const TextureSet set = generateTextureSet(layered);
    ASSERT_EQ(set.layers.size(), 1u);
    const LayerSet& l = set.layers[0];
    // The layer's own diffuse is its palette's colour 1, flat.
    ASSERT_EQ(l.maps.diffuse.pixels.size(), base.maps.diffuse.pixels.size());
    EXPECT_NEAR(l.maps.diffuse.pixels[0], 240.0 / 255, 1e-6);
    // Coverage is opacity × mask: at most 0.8, and the disc pattern covers part of the image.
    double covered = 0, maxAlpha = 0;
    for (float a : l.coverage.pixels) {
        maxAlpha = std::max(maxAlpha, static_cast<double>(a));
        covered += a > 0.5;
    }
    EXPECT_NEAR(maxAlpha, 0.8, 1e-6);
    const double share = covered / static_cast<double>(l.coverage.pixels.size());
    EXPECT_GT(share, 0.05);
    EXPECT_LT(share, 0.8);
    // Diffuse and roughness: C = base + α (L - base) at every pixel; metallic untouched.
    double diffuseErr = 0, roughErr = 0;
    for (size_t i = 0; i < l.coverage.pixels.size(); ++i) {
        const double a = l.coverage.pixels[i];
        for (int c = 0; c < 3; ++c) {
            const double b = base.maps.diffuse.pixels[3 * i + c], L = l.maps.diffuse.pixels[3 * i + c];
            diffuseErr = std::max(diffuseErr, std::abs(set.maps.diffuse.pixels[3 * i + c] - (b + a * (L - b))));
        }
        const double b = base.maps.roughness.pixels[i];
        roughErr = std::max(roughErr, std::abs(set.maps.roughness.pixels[i] - (b + a * (0.9 - b))));
    }
    EXPECT_LT(diffuseErr, 1e-6);
    EXPECT_LT(roughErr, 1e-6);
    EXPECT_EQ(maxAbsDiff(set.maps.metallic.pixels, base.maps.metallic.pixels), 0.0);
    // The height and the normals are the composite's: they differ from the base where the layer is.
    EXPECT_GT(maxAbsDiff(set.maps.height.pixels, base.maps.height.pixels), 0.1);
    EXPECT_GT(maxAbsDiff(set.maps.normal.pixels, base.maps.normal.pixels), 0.05);
    for (size_t i = 0; i < set.maps.normal.pixels.size(); i += 3) {
        const float* n = &set.maps.normal.pixels[i];
        ASSERT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-5);
    }
    // Tileable: the composite tiles too.
    const SeamFigures f = seamFigures(set.maps.roughness);
    EXPECT_LE(f.seam, f.interior + 1e-6) << f.seam << " vs " << f.interior;

    // Opacity 0: the composite is the base material, byte for byte.
    const TextureSpec off = parse(replaced(layeredSpec(4), R"("opacity": 0.8)", R"("opacity": 0)"));
    const TextureSet none = generateTextureSet(off);
    const std::vector<EncodedFile> a = encodeTextureSet(plain, base), b = encodeTextureSet(off, none);
    ASSERT_EQ(b.size(), a.size() + 2); // + the layer's mask and diffuse
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(b[i].fileName, a[i].fileName);
        EXPECT_TRUE(b[i].bytes == a[i].bytes) << a[i].fileName;
    }
    EXPECT_EQ(b[a.size()].fileName, "layer_granular_mask.png");
    EXPECT_EQ(b[a.size() + 1].fileName, "layer_granular_diffuse.png");
}

TEST(TextureLayers, LayeredSpecsAreDeterministicAndTwoLayersCompositeInOrder) {
    const std::string two = layeredSpec(9, R"(}, {"name": "surface", "seed": 77, "levels": 5,
     "patterns": [{"level": 2, "tile": {"shape": "gaussian"}, "scale": {"uniform": 1.5}, "blend": "add"}],
     "maps": {"roughness": {"values": [0.1, 0.1], "write": true}})");
    const TextureSpec spec = parse(two);
    ASSERT_EQ(spec.layers.size(), 2u);
    EXPECT_EQ(spec.layers[1].quadtree.seed, 77u);
    const std::vector<EncodedFile> a = encodeTextureSet(spec, generateTextureSet(spec));
    const std::vector<EncodedFile> b = encodeTextureSet(spec, generateTextureSet(parse(two)));
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
        EXPECT_TRUE(a[i].bytes == b[i].bytes) << a[i].fileName;
    EXPECT_EQ(a.back().fileName, "layer_surface_roughness.png");
    // The second layer blends over the first's composite.
    const TextureSet set = generateTextureSet(spec);
    const TextureSet one = generateTextureSet(parse(layeredSpec(9)));
    double err = 0;
    for (size_t i = 0; i < set.maps.roughness.pixels.size(); ++i) {
        const double a2 = set.layers[1].coverage.pixels[i], below = one.maps.roughness.pixels[i];
        err = std::max(err, std::abs(set.maps.roughness.pixels[i] - (below + a2 * (0.1 - below))));
    }
    EXPECT_LT(err, 1e-6);
    EXPECT_GT(maxAbsDiff(set.maps.roughness.pixels, one.maps.roughness.pixels), 0.1);
}

TEST(TextureLayers, BadLayersAreRefusedWithOneLineNamingTheField) {
    EXPECT_EQ(refusal(layeredSpec(1)), "(accepted)");
    const std::string good = layeredSpec(1);
    const struct {
        std::string from, to, message;
    } cases[] = {
        {R"("name": "granular")", R"("name": "a/b")", "layers[0].name: 'a/b' is not a file name (A-Z a-z 0-9 . _ -)"},
        {R"("opacity": 0.8)", R"("opacity": 1.2)", "layers[0].opacity: must be in [0, 1]"},
        {R"("opacity": 0.8)", R"("opacity": 0.8, "tileable": false)", "layers[0].tileable: unknown field"},
        {R"("levels": 6, "opacity")", R"("levels": 9, "opacity")", "layers[0].levels: must be an integer in [1, 8]"},
        {R"("diffuse": {"colors": [1], "write": true})", R"("diffuse": {"colors": [2]})",
         "layers[0].maps.diffuse.colors[0]: palette index 2 is out of range (the palette has 2 colours)"},
        {R"("roughness": {"values": [0.9, 0.9]})", R"("normal": {})", "layers[0].maps.normal: unknown field"},
        {R"("maps": {"mask": {}, "diffuse")", R"("maps": {"mask": {"write": true}, "diffuse")",
         "layers[0].maps.mask.write: unknown field"},
        {R"("scale": {"uniform": [0.3, 0.7]})", R"("scale": {"uniform": [0.3, 7]})",
         "layers[0].patterns[0].scale.uniform[1]: must be in (0, 4]"},
    };
    for (const auto& c : cases)
        EXPECT_EQ(refusal(replaced(good, c.from, c.to)), "spec.json: " + c.message);
    // A channel the base does not make cannot be composited.
    EXPECT_EQ(refusal(replaced(good, R"("metallic": {"values": [0, 0.1]},)", "")), "(accepted)");
    EXPECT_EQ(refusal(replaced(replaced(good, R"("metallic": {"values": [0, 0.1]},)", ""),
                               R"("height": {"values": [0, 1]})", R"("metallic": {})")),
              "spec.json: layers[0].maps.metallic: the base material makes no metallic map to composite over (add "
              "maps.metallic)");
    // Without its own palette the layer uses the base's (3 colours).
    EXPECT_EQ(refusal(replaced(replaced(good, R"("palette": {"colors": ["#302010", "#f0f0f0"]},)", ""),
                               R"("colors": [1], "write")", R"("colors": [3], "write")")),
              "spec.json: layers[0].maps.diffuse.colors[0]: palette index 3 is out of range (the palette has 3 "
              "colours)");
    // Names are unique.
    EXPECT_EQ(refusal(layeredSpec(1, R"(}, {"name": "granular", "levels": 2,
     "patterns": [{"level": 1, "tile": {"shape": "disc"}}], "maps": {"mask": {}})")),
              "spec.json: layers[1].name: 'granular' already names layers[0]");
    EXPECT_EQ(refusal(specText(1, R"(, "layers": [])")), "spec.json: layers: must have 1 to 8 elements");
}
