// Synthetic reference photograph for palette extraction: blotchy regions of given colours and
// area shares from quadtree noise, blurred across their borders, with per-pixel noise.
#include "bake/texture.hpp"

#include "bake/texture_random.hpp"

#include "sim/util/format.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace viscera::bake {
namespace {

[[noreturn]] void badReference(const std::string& field, const std::string& rule) {
    throw std::invalid_argument("bake::generateReferenceImage(): " + field + " " + rule);
}

void checkReference(const ReferenceSpec& s) {
    if (s.size < 16 || s.size > 4096 || !std::has_single_bit(static_cast<unsigned>(s.size)))
        badReference("size", std::to_string(s.size) + " must be a power of two in [16, 4096]");
    if (s.colors.empty() || s.colors.size() > 16)
        badReference("colors", "must have 1 to 16 colours (has " + std::to_string(s.colors.size()) + ")");
    if (s.shares.size() != s.colors.size())
        badReference("shares", "must have one share per colour (" + std::to_string(s.colors.size()) + " colours, " +
                                   std::to_string(s.shares.size()) + " shares)");
    double sum = 0;
    for (size_t i = 0; i < s.shares.size(); ++i) {
        if (!(s.shares[i] > 0 && s.shares[i] <= 1))
            badReference("shares[" + std::to_string(i) + "]", "must be in (0, 1]");
        sum += s.shares[i];
    }
    if (!(std::abs(sum - 1) <= 1e-6))
        badReference("shares", "must sum to 1 within 1e-6 (sum " + sim::formatNumber(sum, 9) + ")");
    if (!(s.noise >= 0 && s.noise <= 64)) badReference("noise", "must be in [0, 64]");
    if (!(s.blurPx >= 0 && s.blurPx <= 16)) badReference("blurPx", "must be in [0, 16]");
}

/// Corrections of the region bounds after the blur, at most, and the cumulative share error
/// (of all pixels) that ends them early.
constexpr int kCalibrationRounds = 3;
constexpr double kCalibrationTolerance = 1e-3;

/// The noise field is made at most this wide and upsampled to larger sizes: its finest blobs
/// are 1/32 of the image wide in any case.
constexpr int kFieldSize = 256;

/// The noise field of an n × n image (n <= kFieldSize): blobs on levels 1 .. min(5, log2(n) - 2),
/// each level 0.6 times the amplitude of the one above it, summed without clamping so that the
/// ranking has few ties.
std::vector<float> blobField(uint64_t seed, int n) {
    const int finest = std::min(5, std::countr_zero(static_cast<unsigned>(n)) - 2);
    std::vector<float> field(static_cast<size_t>(n) * n, 0.0f);
    double weight = 1;
    for (int level = 1; level <= finest; ++level, weight *= 0.6) {
        QuadtreeParams q;
        q.size = n;
        q.seed = detail::splitmix64(seed ^ 0x7265666572656e63ull); // "referenc"
        q.levels = finest + 1;
        q.tileable = true;
        LevelPattern p;
        p.level = level;
        p.tile.shape = TileShape::Gaussian;
        p.tile.sigma = 0.45;
        p.rotationDeg = {0, 360};
        p.offsetRadius = {0, 0.5};
        p.offsetAngleDeg = {0, 360};
        p.width = {1.2, 2.2};
        p.height = {0.8, 1.6};
        p.opacity = {0.4, 1};
        p.blend = BlendMode::Max;
        q.patterns = {p};
        const GrayImage m = generateMask(q);
        for (size_t i = 0; i < field.size(); ++i)
            field[i] += static_cast<float>(weight * m.pixels[i]);
    }
    return field;
}

/// The field at `size`: made at min(size, kFieldSize), then bilinearly upsampled with wrap-around
/// (pixel centres aligned), so the image still tiles seamlessly.
std::vector<float> blobField(const ReferenceSpec& s) {
    const int n = std::min(s.size, kFieldSize);
    const std::vector<float> coarse = blobField(s.seed, n);
    if (n == s.size) return coarse;
    std::vector<float> field(static_cast<size_t>(s.size) * s.size);
    const double scale = static_cast<double>(n) / s.size;
    const int wrap = n - 1; // n is a power of two
    for (int y = 0; y < s.size; ++y) {
        const double v = (y + 0.5) * scale - 0.5, fy = v - std::floor(v);
        const int y0 = static_cast<int>(std::floor(v)) & wrap, y1 = (y0 + 1) & wrap;
        for (int x = 0; x < s.size; ++x) {
            const double u = (x + 0.5) * scale - 0.5, fx = u - std::floor(u);
            const int x0 = static_cast<int>(std::floor(u)) & wrap, x1 = (x0 + 1) & wrap;
            auto at = [&](int xi, int yi) { return static_cast<double>(coarse[static_cast<size_t>(yi) * n + xi]); };
            field[static_cast<size_t>(y) * s.size + x] = static_cast<float>(
                (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1)));
        }
    }
    return field;
}

/// Pixel indices in ascending field order, ties by index.
std::vector<uint32_t> rankOrder(const std::vector<float>& field) {
    // Non-negative floats order as their bit patterns: one 64-bit key (value, index) per pixel.
    std::vector<uint64_t> keys(field.size());
    for (size_t i = 0; i < field.size(); ++i) {
        uint32_t bits = 0;
        std::memcpy(&bits, &field[i], sizeof bits);
        keys[i] = (static_cast<uint64_t>(bits) << 32) | static_cast<uint64_t>(i);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<uint32_t> order(keys.size());
    for (size_t r = 0; r < keys.size(); ++r)
        order[r] = static_cast<uint32_t>(keys[r] & 0xffffffffu);
    return order;
}

/// The label image (colour c for the ranks in [bounds[c], bounds[c + 1])) as three channels in
/// 8-bit units, blurred across the region borders.
std::array<GrayImage, 3> blurredRegions(const ReferenceSpec& s, const std::vector<uint32_t>& order,
                                        const std::vector<size_t>& bounds) {
    std::array<GrayImage, 3> channel;
    for (GrayImage& g : channel)
        g = {s.size, s.size, std::vector<float>(order.size())};
    for (size_t c = 0; c < s.colors.size(); ++c)
        for (size_t r = bounds[c]; r < bounds[c + 1]; ++r) {
            channel[0].pixels[order[r]] = s.colors[c].r;
            channel[1].pixels[order[r]] = s.colors[c].g;
            channel[2].pixels[order[r]] = s.colors[c].b;
        }
    for (GrayImage& g : channel)
        g = blurGaussian(g, s.blurPx, true);
    return channel;
}

/// Pixels whose nearest colour (RGB) is colours[c], for each c.
std::vector<size_t> nearestCounts(const ReferenceSpec& s, const std::array<GrayImage, 3>& channel) {
    std::vector<size_t> counts(s.colors.size(), 0);
    for (size_t i = 0; i < channel[0].pixels.size(); ++i) {
        size_t best = 0;
        float bestD = std::numeric_limits<float>::infinity();
        for (size_t c = 0; c < s.colors.size(); ++c) {
            const float dr = channel[0].pixels[i] - s.colors[c].r, dg = channel[1].pixels[i] - s.colors[c].g,
                        db = channel[2].pixels[i] - s.colors[c].b;
            const float d = dr * dr + dg * dg + db * db;
            if (d < bestD) {
                bestD = d;
                best = c;
            }
        }
        ++counts[best];
    }
    return counts;
}

} // namespace

Rgb8Image generateReferenceImage(const ReferenceSpec& s) {
    checkReference(s);
    const std::vector<uint32_t> order = rankOrder(blobField(s));
    const size_t n = order.size(), k = s.colors.size();
    // The rank bounds of the colours' regions: the shares, rounded to whole pixels.
    std::vector<size_t> target(k + 1, 0);
    double cumulative = 0;
    for (size_t c = 1; c < k; ++c)
        target[c] = std::min(n, static_cast<size_t>(std::llround((cumulative += s.shares[c - 1]) * double(n))));
    target[k] = n;
    std::vector<size_t> bounds = target;
    std::array<GrayImage, 3> channel;
    for (int round = 0;; ++round) {
        channel = blurredRegions(s, order, bounds);
        if (s.blurPx == 0 || round == kCalibrationRounds) break;
        // The blur moves border pixels towards the neighbouring colour, and thin or small regions
        // lose more than they gain: move each bound by what its cumulative share missed.
        const std::vector<size_t> counts = nearestCounts(s, channel);
        std::vector<size_t> next = bounds;
        size_t measured = 0, worst = 0;
        for (size_t c = 1; c < k; ++c) {
            measured += counts[c - 1];
            const auto miss = static_cast<int64_t>(target[c]) - static_cast<int64_t>(measured);
            worst = std::max(worst, static_cast<size_t>(std::abs(miss)));
            const int64_t moved = static_cast<int64_t>(bounds[c]) + miss;
            next[c] = static_cast<size_t>(
                std::clamp<int64_t>(moved, static_cast<int64_t>(next[c - 1]), static_cast<int64_t>(n)));
        }
        if (static_cast<double>(worst) <= kCalibrationTolerance * double(n)) break;
        bounds = next;
    }
    Rgb8Image out{s.size, s.size, std::vector<uint8_t>(3 * n)};
    std::mt19937_64 rng(detail::splitmix64(s.seed ^ 0x6e6f697365ull)); // "noise"
    auto triangular = [&rng] {
        const double u = detail::uniform01(rng);
        return u + detail::uniform01(rng) - 1.0;
    };
    for (size_t i = 0; i < n; ++i) {
        const double shared = triangular();
        for (size_t c = 0; c < 3; ++c) {
            const double v = channel[c].pixels[i] + s.noise * 0.5 * (shared + triangular());
            out.pixels[3 * i + c] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
        }
    }
    return out;
}

} // namespace viscera::bake
