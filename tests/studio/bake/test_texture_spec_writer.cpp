// The texture spec's writer (bake::textureSpecText) beside its reader: the shipped sample specs,
// the specs the texture tests build and a spec with every optional field set away from its
// default read back equal, field by field, and write the same text again. Fixtures (the image
// files a spec names) are written at run time.
#include "bake/texture.hpp"

#include "sim/util/atomic_file.hpp"
#include "support/scratch_dir.hpp"
#include "texture_spec_fixture.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iterator>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace viscera;
using namespace viscera::bake;

namespace {

/// Every difference between two specs, one line "<field>: <a> vs <b>" each. The origin (the
/// name in messages) is not compared.
class SpecDiff {
public:
    std::vector<std::string> lines;

    template <class T> void value(const std::string& field, const T& a, const T& b) {
        if (!(a == b)) lines.push_back(field + ": " + testing::PrintToString(a) + " vs " + testing::PrintToString(b));
    }
    void range(const std::string& field, Range a, Range b) {
        value(field + ".lo", a.lo, b.lo);
        value(field + ".hi", a.hi, b.hi);
    }
    void colors(const std::string& field, const std::vector<Rgb8>& a, const std::vector<Rgb8>& b) {
        value(field, hexList(a), hexList(b));
    }
    /// Sizes and pixels (the pixels as one line: equal or not).
    template <class Image> void image(const std::string& field, const Image& a, const Image& b) {
        value(field + ".width", a.width, b.width);
        value(field + ".height", a.height, b.height);
        if (a.pixels != b.pixels) lines.push_back(field + ".pixels differ");
    }

    void quadtree(const std::string& field, const QuadtreeParams& a, const QuadtreeParams& b) {
        value(field + ".size", a.size, b.size);
        value(field + ".seed", a.seed, b.seed);
        value(field + ".levels", a.levels, b.levels);
        value(field + ".tileable", a.tileable, b.tileable);
        value(field + ".base", a.base, b.base);
        value(field + ".patterns.size", a.patterns.size(), b.patterns.size());
        for (size_t i = 0; i < a.patterns.size() && i < b.patterns.size(); ++i)
            pattern(field + ".patterns[" + std::to_string(i) + "]", a.patterns[i], b.patterns[i]);
    }
    void pattern(const std::string& field, const LevelPattern& a, const LevelPattern& b) {
        value(field + ".level", a.level, b.level);
        value(field + ".tile.shape", a.tile.shape, b.tile.shape);
        value(field + ".tile.sigma", a.tile.sigma, b.tile.sigma);
        value(field + ".tile.file", a.tile.file, b.tile.file);
        image(field + ".tile.image", a.tile.image, b.tile.image);
        range(field + ".rotationDeg", a.rotationDeg, b.rotationDeg);
        range(field + ".offsetRadius", a.offsetRadius, b.offsetRadius);
        range(field + ".offsetAngleDeg", a.offsetAngleDeg, b.offsetAngleDeg);
        range(field + ".width", a.width, b.width);
        range(field + ".height", a.height, b.height);
        value(field + ".uniformScale", a.uniformScale, b.uniformScale);
        range(field + ".opacity", a.opacity, b.opacity);
        value(field + ".probability", a.probability, b.probability);
        value(field + ".blend", a.blend, b.blend);
    }
    void palette(const std::string& field, const std::optional<PaletteSpec>& a, const std::optional<PaletteSpec>& b) {
        value(field + ".has_value", a.has_value(), b.has_value());
        if (!a || !b) return;
        colors(field + ".colors", a->colors, b->colors);
        image(field + ".image", a->image, b->image);
        value(field + ".imageFile", a->imageFile, b->imageFile);
        value(field + ".reference.has_value", a->reference.has_value(), b->reference.has_value());
        if (a->reference && b->reference) reference(field + ".reference", *a->reference, *b->reference);
        value(field + ".params.method", a->params.method, b->params.method);
        value(field + ".params.threshold", a->params.threshold, b->params.threshold);
        value(field + ".params.k", a->params.k, b->params.k);
        value(field + ".params.maxIterations", a->params.maxIterations, b->params.maxIterations);
        value(field + ".params.seed", a->params.seed, b->params.seed);
        value(field + ".params.maxColors", a->params.maxColors, b->params.maxColors);
        value(field + ".prominentThreshold", a->prominentThreshold, b->prominentThreshold);
    }
    void reference(const std::string& field, const ReferenceSpec& a, const ReferenceSpec& b) {
        value(field + ".size", a.size, b.size);
        value(field + ".seed", a.seed, b.seed);
        colors(field + ".colors", a.colors, b.colors);
        value(field + ".shares", a.shares, b.shares);
        value(field + ".noise", a.noise, b.noise);
        value(field + ".blurPx", a.blurPx, b.blurPx);
    }
    void material(const std::string& field, const MaterialParams& a, const MaterialParams& b) {
        colors(field + ".diffuseColors", a.diffuseColors, b.diffuseColors);
        value(field + ".diffuseStops", a.diffuseStops, b.diffuseStops);
        for (auto [name, x, y] :
             {std::tuple{"roughness", a.roughness, b.roughness}, std::tuple{"metallic", a.metallic, b.metallic},
              std::tuple{"height", a.height, b.height}}) {
            value(field + "." + name + ".atZero", x.atZero, y.atZero);
            value(field + "." + name + ".atOne", x.atOne, y.atOne);
        }
        value(field + ".heightBlurPx", a.heightBlurPx, b.heightBlurPx);
        value(field + ".normalDepth", a.normalDepth, b.normalDepth);
        value(field + ".tileable", a.tileable, b.tileable);
    }
    void requests(const std::string& field, const std::vector<MapRequest>& a, const std::vector<MapRequest>& b) {
        auto text = [](const std::vector<MapRequest>& maps) {
            std::vector<std::string> out;
            for (const MapRequest& r : maps)
                out.push_back(std::string(mapName(r.kind)) + "/" + std::to_string(r.bits));
            return out;
        };
        value(field, text(a), text(b));
    }
    void layer(const std::string& field, const LayerSpec& a, const LayerSpec& b) {
        value(field + ".name", a.name, b.name);
        quadtree(field + ".quadtree", a.quadtree, b.quadtree);
        palette(field + ".palette", a.palette, b.palette);
        value(field + ".opacity", a.opacity, b.opacity);
        material(field + ".material", a.material, b.material);
        value(field + ".diffuseIndices", a.diffuseIndices, b.diffuseIndices);
        for (auto [name, x, y] : {std::tuple{"diffuse", a.paints.diffuse, b.paints.diffuse},
                                  std::tuple{"roughness", a.paints.roughness, b.paints.roughness},
                                  std::tuple{"metallic", a.paints.metallic, b.paints.metallic},
                                  std::tuple{"height", a.paints.height, b.paints.height},
                                  std::tuple{"normal", a.paints.normal, b.paints.normal}})
            value(field + ".paints." + name, x, y);
        requests(field + ".files", a.files, b.files);
    }
    void spec(const TextureSpec& a, const TextureSpec& b) {
        value("name", a.name, b.name);
        quadtree("quadtree", a.quadtree, b.quadtree);
        palette("palette", a.palette, b.palette);
        material("material", a.material, b.material);
        value("diffuseIndices", a.diffuseIndices, b.diffuseIndices);
        requests("maps", a.maps, b.maps);
        value("swatchPx", a.swatchPx, b.swatchPx);
        value("prominentWidth", a.prominentWidth, b.prominentWidth);
        value("prominentHeight", a.prominentHeight, b.prominentHeight);
        value("layers.size", a.layers.size(), b.layers.size());
        for (size_t i = 0; i < a.layers.size() && i < b.layers.size(); ++i)
            layer("layers[" + std::to_string(i) + "]", a.layers[i], b.layers[i]);
    }

private:
    static std::vector<std::string> hexList(const std::vector<Rgb8>& colors) {
        std::vector<std::string> out;
        for (Rgb8 c : colors)
            out.push_back(hexColor(c));
        return out;
    }
};

std::vector<std::string> differences(const TextureSpec& a, const TextureSpec& b) {
    SpecDiff d;
    d.spec(a, b);
    return d.lines;
}

/// The member paths of a JSON document ("maps.height.blur_px", "layers[0].patterns[1].tile").
void keyPaths(const nlohmann::json& j, const std::string& path, std::set<std::string>& out) {
    if (j.is_object()) {
        for (const auto& [key, value] : j.items()) {
            const std::string sub = path.empty() ? key : path + "." + key;
            out.insert(sub);
            keyPaths(value, sub, out);
        }
    } else if (j.is_array()) {
        for (size_t i = 0; i < j.size(); ++i)
            keyPaths(j[i], path + "[" + std::to_string(i) + "]", out);
    }
}

/// Writes `spec`, reads the text back from the same folder and checks: every field equal, the
/// text of the re-read spec the same, the text formatted as documented.
void expectRoundTrip(const TextureSpec& spec, const fs::path& folder) {
    const std::string text = textureSpecText(spec);
    const TextureSpec back = parseTextureSpec(text, spec.origin, folder);
    EXPECT_THAT(differences(spec, back), testing::IsEmpty()) << text;
    EXPECT_EQ(textureSpecText(back), text);
    ASSERT_FALSE(text.empty());
    EXPECT_EQ(text.back(), '\n');
    EXPECT_EQ(nlohmann::json::parse(text).dump(2) + "\n", text); // 2-space indent, keys sorted
}

/// The 7-level spec of the texture tests, with `extra` members.
std::string testSpecText(const std::string& extra = "") {
    return viscera::test::specText(4, extra);
}

/// Every key the reader knows, each value away from its default: a layer with its own image
/// palette (k-means) and explicit seed, a layer with explicit colours and the default seed, a
/// synthetic reference palette (threshold), every map, every tile shape and blend mode.
const char* kEverything = R"({
  "name": "every_field", "size": 64, "seed": 12, "levels": 6, "tileable": false, "base": 0.15, "bit_depth": 16,
  "patterns": [
    {"level": 0, "tile": {"shape": "disc"}, "rotation_deg": [-30, 45], "offset": {"radius": [0.1, 0.7],
     "angle_deg": [10, 200]}, "scale": {"width": [0.5, 2], "height": [0.25, 1.5]}, "opacity": [0.3, 0.9],
     "probability": 0.9, "blend": "subtract"},
    {"level": 1, "tile": {"shape": "gaussian", "sigma": 0.55}, "rotation_deg": 12, "offset": {"radius": 0.3,
     "angle_deg": -90}, "scale": {"uniform": [0.7, 1.3]}, "opacity": 0.6, "probability": 0.45, "blend": "max"},
    {"level": 2, "tile": {"shape": "bell"}, "scale": {"uniform": 0.8}, "blend": "min"},
    {"level": 3, "tile": {"shape": "image", "file": "tiles/blob.png"}, "scale": {"width": 1.5, "height": [0.5, 0.75]},
     "blend": "multiply"},
    {"level": 4, "tile": {"shape": "gaussian"}, "blend": "add"}
  ],
  "palette": {"reference": {"size": 32, "seed": 9, "colors": ["#8a2b24", "#c9645a", "#f0d2c4"],
                            "shares": [0.5, 0.3, 0.2], "noise": 3.5, "blur_px": 0.75},
              "method": "threshold", "threshold": 30, "prominent_threshold": 70, "max_colors": 5},
  "maps": {"mask": {"bit_depth": 8}, "diffuse": {"colors": [2, 0, 1], "stops": [0.1, 0.5, 0.8], "bit_depth": 8},
           "roughness": {"values": [0.7, 0.2], "bit_depth": 8}, "metallic": {"values": [0.05, 0.4]},
           "height": {"values": [0.2, 0.9], "blur_px": 2.5, "bit_depth": 8}, "normal": {"depth": 0.03},
           "palette": {"swatch_px": 20}, "prominent": {"width": 300, "height": 30}, "reference": {}},
  "layers": [
    {"name": "granular", "seed": 40, "levels": 5, "base": 0.1, "opacity": 0.7,
     "patterns": [{"level": 4, "tile": {"shape": "disc"}, "probability": 0.6, "blend": "max"}],
     "palette": {"image": "refs/photo.png", "method": "kmeans", "k": 4, "iterations": 50,
                 "prominent_threshold": 80, "max_colors": 6},
     "maps": {"mask": {"bit_depth": 8}, "diffuse": {"colors": [1, 0], "stops": [0.2, 0.9], "write": true, "bit_depth": 8},
              "roughness": {"values": [0.9, 0.8]}, "metallic": {"values": [0.3, 0.6], "write": true},
              "height": {"values": [0.1, 0.4], "write": true, "bit_depth": 8}}},
    {"name": "surface", "levels": 3,
     "patterns": [{"level": 2, "tile": {"shape": "bell"}, "blend": "add"}],
     "palette": {"colors": ["#302010", "#f0f0f0"]},
     "maps": {"diffuse": {}, "height": {"values": [0.4, 0.45], "write": false}}}
  ]
})";

/// The image files kEverything names, written into `folder`.
void writeEverythingFiles(const fs::path& folder) {
    GrayImage blob{16, 16, {}};
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            blob.pixels.push_back(static_cast<float>((x + y) % 16) / 15.0f);
    writeFileAtomic(folder / "tiles" / "blob.png", encodePng(blob, 8));
    Rgb8Image photo{8, 4, {}};
    for (int i = 0; i < photo.width * photo.height; ++i)
        for (uint8_t v : {uint8_t(40 + 20 * (i % 3)), uint8_t(10 * (i % 5)), uint8_t(200 - 7 * (i % 4))})
            photo.pixels.push_back(v);
    writeFileAtomic(folder / "refs" / "photo.png", encodePng(photo));
}

} // namespace

TEST(TextureSpecWriter, ShippedSampleSpecsReadBackEqual) {
    int samples = 0;
    for (const fs::directory_entry& project : fs::directory_iterator(fs::path(VISCERA_SOURCE_DIR) / "projects")) {
        const fs::path textures = project.path() / "textures";
        if (!fs::is_directory(textures)) continue;
        for (const fs::directory_entry& file : fs::directory_iterator(textures)) {
            if (file.path().extension() != ".json") continue;
            SCOPED_TRACE(file.path().string());
            const TextureSpec spec = loadTextureSpec(file.path());
            expectRoundTrip(spec, file.path().parent_path());
            ++samples;
        }
    }
    EXPECT_GE(samples, 5); // liver: organ, fascia; rectum: fat, vessel, fascia
}

TEST(TextureSpecWriter, SpecsOfTheTextureTestsReadBackEqual) {
    const std::string layer = R"(, "layers": [
    {"name": "granular", "levels": 6, "opacity": 0.8,
     "patterns": [{"level": 4, "tile": {"shape": "disc"}, "scale": {"uniform": [0.3, 0.7]},
                   "offset": {"radius": [0, 0.4]}, "probability": 0.6, "blend": "max"}],
     "palette": {"colors": ["#302010", "#f0f0f0"]},
     "maps": {"mask": {}, "diffuse": {"colors": [1], "write": true}, "roughness": {"values": [0.9, 0.9]},
              "height": {"values": [0, 1]}}}, {"name": "surface", "seed": 77, "levels": 5,
     "patterns": [{"level": 2, "tile": {"shape": "gaussian"}, "scale": {"uniform": 1.5}, "blend": "add"}],
     "maps": {"roughness": {"values": [0.1, 0.1], "write": true}}}])";
    const std::string minimal = R"({"size": 16, "seed": 0, "levels": 1,
      "patterns": [{"level": 0, "tile": {"shape": "disc"}}], "maps": {"mask": {}}})";
    for (const std::string& text : {testSpecText(), testSpecText(layer), minimal}) {
        SCOPED_TRACE(text);
        expectRoundTrip(parseTextureSpec(text, "spec.json", "."), ".");
    }
    // The name taken from the origin is written, so another origin reads the same name.
    const TextureSpec named = parseTextureSpec(minimal, "dir/organ_wall.json", ".");
    EXPECT_EQ(parseTextureSpec(textureSpecText(named), "x.json", ".").name, "organ_wall");
}

TEST(TextureSpecWriter, EveryOptionalFieldReadsBackEqual) {
    test::Scratch scratch("viscera-texture-writer");
    const fs::path folder = scratch.dir / "spec";
    writeEverythingFiles(folder);
    const TextureSpec spec = parseTextureSpec(kEverything, "every.json", folder);
    // The fixture reaches what it means to: away from the defaults where a writer could drop them.
    ASSERT_EQ(spec.layers.size(), 2u);
    EXPECT_EQ(spec.layers[0].quadtree.seed, 40u);
    EXPECT_EQ(spec.layers[1].quadtree.seed, 14u); // base seed + 1 + index: not written
    ASSERT_TRUE(spec.palette && spec.palette->reference);
    ASSERT_TRUE(spec.layers[0].palette);
    EXPECT_EQ(spec.layers[0].palette->imageFile, "refs/photo.png");
    EXPECT_EQ(spec.layers[0].palette->image.width, 8);
    EXPECT_EQ(spec.quadtree.patterns[3].tile.file, "tiles/blob.png");
    EXPECT_EQ(spec.maps.size(), 9u);
    expectRoundTrip(spec, folder);

    // Every key of the fixture is in the written text (besides defaults it adds).
    std::set<std::string> given, written;
    keyPaths(nlohmann::json::parse(kEverything), "", given);
    keyPaths(nlohmann::json::parse(textureSpecText(spec)), "", written);
    std::vector<std::string> dropped;
    std::set_difference(given.begin(), given.end(), written.begin(), written.end(), std::back_inserter(dropped));
    EXPECT_THAT(dropped, testing::IsEmpty());
    // File references stay the relative paths the spec holds.
    const nlohmann::json j = nlohmann::json::parse(textureSpecText(spec));
    EXPECT_EQ(j["patterns"][3]["tile"]["file"], "tiles/blob.png");
    EXPECT_EQ(j["layers"][0]["palette"]["image"], "refs/photo.png");
    EXPECT_FALSE(j["layers"][1].contains("seed"));
}

TEST(TextureSpecWriter, AChangedFieldIsWrittenAndReadBack) {
    test::Scratch scratch("viscera-texture-writer");
    const fs::path folder = scratch.dir / "spec";
    writeEverythingFiles(folder);
    const TextureSpec original = parseTextureSpec(kEverything, "every.json", folder);
    // Each edit changes one field a writer could forget; the text differs and reads back equal.
    const std::vector<std::pair<std::string, std::function<void(TextureSpec&)>>> edits = {
        {"base", [](TextureSpec& s) { s.quadtree.base = 0.35; }},
        {"tile sigma", [](TextureSpec& s) { s.quadtree.patterns[1].tile.sigma = 0.25; }},
        {"height range",
         [](TextureSpec& s) {
             s.quadtree.patterns[0].height = {0.4, 0.6};
         }},
        {"palette threshold", [](TextureSpec& s) { s.palette->params.threshold = 31.5; }},
        {"reference noise", [](TextureSpec& s) { s.palette->reference->noise = 2; }},
        {"diffuse stops",
         [](TextureSpec& s) {
             s.material.diffuseStops = {0, 0.5, 1};
         }},
        {"mask bits", [](TextureSpec& s) { s.maps[0].bits = 16; }},
        {"layer k", [](TextureSpec& s) { s.layers[0].palette->params.k = 5; }},
        {"layer seed", [](TextureSpec& s) { s.layers[1].quadtree.seed = 3; }},
        {"layer writes",
         [](TextureSpec& s) {
             s.layers[1].files.push_back({MapKind::Height, 16});
         }},
    };
    const std::string before = textureSpecText(original);
    for (const auto& [what, edit] : edits) {
        SCOPED_TRACE(what);
        TextureSpec spec = original;
        edit(spec);
        EXPECT_NE(textureSpecText(spec), before);
        expectRoundTrip(spec, folder);
    }
}
