// Colour palette and prominent-colour proportional map of a reference image [A §6.2.2, Fig. 6.5].
#include "bake/texture.hpp"

#include "bake/texture_random.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace viscera::bake {
namespace {

uint32_t pack(Rgb8 c) {
    return (uint32_t{c.r} << 16) | (uint32_t{c.g} << 8) | c.b;
}

Rgb8 unpack(uint32_t v) {
    return {static_cast<uint8_t>(v >> 16), static_cast<uint8_t>(v >> 8), static_cast<uint8_t>(v)};
}

struct ColorCount {
    uint32_t color = 0; ///< packed 0xrrggbb
    uint64_t count = 0;
};

/// The image's distinct colours, most frequent first (equal counts by colour value).
std::vector<ColorCount> distinctColors(const Rgb8Image& image) {
    const size_t n = static_cast<size_t>(image.width) * image.height;
    std::vector<ColorCount> out;
    auto at = [&](size_t i) { return pack({image.pixels[3 * i], image.pixels[3 * i + 1], image.pixels[3 * i + 2]}); };
    if (n > (size_t{1} << 22)) {
        // Large images: one counter per possible colour (64 MiB) beats sorting the pixels.
        std::vector<uint32_t> counts(size_t{1} << 24, 0);
        for (size_t i = 0; i < n; ++i)
            ++counts[at(i)];
        for (uint32_t c = 0; c < counts.size(); ++c)
            if (counts[c]) out.push_back({c, counts[c]});
    } else {
        std::vector<uint32_t> px(n);
        for (size_t i = 0; i < n; ++i)
            px[i] = at(i);
        std::sort(px.begin(), px.end());
        for (size_t i = 0; i < n;) {
            size_t j = i;
            while (j < n && px[j] == px[i])
                ++j;
            out.push_back({px[i], j - i});
            i = j;
        }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const ColorCount& a, const ColorCount& b) { return a.count > b.count; });
    return out;
}

struct Group {
    uint32_t leader = 0;
    uint64_t count = 0;
    std::array<double, 3> sum{};
};

void addTo(Group& g, const ColorCount& c) {
    const Rgb8 v = unpack(c.color);
    g.count += c.count;
    g.sum[0] += static_cast<double>(v.r) * static_cast<double>(c.count);
    g.sum[1] += static_cast<double>(v.g) * static_cast<double>(c.count);
    g.sum[2] += static_cast<double>(v.b) * static_cast<double>(c.count);
}

/// Component-wise threshold grouping [A §6.2.2]; a grid of cells `threshold` wide finds the
/// leaders a colour can be similar to in the 27 cells around it.
std::vector<Group> thresholdGroups(const std::vector<ColorCount>& colors, double threshold) {
    std::vector<Group> groups;
    std::unordered_map<uint32_t, std::vector<uint32_t>> grid;
    auto cell = [threshold](int v) { return static_cast<int>(std::floor(v / threshold)); };
    auto key = [](int i, int j, int k) {
        return static_cast<uint32_t>(((i + 1) * 1024 + (j + 1)) * 1024 + (k + 1)); // cells in [-1, 513)
    };
    for (const ColorCount& c : colors) {
        const Rgb8 v = unpack(c.color);
        const int ci = cell(v.r), cj = cell(v.g), ck = cell(v.b);
        uint32_t found = std::numeric_limits<uint32_t>::max();
        for (int i = ci - 1; i <= ci + 1; ++i)
            for (int j = cj - 1; j <= cj + 1; ++j)
                for (int k = ck - 1; k <= ck + 1; ++k) {
                    auto it = grid.find(key(i, j, k));
                    if (it == grid.end()) continue;
                    for (uint32_t g : it->second) {
                        const Rgb8 l = unpack(groups[g].leader);
                        if (g < found && std::abs(l.r - v.r) < threshold && std::abs(l.g - v.g) < threshold &&
                            std::abs(l.b - v.b) < threshold)
                            found = g;
                    }
                }
        if (found == std::numeric_limits<uint32_t>::max()) {
            found = static_cast<uint32_t>(groups.size());
            groups.push_back({c.color, 0, {}});
            grid[key(ci, cj, ck)].push_back(found);
        }
        addTo(groups[found], c);
    }
    return groups;
}

double distance2(const std::array<double, 3>& a, uint32_t packed) {
    const Rgb8 v = unpack(packed);
    const double dr = a[0] - v.r, dg = a[1] - v.g, db = a[2] - v.b;
    return dr * dr + dg * dg + db * db;
}

/// Index i with probability weight[i] / Σ weight (Σ weight > 0).
size_t pickWeighted(const std::vector<double>& weight, std::mt19937_64& rng) {
    double total = 0;
    for (double w : weight)
        total += w;
    const double r = detail::uniform01(rng) * total;
    double acc = 0;
    for (size_t i = 0; i < weight.size(); ++i) {
        acc += weight[i];
        if (r < acc && weight[i] > 0) return i;
    }
    for (size_t i = weight.size(); i-- > 0;) // r rounded up to the total: the last positive weight
        if (weight[i] > 0) return i;
    return 0;
}

/// Weighted k-means with k-means++ seeding over the distinct colours.
std::vector<Group> kmeansGroups(const std::vector<ColorCount>& colors, const PaletteParams& p) {
    std::mt19937_64 rng(detail::splitmix64(p.seed));
    const size_t n = colors.size();
    std::vector<std::array<double, 3>> centres;
    std::vector<double> weight(n), nearest(n, std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < n; ++i)
        weight[i] = static_cast<double>(colors[i].count);
    while (centres.size() < static_cast<size_t>(p.k)) {
        std::vector<double> w(n);
        double total = 0;
        for (size_t i = 0; i < n; ++i)
            total += w[i] = centres.empty() ? weight[i] : weight[i] * nearest[i];
        if (!(total > 0)) break; // every colour is already a centre
        const Rgb8 c = unpack(colors[pickWeighted(w, rng)].color);
        centres.push_back({double(c.r), double(c.g), double(c.b)});
        for (size_t i = 0; i < n; ++i)
            nearest[i] = std::min(nearest[i], distance2(centres.back(), colors[i].color));
    }
    std::vector<uint32_t> assign(n, std::numeric_limits<uint32_t>::max());
    std::vector<Group> groups;
    for (int it = 0; it < p.maxIterations; ++it) {
        bool changed = false;
        for (size_t i = 0; i < n; ++i) {
            uint32_t best = 0;
            double bestD = distance2(centres[0], colors[i].color);
            for (uint32_t c = 1; c < centres.size(); ++c) {
                const double d = distance2(centres[c], colors[i].color);
                if (d < bestD) {
                    bestD = d;
                    best = c;
                }
            }
            changed |= assign[i] != best;
            assign[i] = best;
        }
        groups.assign(centres.size(), Group{});
        for (size_t i = 0; i < n; ++i)
            addTo(groups[assign[i]], colors[i]);
        for (size_t c = 0; c < centres.size(); ++c)
            if (groups[c].count > 0)
                for (int ch = 0; ch < 3; ++ch)
                    centres[c][static_cast<size_t>(ch)] =
                        groups[c].sum[static_cast<size_t>(ch)] / static_cast<double>(groups[c].count);
        if (!changed) break;
    }
    return groups;
}

} // namespace

std::vector<PaletteColor> extractPalette(const Rgb8Image& image, const PaletteParams& p) {
    const char* where = "bake::extractPalette(): ";
    if (image.width < 1 || image.height < 1 ||
        image.pixels.size() != static_cast<size_t>(image.width) * image.height * 3)
        throw std::invalid_argument(std::string(where) + "image must be a non-empty RGB image");
    if (p.method == PaletteMethod::Threshold && !(p.threshold > 0 && p.threshold <= 256))
        throw std::invalid_argument(std::string(where) + "threshold must be in (0, 256]");
    if (p.method == PaletteMethod::KMeans && (p.k < 1 || p.k > 64 || p.maxIterations < 1 || p.maxIterations > 1000))
        throw std::invalid_argument(std::string(where) + "k must be in [1, 64] and maxIterations in [1, 1000]");
    if (p.maxColors < 1 || p.maxColors > 256)
        throw std::invalid_argument(std::string(where) + "maxColors must be in [1, 256]");
    const std::vector<ColorCount> colors = distinctColors(image);
    const std::vector<Group> groups =
        p.method == PaletteMethod::Threshold ? thresholdGroups(colors, p.threshold) : kmeansGroups(colors, p);
    const double total = static_cast<double>(image.width) * image.height;
    std::vector<PaletteColor> out;
    for (const Group& g : groups) {
        if (g.count == 0) continue;
        auto mean = [&](size_t ch) {
            return static_cast<uint8_t>(std::clamp(std::lround(g.sum[ch] / static_cast<double>(g.count)), 0L, 255L));
        };
        out.push_back({{mean(0), mean(1), mean(2)}, g.count, static_cast<double>(g.count) / total});
    }
    std::sort(out.begin(), out.end(), [](const PaletteColor& a, const PaletteColor& b) {
        return a.pixels != b.pixels ? a.pixels > b.pixels : pack(a.color) < pack(b.color);
    });
    if (out.size() > static_cast<size_t>(p.maxColors)) out.resize(static_cast<size_t>(p.maxColors));
    return out;
}

Rgb8Image proportionalMap(const std::vector<PaletteColor>& colors, int width, int height) {
    if (colors.empty() || width < 1 || height < 1)
        throw std::invalid_argument("bake::proportionalMap(): needs colours and a size of at least 1 x 1");
    double total = 0;
    for (const PaletteColor& c : colors)
        total += c.share;
    Rgb8Image out{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height * 3)};
    double cumulative = 0;
    int x0 = 0;
    for (size_t i = 0; i < colors.size(); ++i) {
        cumulative += colors[i].share;
        const int x1 =
            i + 1 == colors.size() ? width : static_cast<int>(std::lround(total > 0 ? cumulative / total * width : 0));
        for (int y = 0; y < height; ++y)
            for (int x = x0; x < std::min(x1, width); ++x) {
                uint8_t* px = &out.pixels[3 * (static_cast<size_t>(y) * width + x)];
                px[0] = colors[i].color.r;
                px[1] = colors[i].color.g;
                px[2] = colors[i].color.b;
            }
        x0 = std::max(x0, x1);
    }
    return out;
}

Rgb8Image paletteSwatches(const std::vector<Rgb8>& colors, int swatch) {
    if (colors.empty() || swatch < 1)
        throw std::invalid_argument("bake::paletteSwatches(): needs colours and a swatch of at least 1 pixel");
    std::vector<PaletteColor> equal;
    for (Rgb8 c : colors)
        equal.push_back({c, 1, 1.0});
    return proportionalMap(equal, swatch * static_cast<int>(colors.size()), swatch);
}

} // namespace viscera::bake
