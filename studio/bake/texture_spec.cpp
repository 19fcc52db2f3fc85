// The texture spec (JSON, read through sim::JsonField; written back by textureSpecText, each
// writer beside its reader, one rule per field) and the bake of its files.
#include "bake/texture.hpp"

#include <algorithm>

#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <bit>
#include <chrono>
#include <cmath>
#include <future>

namespace viscera::bake {
namespace {

namespace fs = std::filesystem;
using sim::formatNumber;
using sim::JsonField;
using sim::NumberRule;

/// A number (that value) or [lo, hi] with lo <= hi, each admitted by `rule`.
Range readRange(const JsonField& f, const NumberRule& rule) {
    if (f.value().is_array()) {
        const std::vector<JsonField> e = f.items(2, 2);
        const Range r{e[0].number(rule), e[1].number(rule)};
        if (r.lo > r.hi)
            f.fail("[" + formatNumber(r.lo) + ", " + formatNumber(r.hi) +
                   "] is not an interval (lower bound above upper)");
        return r;
    }
    if (!f.value().is_number())
        f.fail(std::string("must be a number or [lo, hi] (found ") + f.value().type_name() + ")");
    const double v = f.number(rule);
    return {v, v};
}

Range readRange(const JsonField& parent, std::string_view key, Range fallback, const NumberRule& rule) {
    auto f = parent.find(key);
    return f ? readRange(*f, rule) : fallback;
}

/// A number when lo == hi, else [lo, hi] (readRange reads both).
nlohmann::json rangeJson(Range r) {
    return r.lo == r.hi ? nlohmann::json(r.lo) : nlohmann::json::array({r.lo, r.hi});
}

int readBits(const JsonField& parent, int fallback) {
    auto f = parent.find("bit_depth");
    if (!f) return fallback;
    const int bits = f->integer();
    if (bits != 8 && bits != 16) f->fail("must be 8 or 16");
    return bits;
}

/// A file the spec names: a relative path that stays inside the spec's folder.
fs::path specFile(const JsonField& f, const fs::path& folder) {
    const std::string s = f.string();
    const std::string shown = std::string(1, '\'') + sim::displayName(s) + "'";
    const bool drive = s.size() >= 2 && std::isalpha(static_cast<unsigned char>(s[0])) && s[1] == ':';
    if (!s.empty() && (s.front() == '/' || drive || fs::path(s).is_absolute()))
        f.fail(shown + " is an absolute path (files are named relative to the spec's folder)");
    for (size_t start = 0; start <= s.size();) {
        const size_t end = std::min(s.find_first_of("/\\", start), s.size());
        if (s.compare(start, end - start, "..") == 0) f.fail(shown + " escapes the spec's folder ('..' component)");
        start = end + 1;
    }
    f.entryPath(); // the remaining rules of every file reference: portable characters, no '\', ...
    // A symbolic link inside the folder must not lead out of it either.
    std::error_code e1, e2;
    const fs::path base = fs::weakly_canonical(folder.empty() ? fs::path(".") : folder, e1);
    const fs::path full = fs::weakly_canonical(folder / s, e2);
    if (!e1 && !e2) {
        const fs::path rel = full.lexically_relative(base);
        if (rel.empty() || *rel.begin() == "..") f.fail(shown + " resolves outside the spec's folder (symbolic link)");
    }
    return folder / s;
}

template <class Read> auto readImageField(const JsonField& f, const fs::path& folder, const Read& read) {
    const fs::path file = specFile(f, folder);
    try {
        return read(file);
    } catch (const InputError& e) {
        f.fail(e.what());
    }
}

Tile readTile(const JsonField& f, const fs::path& folder) {
    f.anyObject();
    const std::string shape = f["shape"].choice({"disc", "gaussian", "bell", "image"}, "a tile shape");
    Tile t;
    if (shape == "gaussian") {
        f.object({"shape", "sigma"});
        t.shape = TileShape::Gaussian;
        t.sigma = f.number("sigma", 0.4, NumberRule::aboveUpTo(0, 4));
    } else if (shape == "image") {
        f.object({"shape", "file"});
        t.shape = TileShape::Image;
        t.image = readImageField(f["file"], folder, [](const fs::path& p) { return readGrayImage(p); });
        t.file = f["file"].string();
    } else {
        f.object({"shape"});
        t.shape = shape == "disc" ? TileShape::Disc : TileShape::Bell;
    }
    return t;
}

nlohmann::json tileJson(const Tile& t) {
    switch (t.shape) {
    case TileShape::Disc:
        return {{"shape", "disc"}};
    case TileShape::Gaussian:
        return {{"shape", "gaussian"}, {"sigma", t.sigma}};
    case TileShape::Bell:
        return {{"shape", "bell"}};
    case TileShape::Image:
        return {{"shape", "image"}, {"file", t.file}}; // the path as the spec wrote it
    }
    return {};
}

LevelPattern readPattern(const JsonField& f, int levels, const fs::path& folder) {
    f.object({"level", "tile", "rotation_deg", "offset", "scale", "opacity", "probability", "blend"});
    LevelPattern p;
    p.level = f["level"].integer(0, levels - 1);
    p.tile = readTile(f["tile"], folder);
    const NumberRule degrees = NumberRule::closed(-360, 360), scale = NumberRule::aboveUpTo(0, 4);
    p.rotationDeg = readRange(f, "rotation_deg", p.rotationDeg, degrees);
    if (auto o = f.find("offset")) {
        o->object({"radius", "angle_deg"});
        p.offsetRadius = readRange(*o, "radius", p.offsetRadius, NumberRule::closed(0, 2));
        p.offsetAngleDeg = readRange(*o, "angle_deg", p.offsetAngleDeg, degrees);
    }
    if (auto s = f.find("scale")) {
        if (s->has("uniform")) {
            s->object({"uniform"});
            p.uniformScale = true;
            p.width = readRange((*s)["uniform"], scale);
        } else {
            s->object({"width", "height"});
            p.width = readRange(*s, "width", p.width, scale);
            p.height = readRange(*s, "height", p.height, scale);
        }
    }
    p.opacity = readRange(f, "opacity", p.opacity, NumberRule::closed(0, 1));
    p.probability = f.number("probability", 1.0, NumberRule::closed(0, 1));
    if (auto b = f.find("blend")) {
        const std::string mode = b->choice({"add", "subtract", "max", "min", "multiply"}, "a blend mode");
        p.blend = mode == "add"        ? BlendMode::Add
                  : mode == "subtract" ? BlendMode::Subtract
                  : mode == "max"      ? BlendMode::Max
                  : mode == "min"      ? BlendMode::Min
                                       : BlendMode::Multiply;
    }
    return p;
}

const char* blendName(BlendMode mode) {
    switch (mode) {
    case BlendMode::Add:
        return "add";
    case BlendMode::Subtract:
        return "subtract";
    case BlendMode::Max:
        return "max";
    case BlendMode::Min:
        return "min";
    case BlendMode::Multiply:
        return "multiply";
    }
    return "";
}

nlohmann::json patternJson(const LevelPattern& p) {
    nlohmann::json f = {{"level", p.level},
                        {"tile", tileJson(p.tile)},
                        {"rotation_deg", rangeJson(p.rotationDeg)},
                        {"offset", {{"radius", rangeJson(p.offsetRadius)}, {"angle_deg", rangeJson(p.offsetAngleDeg)}}},
                        {"opacity", rangeJson(p.opacity)},
                        {"probability", p.probability},
                        {"blend", blendName(p.blend)}};
    f["scale"] = p.uniformScale ? nlohmann::json{{"uniform", rangeJson(p.width)}}
                                : nlohmann::json{{"width", rangeJson(p.width)}, {"height", rangeJson(p.height)}};
    return f;
}

/// A colour "#rrggbb".
Rgb8 readColor(const JsonField& c) {
    const std::optional<Rgb8> rgb = parseHexColor(c.string());
    if (!rgb) c.fail("'" + sim::displayName(c.string()) + "' is not a colour (#rrggbb)");
    return *rgb;
}

/// palette.reference: every rule of ReferenceSpec, so that generateReferenceImage() accepts it.
ReferenceSpec readReference(const JsonField& f) {
    f.object({"size", "seed", "colors", "shares", "noise", "blur_px"});
    ReferenceSpec r;
    if (auto size = f.find("size")) {
        r.size = size->integer(16, 4096);
        if (!std::has_single_bit(static_cast<unsigned>(r.size)))
            size->fail("must be a power of two (" + std::to_string(r.size) + " is not)");
    }
    r.seed = static_cast<uint64_t>(f.integer("seed", 0, 0, INT32_MAX));
    for (const JsonField& c : f["colors"].items(1, 16))
        r.colors.push_back(readColor(c));
    const JsonField shares = f["shares"];
    const std::vector<JsonField> items = shares.items();
    if (items.size() != r.colors.size())
        shares.fail("must have one share per colour (" + std::to_string(r.colors.size()) + " colours, " +
                    std::to_string(items.size()) + " shares)");
    double sum = 0;
    for (const JsonField& share : items)
        sum += r.shares.emplace_back(share.number(NumberRule::aboveUpTo(0, 1)));
    if (!(std::abs(sum - 1) <= 1e-6)) shares.fail("must sum to 1 within 1e-6 (sum " + formatNumber(sum, 9) + ")");
    r.noise = f.number("noise", r.noise, NumberRule::closed(0, 64));
    r.blurPx = f.number("blur_px", r.blurPx, NumberRule::closed(0, 16));
    return r;
}

nlohmann::json colorsJson(const std::vector<Rgb8>& colors) {
    nlohmann::json list = nlohmann::json::array();
    for (Rgb8 c : colors)
        list.push_back(hexColor(c));
    return list;
}

nlohmann::json referenceJson(const ReferenceSpec& r) {
    return {{"size", r.size},     {"seed", r.seed},   {"colors", colorsJson(r.colors)},
            {"shares", r.shares}, {"noise", r.noise}, {"blur_px", r.blurPx}};
}

PaletteSpec readPalette(const JsonField& f, const fs::path& folder, uint64_t seed) {
    f.anyObject();
    PaletteSpec p;
    std::vector<std::string> sources;
    for (const char* key : {"colors", "image", "reference"})
        if (f.has(key)) sources.push_back(std::string(1, '\'') + key + "'");
    if (sources.size() > 1)
        f.fail("takes one of 'colors', 'image' and 'reference' (found " + sources[0] + " and " + sources[1] + ")");
    if (f.has("colors")) {
        f.object({"colors"});
        for (const JsonField& c : f["colors"].items(1, 256))
            p.colors.push_back(readColor(c));
        return p;
    }
    if (sources.empty())
        f.fail("needs 'colors' (a list of #rrggbb), 'image' (a reference image) or 'reference' (a synthetic "
               "reference photograph)");
    const char* source = f.has("image") ? "image" : "reference";
    const std::string method =
        f.has("method") ? f["method"].choice({"threshold", "kmeans"}, "a palette method") : "threshold";
    if (method == "threshold")
        f.object({source, "method", "threshold", "prominent_threshold", "max_colors"});
    else
        f.object({source, "method", "k", "iterations", "prominent_threshold", "max_colors"});
    // Every number is checked before the image is read.
    const NumberRule threshold = NumberRule::aboveUpTo(0, 256);
    p.params.method = method == "threshold" ? PaletteMethod::Threshold : PaletteMethod::KMeans;
    p.params.threshold = f.number("threshold", p.params.threshold, threshold);
    p.params.k = f.integer("k", p.params.k, 1, 64);
    p.params.maxIterations = f.integer("iterations", p.params.maxIterations, 1, 1000);
    p.params.maxColors = f.integer("max_colors", p.params.maxColors, 1, 256);
    p.params.seed = seed;
    const bool byThreshold = p.params.method == PaletteMethod::Threshold;
    p.prominentThreshold =
        f.number("prominent_threshold", byThreshold ? std::max(64.0, p.params.threshold) : 64.0, threshold);
    if (byThreshold && p.prominentThreshold < p.params.threshold)
        f.failAt("prominent_threshold", "must be at least the threshold (" + formatNumber(p.params.threshold) + ")");
    if (f.has("reference")) {
        p.reference = readReference(f["reference"]);
        return p;
    }
    p.imageFile = f["image"].string();
    p.image = readImageField(f["image"], folder, [](const fs::path& file) { return readRgb8Image(file); });
    return p;
}

/// Explicit colours alone; else the source and the parameters its method reads (the seed is the
/// quadtree's: not written).
nlohmann::json paletteJson(const PaletteSpec& p) {
    if (!p.colors.empty()) return {{"colors", colorsJson(p.colors)}};
    nlohmann::json f;
    if (p.reference)
        f["reference"] = referenceJson(*p.reference);
    else
        f["image"] = p.imageFile;
    if (p.params.method == PaletteMethod::Threshold) {
        f["method"] = "threshold";
        f["threshold"] = p.params.threshold;
    } else {
        f["method"] = "kmeans";
        f["k"] = p.params.k;
        f["iterations"] = p.params.maxIterations;
    }
    f["max_colors"] = p.params.maxColors;
    f["prominent_threshold"] = p.prominentThreshold;
    return f;
}

MaskMapping readValues(const JsonField& map, MaskMapping fallback) {
    auto v = map.find("values");
    if (!v) return fallback;
    const std::vector<JsonField> e = v->items(2, 2);
    return {e[0].number(NumberRule::closed(0, 1)), e[1].number(NumberRule::closed(0, 1))};
}

nlohmann::json valuesJson(MaskMapping m) {
    return nlohmann::json::array({m.atZero, m.atOne});
}

/// maps.diffuse's gradient: palette indices and optional stops (one per index, non-decreasing).
void readDiffuse(const JsonField& f, std::vector<int>& indices, std::vector<double>& stops) {
    if (auto c = f.find("colors"))
        for (const JsonField& i : c->items(1, 256))
            indices.push_back(i.integer(0, 255));
    if (auto s = f.find("stops")) {
        if (indices.empty()) s->fail("needs 'colors' (one stop per colour)");
        const std::vector<JsonField> items = s->items(indices.size(), indices.size());
        for (size_t i = 0; i < items.size(); ++i) {
            stops.push_back(items[i].number(NumberRule::closed(0, 1)));
            if (i > 0 && stops[i] < stops[i - 1])
                items[i].fail("must not be below the stop before it (" + formatNumber(stops[i - 1]) + ")");
        }
    }
}

/// "colors" and "stops" into the diffuse map's object `f` when there are any.
void writeDiffuse(const std::vector<int>& indices, const std::vector<double>& stops, nlohmann::json& f) {
    if (!indices.empty()) f["colors"] = indices;
    if (!stops.empty()) f["stops"] = stops;
}

/// Explicit palette colours must cover the diffuse indices.
void checkIndices(const JsonField& diffuse, const std::optional<PaletteSpec>& palette,
                  const std::vector<int>& indices) {
    if (!palette || palette->colors.empty() || indices.empty()) return;
    const std::vector<JsonField> items = diffuse["colors"].items();
    const size_t n = palette->colors.size();
    for (size_t i = 0; i < items.size(); ++i)
        if (indices[i] >= static_cast<int>(n))
            items[i].fail("palette index " + std::to_string(indices[i]) + " is out of range (the palette has " +
                          std::to_string(n) + " colours)");
}

void readMaps(const JsonField& m, int bits, TextureSpec& spec) {
    m.object({"mask", "diffuse", "roughness", "metallic", "height", "normal", "palette", "prominent", "reference"});
    if (m.value().empty()) m.fail("must name at least one map");
    MaterialParams& mat = spec.material;
    for (MapKind kind : {MapKind::Mask, MapKind::Diffuse, MapKind::Roughness, MapKind::Metallic, MapKind::Height,
                         MapKind::Normal, MapKind::Palette, MapKind::Prominent, MapKind::Reference}) {
        auto f = m.find(mapName(kind));
        if (!f) continue;
        switch (kind) {
        case MapKind::Mask:
            f->object({"bit_depth"});
            break;
        case MapKind::Diffuse:
            f->object({"colors", "stops", "bit_depth"});
            readDiffuse(*f, spec.diffuseIndices, mat.diffuseStops);
            break;
        case MapKind::Roughness:
        case MapKind::Metallic:
            f->object({"values", "bit_depth"});
            (kind == MapKind::Roughness ? mat.roughness : mat.metallic) =
                readValues(*f, kind == MapKind::Roughness ? mat.roughness : mat.metallic);
            break;
        case MapKind::Height:
            f->object({"values", "blur_px", "bit_depth"});
            mat.height = readValues(*f, mat.height);
            mat.heightBlurPx = f->number("blur_px", mat.heightBlurPx, NumberRule::closed(0, 64));
            break;
        case MapKind::Normal:
            f->object({"depth", "bit_depth"});
            mat.normalDepth = f->number("depth", mat.normalDepth, NumberRule::aboveUpTo(0, 1));
            break;
        case MapKind::Palette:
            f->object({"swatch_px"});
            spec.swatchPx = f->integer("swatch_px", spec.swatchPx, 1, 512);
            break;
        case MapKind::Prominent:
            f->object({"width", "height"});
            spec.prominentWidth = f->integer("width", spec.prominentWidth, 1, 4096);
            spec.prominentHeight = f->integer("height", spec.prominentHeight, 1, 4096);
            break;
        case MapKind::Reference:
            f->object({});
            break;
        }
        spec.maps.push_back({kind, readBits(*f, bits)});
    }
}

/// maps: one object per request. The palette, prominent and reference maps have no bit_depth
/// of their own (they take the spec's, specBits); the others write theirs.
nlohmann::json mapsJson(const TextureSpec& spec) {
    const MaterialParams& mat = spec.material;
    nlohmann::json m = nlohmann::json::object();
    for (const MapRequest& r : spec.maps) {
        nlohmann::json f = nlohmann::json::object();
        switch (r.kind) {
        case MapKind::Mask:
            break;
        case MapKind::Diffuse:
            writeDiffuse(spec.diffuseIndices, mat.diffuseStops, f);
            break;
        case MapKind::Roughness:
        case MapKind::Metallic:
            f["values"] = valuesJson(r.kind == MapKind::Roughness ? mat.roughness : mat.metallic);
            break;
        case MapKind::Height:
            f["values"] = valuesJson(mat.height);
            f["blur_px"] = mat.heightBlurPx;
            break;
        case MapKind::Normal:
            f["depth"] = mat.normalDepth;
            break;
        case MapKind::Palette:
            f["swatch_px"] = spec.swatchPx;
            break;
        case MapKind::Prominent:
            f["width"] = spec.prominentWidth;
            f["height"] = spec.prominentHeight;
            break;
        case MapKind::Reference:
            break;
        }
        if (r.kind != MapKind::Palette && r.kind != MapKind::Prominent && r.kind != MapKind::Reference)
            f["bit_depth"] = r.bits;
        m[std::string(mapName(r.kind))] = std::move(f);
    }
    return m;
}

/// The spec's bit_depth: that of its palette, prominent or reference map (which have no
/// bit_depth of their own), else 8.
int specBits(const TextureSpec& spec) {
    for (const MapRequest& r : spec.maps)
        if (r.kind == MapKind::Palette || r.kind == MapKind::Prominent || r.kind == MapKind::Reference) return r.bits;
    return 8;
}

bool wants(const std::vector<MapRequest>& maps, MapKind kind) {
    for (const MapRequest& r : maps)
        if (r.kind == kind) return true;
    return false;
}
bool wants(const TextureSpec& spec, MapKind kind) {
    return wants(spec.maps, kind);
}

/// The quadtree fields shared by the spec's root and its layers: levels, base, patterns.
void readQuadtree(const JsonField& f, QuadtreeParams& q, const fs::path& dir) {
    q.levels = f["levels"].integer(1, std::countr_zero(static_cast<unsigned>(q.size)) + 1);
    q.base = f.number("base", 0.0, NumberRule::closed(0, 1));
    const std::vector<JsonField> patterns = f["patterns"].items(1, static_cast<size_t>(q.levels));
    for (size_t i = 0; i < patterns.size(); ++i) {
        q.patterns.push_back(readPattern(patterns[i], q.levels, dir));
        for (size_t j = 0; j < i; ++j)
            if (q.patterns[j].level == q.patterns[i].level)
                patterns[i]["level"].fail("level " + std::to_string(q.patterns[i].level) + " already has a pattern (" +
                                          patterns[j].path() + ")");
    }
}

void writeQuadtree(const QuadtreeParams& q, nlohmann::json& f) {
    f["levels"] = q.levels;
    f["base"] = q.base;
    nlohmann::json patterns = nlohmann::json::array();
    for (const LevelPattern& p : q.patterns)
        patterns.push_back(patternJson(p));
    f["patterns"] = std::move(patterns);
}

/// A file-name part: "A-Z a-z 0-9 . _ -", no '/'.
std::string readFileName(const JsonField& n) {
    std::string name = n.nonEmptyString();
    if (name.find('/') != std::string::npos || sim::entryNameProblem(name))
        n.fail("'" + sim::displayName(name) + "' is not a file name (A-Z a-z 0-9 . _ -)");
    return name;
}

/// layers[i]: see LayerSpec. A layer paints only channels the base makes (height: when the base
/// makes a height or normal map), with its own palette or the base's.
LayerSpec readLayer(const JsonField& f, const TextureSpec& spec, size_t index, int bits, const fs::path& dir) {
    f.object({"name", "seed", "levels", "base", "patterns", "palette", "opacity", "maps"});
    LayerSpec layer;
    layer.name = readFileName(f["name"]);
    layer.quadtree.size = spec.quadtree.size;
    layer.quadtree.tileable = spec.quadtree.tileable;
    layer.quadtree.seed =
        f.has("seed") ? static_cast<uint64_t>(f["seed"].integer(0, INT32_MAX)) : spec.quadtree.seed + 1 + index;
    readQuadtree(f, layer.quadtree, dir);
    layer.opacity = f.number("opacity", 1.0, NumberRule::closed(0, 1));
    layer.material.tileable = spec.quadtree.tileable; // the composite height is blurred once, not per layer
    const JsonField m = f["maps"];
    m.object({"mask", "diffuse", "roughness", "metallic", "height"});
    if (m.value().empty()) m.fail("must name at least one map");
    const bool baseHeight = wants(spec, MapKind::Height) || wants(spec, MapKind::Normal);
    for (MapKind kind : {MapKind::Mask, MapKind::Diffuse, MapKind::Roughness, MapKind::Metallic, MapKind::Height}) {
        auto c = m.find(mapName(kind));
        if (!c) continue;
        const std::string name(mapName(kind));
        if (kind == MapKind::Mask) {
            c->object({"bit_depth"});
            layer.files.push_back({kind, readBits(*c, bits)});
            continue;
        }
        if (kind == MapKind::Diffuse) {
            c->object({"colors", "stops", "write", "bit_depth"});
            readDiffuse(*c, layer.diffuseIndices, layer.material.diffuseStops);
        } else {
            c->object({"values", "write", "bit_depth"});
            MaskMapping& v = kind == MapKind::Roughness  ? layer.material.roughness
                             : kind == MapKind::Metallic ? layer.material.metallic
                                                         : layer.material.height;
            v = readValues(*c, v);
        }
        if (kind == MapKind::Height ? !baseHeight : !wants(spec, kind))
            c->fail("the base material makes no " + name + " map to composite over (add maps." +
                    (kind == MapKind::Height ? std::string("height or maps.normal") : name) + ")");
        (kind == MapKind::Diffuse     ? layer.paints.diffuse
         : kind == MapKind::Roughness ? layer.paints.roughness
         : kind == MapKind::Metallic  ? layer.paints.metallic
                                      : layer.paints.height) = true;
        if (c->boolean("write", false)) layer.files.push_back({kind, readBits(*c, bits)});
    }
    if (auto p = f.find("palette")) layer.palette = readPalette(*p, dir, layer.quadtree.seed);
    if (layer.paints.diffuse) {
        if (!layer.palette && !spec.palette)
            m.failAt("diffuse", "needs a palette (layers[" + std::to_string(index) + "].palette or the base's)");
        checkIndices(m["diffuse"], layer.palette ? layer.palette : spec.palette, layer.diffuseIndices);
    }
    return layer;
}

/// layers[index]; the seed only when it is not the default (the base's + 1 + index), which may
/// lie beyond the range an explicit seed has.
nlohmann::json layerJson(const LayerSpec& layer, const TextureSpec& spec, size_t index) {
    nlohmann::json f = {{"name", layer.name}, {"opacity", layer.opacity}};
    if (layer.quadtree.seed != spec.quadtree.seed + 1 + index) f["seed"] = layer.quadtree.seed;
    writeQuadtree(layer.quadtree, f);
    if (layer.palette) f["palette"] = paletteJson(*layer.palette);
    auto writes = [&](MapKind kind) -> const MapRequest* {
        for (const MapRequest& r : layer.files)
            if (r.kind == kind) return &r;
        return nullptr;
    };
    nlohmann::json m = nlohmann::json::object();
    if (const MapRequest* r = writes(MapKind::Mask)) m["mask"] = {{"bit_depth", r->bits}};
    const MapSelection& paints = layer.paints;
    for (MapKind kind : {MapKind::Diffuse, MapKind::Roughness, MapKind::Metallic, MapKind::Height}) {
        const bool painted = kind == MapKind::Diffuse     ? paints.diffuse
                             : kind == MapKind::Roughness ? paints.roughness
                             : kind == MapKind::Metallic  ? paints.metallic
                                                          : paints.height;
        if (!painted) continue;
        nlohmann::json c = nlohmann::json::object();
        if (kind == MapKind::Diffuse)
            writeDiffuse(layer.diffuseIndices, layer.material.diffuseStops, c);
        else
            c["values"] = valuesJson(kind == MapKind::Roughness  ? layer.material.roughness
                                     : kind == MapKind::Metallic ? layer.material.metallic
                                                                 : layer.material.height);
        const MapRequest* r = writes(kind);
        c["write"] = r != nullptr;
        if (r) c["bit_depth"] = r->bits;
        m[std::string(mapName(kind))] = std::move(c);
    }
    f["maps"] = std::move(m);
    return f;
}

std::string defaultName(const std::string& origin) {
    const std::string stem = fs::path(origin).stem().string();
    return !stem.empty() && !sim::entryNameProblem(stem) ? stem : "texture";
}

nlohmann::json colorList(const std::vector<PaletteColor>& colors) {
    nlohmann::json list = nlohmann::json::array();
    for (const PaletteColor& c : colors)
        list.push_back({{"color", hexColor(c.color)}, {"share", c.share}, {"pixels", c.pixels}});
    return list;
}

} // namespace

std::string_view mapName(MapKind kind) {
    static constexpr std::string_view kNames[] = {"mask",   "diffuse", "roughness", "metallic", "height",
                                                  "normal", "palette", "prominent", "reference"};
    return kNames[static_cast<size_t>(kind)];
}

TextureSpec parseTextureSpec(std::string_view text, const std::string& origin, const fs::path& folder) {
    const nlohmann::json doc = sim::parseJsonText(text, origin);
    const JsonField root(doc, "", origin);
    root.object(
        {"name", "size", "seed", "levels", "tileable", "base", "patterns", "palette", "maps", "bit_depth", "layers"});
    TextureSpec spec;
    spec.origin = origin;
    spec.name = defaultName(origin);
    if (auto n = root.find("name")) spec.name = readFileName(*n);
    QuadtreeParams& q = spec.quadtree;
    const JsonField size = root["size"];
    q.size = size.integer(8, 4096);
    if (!std::has_single_bit(static_cast<unsigned>(q.size)))
        size.fail("must be a power of two (" + std::to_string(q.size) + " is not)");
    q.seed = static_cast<uint64_t>(root["seed"].integer(0, INT32_MAX));
    q.tileable = root.boolean("tileable", true);
    const int bits = readBits(root, 8);
    const fs::path dir = folder.empty() ? fs::path(".") : folder;
    readQuadtree(root, q, dir);
    spec.material.tileable = q.tileable;
    readMaps(root["maps"], bits, spec);
    if (auto p = root.find("palette")) spec.palette = readPalette(*p, dir, q.seed);
    for (MapKind kind : {MapKind::Diffuse, MapKind::Palette})
        if (wants(spec, kind) && !spec.palette)
            root.failAt("palette", "required field is missing (maps." + std::string(mapName(kind)) + " uses it)");
    if (wants(spec, MapKind::Prominent) && (!spec.palette || !spec.palette->colors.empty()))
        root.failAt("maps.prominent", "needs a reference image (palette.image or palette.reference)");
    if (wants(spec, MapKind::Reference) && (!spec.palette || !spec.palette->reference))
        root.failAt("maps.reference", "needs a synthetic reference photograph (palette.reference)");
    if (wants(spec, MapKind::Diffuse)) checkIndices(root["maps"]["diffuse"], spec.palette, spec.diffuseIndices);
    if (auto l = root.find("layers")) {
        const std::vector<JsonField> layers = l->items(1, 8);
        for (size_t i = 0; i < layers.size(); ++i) {
            spec.layers.push_back(readLayer(layers[i], spec, i, bits, dir));
            for (size_t j = 0; j < i; ++j)
                if (spec.layers[j].name == spec.layers[i].name)
                    layers[i]["name"].fail("'" + spec.layers[i].name + "' already names " + layers[j].path());
        }
    }
    return spec;
}

std::string textureSpecText(const TextureSpec& spec) {
    nlohmann::json root = {{"name", spec.name},
                           {"size", spec.quadtree.size},
                           {"seed", spec.quadtree.seed},
                           {"tileable", spec.quadtree.tileable},
                           {"bit_depth", specBits(spec)}};
    writeQuadtree(spec.quadtree, root);
    if (spec.palette) root["palette"] = paletteJson(*spec.palette);
    root["maps"] = mapsJson(spec);
    if (!spec.layers.empty()) {
        nlohmann::json layers = nlohmann::json::array();
        for (size_t i = 0; i < spec.layers.size(); ++i)
            layers.push_back(layerJson(spec.layers[i], spec, i));
        root["layers"] = std::move(layers);
    }
    return root.dump(2) + "\n";
}

std::vector<std::string> specInputFiles(const TextureSpec& spec) {
    std::vector<std::string> files;
    auto add = [&files](const std::string& f) {
        if (!f.empty() && std::find(files.begin(), files.end(), f) == files.end()) files.push_back(f);
    };
    auto addLayer = [&add](const std::optional<PaletteSpec>& palette, const QuadtreeParams& q) {
        if (palette) add(palette->imageFile);
        for (const LevelPattern& lp : q.patterns)
            if (lp.tile.shape == TileShape::Image) add(lp.tile.file);
    };
    addLayer(spec.palette, spec.quadtree);
    for (const LayerSpec& l : spec.layers)
        addLayer(l.palette, l.quadtree);
    return files;
}

TextureSpec loadTextureSpec(const fs::path& file) {
    return parseTextureSpec(readFile(file, std::uintmax_t{1} << 20), file.string(), file.parent_path());
}

namespace {

/// The palette's colours: explicit, or extracted from its image or synthetic reference (made into
/// `reference`); `extracted` and `prominent` receive the extraction's groups when given.
std::vector<Rgb8> paletteColors(const PaletteSpec& p, Rgb8Image& reference, std::vector<PaletteColor>* extracted,
                                std::vector<PaletteColor>* prominent) {
    if (!p.colors.empty()) return p.colors;
    if (p.reference) reference = generateReferenceImage(*p.reference);
    const Rgb8Image& image = p.reference ? reference : p.image;
    std::vector<PaletteColor> groups = extractPalette(image, p.params);
    std::vector<Rgb8> colors;
    for (const PaletteColor& c : groups)
        colors.push_back(c.color);
    if (prominent) {
        PaletteParams params = p.params;
        params.method = PaletteMethod::Threshold;
        params.threshold = p.prominentThreshold;
        params.maxColors = 256;
        *prominent = extractPalette(image, params);
    }
    if (extracted) *extracted = std::move(groups);
    return colors;
}

/// The diffuse gradient's colours: the palette's at `indices` (all of them when empty).
std::vector<Rgb8> gradientColors(const std::vector<Rgb8>& palette, const std::vector<int>& indices,
                                 const PaletteSpec& source, const std::string& where) {
    if (indices.empty()) return palette;
    std::vector<Rgb8> colors;
    for (size_t i = 0; i < indices.size(); ++i) {
        const int index = indices[i];
        if (index >= static_cast<int>(palette.size()))
            throw InputError(where + ".colors[" + std::to_string(i) + "]: palette index " + std::to_string(index) +
                             " is out of range (the palette of " +
                             (source.reference ? std::string("the synthetic reference")
                                               : "'" + sim::displayName(source.imageFile) + "'") +
                             " has " + std::to_string(palette.size()) + " colours)");
        colors.push_back(palette[static_cast<size_t>(index)]);
    }
    return colors;
}

} // namespace

TextureSet generateTextureSet(const TextureSpec& spec) {
    TextureSet set;
    set.mask = generateMask(spec.quadtree);
    if (spec.palette)
        set.colors =
            paletteColors(*spec.palette, set.reference, &set.palette,
                          wants(spec, MapKind::Prominent) || wants(spec, MapKind::Palette) ? &set.prominent : nullptr);
    MaterialParams material = spec.material;
    const MapSelection which{wants(spec, MapKind::Diffuse), wants(spec, MapKind::Roughness),
                             wants(spec, MapKind::Metallic), wants(spec, MapKind::Height),
                             wants(spec, MapKind::Normal)};
    if (which.diffuse)
        material.diffuseColors =
            gradientColors(set.colors, spec.diffuseIndices, *spec.palette, spec.origin + ": maps.diffuse");
    if (spec.layers.empty()) {
        if (which.diffuse || which.roughness || which.metallic || which.height || which.normal)
            set.maps = generateMaps(set.mask, material, which);
        return set;
    }
    // Layers composite over the unblurred base height; the blur and the normals come last.
    MapSelection base = which;
    base.height = which.height || which.normal;
    base.normal = false;
    material.heightBlurPx = 0;
    set.maps = generateMaps(set.mask, material, base);
    for (size_t i = 0; i < spec.layers.size(); ++i) {
        const LayerSpec& l = spec.layers[i];
        LayerSet& out = set.layers.emplace_back();
        const GrayImage mask = generateMask(l.quadtree);
        out.coverage = mask;
        for (float& a : out.coverage.pixels)
            a = static_cast<float>(l.opacity * a);
        MapSelection own = l.paints;
        for (const MapRequest& r : l.files)
            (r.kind == MapKind::Diffuse     ? own.diffuse
             : r.kind == MapKind::Roughness ? own.roughness
             : r.kind == MapKind::Metallic  ? own.metallic
             : r.kind == MapKind::Height    ? own.height
                                            : own.normal) = true;
        own.normal = false;
        MaterialParams lm = l.material;
        if (own.diffuse) {
            Rgb8Image reference;
            out.colors = l.palette ? paletteColors(*l.palette, reference, nullptr, nullptr) : set.colors;
            lm.diffuseColors = gradientColors(out.colors, l.diffuseIndices, l.palette ? *l.palette : *spec.palette,
                                              spec.origin + ": layers[" + std::to_string(i) + "].maps.diffuse");
        }
        if (own.diffuse || own.roughness || own.metallic || own.height) out.maps = generateMaps(mask, lm, own);
        compositeLayer(set.maps, out.maps, out.coverage, l.paints);
    }
    if (base.height) {
        GrayImage height = blurGaussian(set.maps.height, spec.material.heightBlurPx, spec.material.tileable);
        if (which.normal)
            set.maps.normal = normalsFromHeight(height, spec.material.normalDepth, spec.material.tileable);
        set.maps.height = which.height ? std::move(height) : GrayImage{};
    }
    return set;
}

namespace {

/// The file(s) of one map request.
std::vector<EncodedFile> encodeMap(const TextureSpec& spec, const TextureSet& set, const MapRequest& r) {
    std::vector<EncodedFile> files;
    auto add = [&](std::string_view suffix, std::string bytes) {
        files.push_back({spec.name + "_" + std::string(suffix), std::move(bytes)});
    };
    const std::string png = std::string(mapName(r.kind)) + ".png";
    const GrayImage* gray = r.kind == MapKind::Mask        ? &set.mask
                            : r.kind == MapKind::Roughness ? &set.maps.roughness
                            : r.kind == MapKind::Metallic  ? &set.maps.metallic
                            : r.kind == MapKind::Height    ? &set.maps.height
                                                           : nullptr;
    switch (r.kind) {
    case MapKind::Mask:
    case MapKind::Roughness:
    case MapKind::Metallic:
    case MapKind::Height:
        add(png, encodePng(*gray, r.bits));
        break;
    case MapKind::Diffuse:
        add(png, encodePng(set.maps.diffuse, r.bits));
        break;
    case MapKind::Normal:
        add(png, encodeNormalPng(set.maps.normal, r.bits));
        break;
    case MapKind::Palette: {
        add(png, encodePng(paletteSwatches(set.colors, spec.swatchPx)));
        nlohmann::json j;
        const PaletteSpec& p = *spec.palette;
        j["source"] = p.reference           ? nlohmann::json("reference")
                      : p.imageFile.empty() ? nlohmann::json("colors")
                                            : nlohmann::json(p.imageFile);
        if (p.reference) j["reference"] = referenceJson(*p.reference);
        j["colors"] = colorsJson(set.colors);
        j["palette"] = colorList(set.palette);
        j["prominent"] = colorList(set.prominent);
        add("palette.json", j.dump(2) + "\n");
        break;
    }
    case MapKind::Prominent:
        add(png, encodePng(proportionalMap(set.prominent, spec.prominentWidth, spec.prominentHeight)));
        break;
    case MapKind::Reference:
        add(png, encodePng(set.reference));
        break;
    }
    return files;
}

/// A layer's own map: <name>_<layer>_<map>.png.
EncodedFile encodeLayerMap(const TextureSpec& spec, const TextureSet& set, size_t layer, const MapRequest& r) {
    const LayerSet& l = set.layers[layer];
    EncodedFile f{spec.name + "_" + spec.layers[layer].name + "_" + std::string(mapName(r.kind)) + ".png", {}};
    f.bytes = r.kind == MapKind::Diffuse ? encodePng(l.maps.diffuse, r.bits)
                                         : encodePng(r.kind == MapKind::Mask        ? l.coverage
                                                     : r.kind == MapKind::Roughness ? l.maps.roughness
                                                     : r.kind == MapKind::Metallic  ? l.maps.metallic
                                                                                    : l.maps.height,
                                                     r.bits);
    return f;
}

} // namespace

std::vector<EncodedFile> encodeTextureSet(const TextureSpec& spec, const TextureSet& set) {
    // The maps encode concurrently (zlib dominates); the files keep the order of spec.maps, then
    // each layer's in its order.
    std::vector<std::future<std::vector<EncodedFile>>> jobs;
    for (const MapRequest& r : spec.maps)
        jobs.push_back(std::async(std::launch::async, [&spec, &set, r] { return encodeMap(spec, set, r); }));
    for (size_t i = 0; i < spec.layers.size() && i < set.layers.size(); ++i)
        for (const MapRequest& r : spec.layers[i].files)
            jobs.push_back(std::async(std::launch::async, [&spec, &set, i, r] {
                return std::vector<EncodedFile>{encodeLayerMap(spec, set, i, r)};
            }));
    std::vector<EncodedFile> files;
    for (auto& job : jobs)
        for (EncodedFile& f : job.get())
            files.push_back(std::move(f));
    return files;
}

BakeTextureResult bakeTexture(const TextureSpec& spec, const fs::path& outDir) {
    using Clock = std::chrono::steady_clock;
    auto seconds = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double>(b - a).count();
    };
    requireWritableFolder(outDir);
    BakeTextureResult r;
    const auto t0 = Clock::now();
    r.set = generateTextureSet(spec);
    const auto t1 = Clock::now();
    const std::vector<EncodedFile> files = encodeTextureSet(spec, r.set);
    const auto t2 = Clock::now();
    for (const EncodedFile& f : files) {
        writeFileAtomic(outDir / f.fileName, f.bytes);
        r.files.push_back({outDir / f.fileName, f.bytes.size()});
    }
    const auto t3 = Clock::now();
    r.generateSeconds = seconds(t0, t1);
    r.encodeSeconds = seconds(t1, t2);
    r.writeSeconds = seconds(t2, t3);
    return r;
}

} // namespace viscera::bake
