// The texture spec (JSON, read through sim::JsonField) and the bake of its files.
#include "bake/texture.hpp"

#include <algorithm>

#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
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

MaskMapping readValues(const JsonField& map, MaskMapping fallback) {
    auto v = map.find("values");
    if (!v) return fallback;
    const std::vector<JsonField> e = v->items(2, 2);
    return {e[0].number(NumberRule::closed(0, 1)), e[1].number(NumberRule::closed(0, 1))};
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
            if (auto c = f->find("colors"))
                for (const JsonField& i : c->items(1, 256))
                    spec.diffuseIndices.push_back(i.integer(0, 255));
            if (auto s = f->find("stops")) {
                if (spec.diffuseIndices.empty()) s->fail("needs 'colors' (one stop per colour)");
                const std::vector<JsonField> stops = s->items(spec.diffuseIndices.size(), spec.diffuseIndices.size());
                for (size_t i = 0; i < stops.size(); ++i) {
                    mat.diffuseStops.push_back(stops[i].number(NumberRule::closed(0, 1)));
                    if (i > 0 && mat.diffuseStops[i] < mat.diffuseStops[i - 1])
                        stops[i].fail("must not be below the stop before it (" + formatNumber(mat.diffuseStops[i - 1]) +
                                      ")");
                }
            }
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

bool wants(const TextureSpec& spec, MapKind kind) {
    for (const MapRequest& r : spec.maps)
        if (r.kind == kind) return true;
    return false;
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
    root.object({"name", "size", "seed", "levels", "tileable", "base", "patterns", "palette", "maps", "bit_depth"});
    TextureSpec spec;
    spec.origin = origin;
    spec.name = defaultName(origin);
    if (auto n = root.find("name")) {
        spec.name = n->nonEmptyString();
        if (spec.name.find('/') != std::string::npos || sim::entryNameProblem(spec.name))
            n->fail("'" + sim::displayName(spec.name) + "' is not a file name (A-Z a-z 0-9 . _ -)");
    }
    QuadtreeParams& q = spec.quadtree;
    const JsonField size = root["size"];
    q.size = size.integer(8, 4096);
    if (!std::has_single_bit(static_cast<unsigned>(q.size)))
        size.fail("must be a power of two (" + std::to_string(q.size) + " is not)");
    q.seed = static_cast<uint64_t>(root["seed"].integer(0, INT32_MAX));
    q.levels = root["levels"].integer(1, std::countr_zero(static_cast<unsigned>(q.size)) + 1);
    q.tileable = root.boolean("tileable", true);
    q.base = root.number("base", 0.0, NumberRule::closed(0, 1));
    const int bits = readBits(root, 8);
    const fs::path dir = folder.empty() ? fs::path(".") : folder;
    const std::vector<JsonField> patterns = root["patterns"].items(1, static_cast<size_t>(q.levels));
    for (size_t i = 0; i < patterns.size(); ++i) {
        q.patterns.push_back(readPattern(patterns[i], q.levels, dir));
        for (size_t j = 0; j < i; ++j)
            if (q.patterns[j].level == q.patterns[i].level)
                patterns[i]["level"].fail("level " + std::to_string(q.patterns[i].level) + " already has a pattern (" +
                                          patterns[j].path() + ")");
    }
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
    if (spec.palette && !spec.palette->colors.empty() && !spec.diffuseIndices.empty()) {
        const std::vector<JsonField> indices = root["maps"]["diffuse"]["colors"].items();
        const size_t n = spec.palette->colors.size();
        for (size_t i = 0; i < indices.size(); ++i)
            if (spec.diffuseIndices[i] >= static_cast<int>(n))
                indices[i].fail("palette index " + std::to_string(spec.diffuseIndices[i]) +
                                " is out of range (the palette has " + std::to_string(n) + " colours)");
    }
    return spec;
}

std::vector<std::string> specInputFiles(const TextureSpec& spec) {
    std::vector<std::string> files;
    auto add = [&files](const std::string& f) {
        if (!f.empty() && std::find(files.begin(), files.end(), f) == files.end()) files.push_back(f);
    };
    if (spec.palette) add(spec.palette->imageFile);
    for (const LevelPattern& lp : spec.quadtree.patterns)
        if (lp.tile.shape == TileShape::Image) add(lp.tile.file);
    return files;
}

TextureSpec loadTextureSpec(const fs::path& file) {
    return parseTextureSpec(readFile(file, std::uintmax_t{1} << 20), file.string(), file.parent_path());
}

TextureSet generateTextureSet(const TextureSpec& spec) {
    TextureSet set;
    set.mask = generateMask(spec.quadtree);
    if (spec.palette) {
        const PaletteSpec& p = *spec.palette;
        if (p.reference) set.reference = generateReferenceImage(*p.reference);
        const Rgb8Image& image = p.reference ? set.reference : p.image;
        if (p.colors.empty()) {
            set.palette = extractPalette(image, p.params);
            for (const PaletteColor& c : set.palette)
                set.colors.push_back(c.color);
            if (wants(spec, MapKind::Prominent) || wants(spec, MapKind::Palette)) {
                PaletteParams prominent = p.params;
                prominent.method = PaletteMethod::Threshold;
                prominent.threshold = p.prominentThreshold;
                prominent.maxColors = 256;
                set.prominent = extractPalette(image, prominent);
            }
        } else {
            set.colors = p.colors;
        }
    }
    MaterialParams material = spec.material;
    MapSelection which{wants(spec, MapKind::Diffuse), wants(spec, MapKind::Roughness), wants(spec, MapKind::Metallic),
                       wants(spec, MapKind::Height), wants(spec, MapKind::Normal)};
    if (which.diffuse) {
        if (spec.diffuseIndices.empty()) material.diffuseColors = set.colors;
        for (size_t i = 0; i < spec.diffuseIndices.size(); ++i) {
            const int index = spec.diffuseIndices[i];
            if (index >= static_cast<int>(set.colors.size()))
                throw InputError(spec.origin + ": maps.diffuse.colors[" + std::to_string(i) + "]: palette index " +
                                 std::to_string(index) + " is out of range (the palette of " +
                                 (spec.palette->reference ? std::string("the synthetic reference")
                                                          : "'" + sim::displayName(spec.palette->imageFile) + "'") +
                                 " has " + std::to_string(set.colors.size()) + " colours)");
            material.diffuseColors.push_back(set.colors[static_cast<size_t>(index)]);
        }
    }
    if (which.diffuse || which.roughness || which.metallic || which.height || which.normal)
        set.maps = generateMaps(set.mask, material, which);
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
        if (p.reference) {
            nlohmann::json colors = nlohmann::json::array();
            for (Rgb8 c : p.reference->colors)
                colors.push_back(hexColor(c));
            j["reference"] = {
                {"size", p.reference->size},     {"seed", p.reference->seed},   {"colors", colors},
                {"shares", p.reference->shares}, {"noise", p.reference->noise}, {"blur_px", p.reference->blurPx}};
        }
        nlohmann::json colors = nlohmann::json::array();
        for (Rgb8 c : set.colors)
            colors.push_back(hexColor(c));
        j["colors"] = colors;
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

} // namespace

std::vector<EncodedFile> encodeTextureSet(const TextureSpec& spec, const TextureSet& set) {
    // The maps encode concurrently (zlib dominates); the files keep the order of spec.maps.
    std::vector<std::future<std::vector<EncodedFile>>> jobs;
    for (const MapRequest& r : spec.maps)
        jobs.push_back(std::async(std::launch::async, [&spec, &set, r] { return encodeMap(spec, set, r); }));
    std::vector<EncodedFile> files;
    for (auto& job : jobs)
        for (EncodedFile& f : job.get())
            files.push_back(std::move(f));
    return files;
}

void requireWritableFolder(const fs::path& dir) {
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw InputError(dir.string() + ": the output folder is a file, not a folder");
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot create the output folder (" + ec.message() + ")");
    const fs::path probe = dir / (".viscera-write-probe-" + std::to_string(::getpid()));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0) throw InputError(dir.string() + ": the output folder is not writable (" + std::strerror(errno) + ")");
    ::close(fd);
    ::unlink(probe.c_str());
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
