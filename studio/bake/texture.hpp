#pragma once
/// Procedural tissue materials [A §6.2]: the quadtree pattern mask [A §6.2.1], the colour palette
/// and prominent-colour proportional map of a reference image (a file, or a synthetic photograph
/// made by code), and the PBR maps of a material made from the mask, with sub-layers composited
/// over it by their own masks [A §6.2.2, Fig. 6.8]; the JSON texture spec that drives them (`viscera-studio texture
/// <spec.json> -o <dir>`).
///
/// Images are plain row-major float or byte buffers: OpenCV (PNG coding, colour conversion,
/// resampling) is private to viscera::bake. Everything is deterministic: the same parameters and
/// seed give bit-identical images and PNG bytes on every run and thread count (the random draws
/// come from std::mt19937_64 with a fixed integer-to-double mapping, never from a standard
/// distribution, whose output is implementation-defined).
///
/// Coordinates: pixel (x, y) has its centre at (x + 0.5, y + 0.5), x to the right, y down (row
/// 0 is the top row of the PNG). Angles are degrees, counter-clockwise as displayed.
#include "sim/util/atomic_file.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::bake {

// ---- images ---------------------------------------------------------------------------------

/// One channel, row-major: pixels[y * width + x]. Values in [0, 1] unless a field says otherwise.
struct GrayImage {
    int width = 0, height = 0;
    std::vector<float> pixels;

    float at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

/// Three channels R, G, B interleaved, row-major: pixels[3 * (y * width + x) + c].
struct RgbImage {
    int width = 0, height = 0;
    std::vector<float> pixels;
};

/// An 8-bit colour, sRGB-encoded as stored in image files.
struct Rgb8 {
    uint8_t r = 0, g = 0, b = 0;
    bool operator==(const Rgb8&) const = default;
};

/// 8-bit R, G, B interleaved, row-major (reference photographs, swatch images).
struct Rgb8Image {
    int width = 0, height = 0;
    std::vector<uint8_t> pixels;
};

/// "#rrggbb", lower case.
std::string hexColor(Rgb8 color);
/// Parses "#rrggbb" (either case); nullopt for anything else.
std::optional<Rgb8> parseHexColor(std::string_view text);

// ---- quadtree pattern mask [A §6.2.1] -------------------------------------------------------

/// The pattern drawn in one quadtree node. The radial shapes are functions of the tile's
/// elliptical radius ρ (ρ = 1 on the tile's border), zero outside it.
enum class TileShape {
    Disc,     ///< 1 inside, antialiased over one pixel at the border
    Gaussian, ///< exp(-ρ²/2σ²) lowered and rescaled to reach 0 at ρ = 1 (continuous border)
    Bell,     ///< (1 + cos πρ) / 2
    Image,    ///< a grayscale image stretched over the tile (bilinear, mip-mapped); 0 outside
};

/// How one level's image L combines with the canvas C of the levels above it (coarser levels);
/// the result is clamped to [0, 1] after each level.
enum class BlendMode { Add, Subtract, Max, Min, Multiply };

/// A closed interval a value is drawn from uniformly; lo == hi: that value.
struct Range {
    double lo = 0, hi = 0;
};

struct Tile {
    TileShape shape = TileShape::Gaussian;
    double sigma = 0.4; ///< Gaussian: standard deviation in units of the tile's half-size, (0, 4]
    GrayImage image;    ///< Image: the pattern, values in [0, 1], at most 4096 × 4096
    std::string file;   ///< Image: the file as written in the spec (relative to its folder)
};

/// The pattern of one quadtree level and its per-node randomness [A Fig. 6.4]. Every node of the
/// level draws its own values from these ranges.
struct LevelPattern {
    int level = 0; ///< 0 = the whole image; level L has 2^L × 2^L nodes of size / 2^L pixels
    Tile tile;
    Range rotationDeg{0, 0};      ///< tile rotation about its centre, degrees, in [-360, 360]
    Range offsetRadius{0, 0};     ///< tile centre's distance from the node centre, × node size, [0, 2]
    Range offsetAngleDeg{0, 360}; ///< direction of that offset (polar coordinates), degrees, [-360, 360]
    Range width{1, 1};            ///< tile width, × node size, (0, 4]
    Range height{1, 1};           ///< tile height, × node size, (0, 4]; unused when uniformScale
    bool uniformScale = false;    ///< height = width (one draw from `width`)
    Range opacity{1, 1};          ///< the tile's values are multiplied by this, [0, 1]
    double probability = 1;       ///< chance that a node has a tile at all, [0, 1]
    BlendMode blend = BlendMode::Add;
};

struct QuadtreeParams {
    int size = 512;    ///< width = height in pixels, a power of two in [8, 4096]
    uint64_t seed = 0; ///< one seed for every level; each level draws from its own stream
    int levels = 1;    ///< quadtree depth, [1, log2(size) + 1] (the deepest nodes are >= 1 pixel)
    /// Toroidal: a tile crossing a border continues on the opposite side, so the mask tiles
    /// seamlessly. Otherwise tiles are clipped at the border.
    bool tileable = true;
    double base = 0;                    ///< canvas value before the first level, [0, 1]
    std::vector<LevelPattern> patterns; ///< at most one per level, applied from coarse to fine
};

/// Quadtree procedural mask [A §6.2.1, Fig. 6.3]: for each patterned level, every node places
/// its tile at node centre + polar offset, with its drawn size, rotation and opacity (a node
/// skips its tile with probability 1 - probability); the tiles of one level combine by maximum
/// into the level image, which blends into the canvas with the level's mode. Values in [0, 1].
/// Throws std::invalid_argument "bake::generateMask(): <field> ..." when a parameter is out of
/// its range. Cost: O(Σ tile areas) per level, about size² × width × height per level.
GrayImage generateMask(const QuadtreeParams& params);

// ---- palette [A §6.2.2, Fig. 6.5] -----------------------------------------------------------

struct PaletteColor {
    Rgb8 color;          ///< the mean of the group's pixels, rounded
    uint64_t pixels = 0; ///< pixels in the group
    double share = 0;    ///< pixels / all pixels of the image
};

enum class PaletteMethod {
    /// [A §6.2.2]: two colours are similar when |Δr|, |Δg| and |Δb| are all below the threshold.
    /// The image's distinct colours are visited from the most to the least frequent; each joins
    /// the first group whose leading (first, most frequent) colour it is similar to, or leads a
    /// new group. A palette colour is the mean of its group.
    Threshold,
    /// Weighted k-means in RGB with k-means++ seeding (the params' seed), Lloyd iterations until
    /// no colour changes cluster.
    KMeans,
};

struct PaletteParams {
    PaletteMethod method = PaletteMethod::Threshold;
    double threshold = 24;   ///< Threshold: in 8-bit units, (0, 256]
    int k = 6;               ///< KMeans: clusters, [1, 64] (fewer when the image has fewer colours)
    int maxIterations = 100; ///< KMeans: Lloyd iterations at most, [1, 1000]
    uint64_t seed = 0;       ///< KMeans: seeding
    int maxColors = 8;       ///< the most frequent this many groups are returned, [1, 256]
};

/// Palette of an image, sorted by share (descending; equal shares by colour value). Shares are
/// of all pixels, so they sum to 1 unless maxColors cut groups off. Throws std::invalid_argument
/// "bake::extractPalette(): ..." for an empty image or a parameter out of range.
/// Cost: one hash of every pixel, then O(distinct colours × 27) (threshold) or
/// O(distinct colours × k × iterations) (k-means).
std::vector<PaletteColor> extractPalette(const Rgb8Image& image, const PaletteParams& params);

/// Prominent-colour proportional map [A Fig. 6.5]: vertical bars left to right in the order
/// given, widths proportional to the shares (rescaled to fill the width). width, height >= 1.
Rgb8Image proportionalMap(const std::vector<PaletteColor>& colors, int width, int height);

/// The palette as a row of square swatches of `swatch` pixels.
Rgb8Image paletteSwatches(const std::vector<Rgb8>& colors, int swatch);

// ---- synthetic reference photograph ---------------------------------------------------------

/// A reference photograph for palette extraction made by code instead of read from a file
/// (reference images are generated in the repository, never downloaded or committed).
struct ReferenceSpec {
    int size = 256;             ///< width = height in pixels, a power of two in [16, 4096]
    uint64_t seed = 0;          ///< the regions' layout and the noise
    std::vector<Rgb8> colors;   ///< region colours, 1 to 16
    std::vector<double> shares; ///< area share of each colour: one per colour, each > 0, sum 1 (within 1e-6)
    double noise = 6;           ///< per-pixel noise amplitude, 8-bit units, [0, 64]
    double blurPx = 1.5;        ///< Gaussian blur across the region borders, σ in pixels, [0, 16]
};

/// A blotchy, tileable tissue-like photograph, size × size, of `colors` covering `shares` of the
/// area. A noise field Σ_l 0.6^(l-1) · generateMask(one level-l pattern of rotated, offset Gaussian
/// blobs), l = 1 .. min(5, log2(min(size, 256)) - 2) (made at most 256 px wide, then bilinearly
/// upsampled with wrap-around) is ranked pixel by pixel (ties by pixel index) and colour i takes
/// the ranks in [N·S(i-1), N·S(i)), S the cumulative shares, N = size²: colours[0] fills the low
/// ground, the last colour the blobs' cores, and each colour borders mostly the ones before and
/// after it in the list. The label image is blurred (σ = blurPx, wrapping); since blurring moves
/// pixels of thin regions towards their neighbours' colours, the rank bounds are then corrected (at
/// most 3 rounds) until the share of pixels nearest (RGB) each colour is within 1e-3 of its share.
/// Last, every channel moves by noise · (a + b_c) / 2, with a (shared by the channels) and b_c
/// triangular on [-1, 1] (at most ±noise, standard deviation ≈ 0.29 · noise), rounded and clamped
/// to [0, 255]. blurPx = 0 and noise = 0: the shares to the pixel. Deterministic: the same spec
/// gives the same bytes on every run and thread count. Throws std::invalid_argument
/// "bake::generateReferenceImage(): <field> ..." when a field breaks its rule. Cost: about 0.05 s
/// at 256², 0.4 s at 1024², 8 s at 4096² (two cores): a sort and up to four blurs of N pixels.
Rgb8Image generateReferenceImage(const ReferenceSpec& spec);

// ---- material maps of one layer [A §6.2.2, Fig. 6.8-6.9] ------------------------------------

/// A map made from the mask: value(m) = atZero + (atOne - atZero) · m.
struct MaskMapping {
    double atZero = 0, atOne = 1;
};

struct MaterialParams {
    /// Diffuse gradient: mask 0 gives the first colour, 1 the last, piecewise linear between
    /// them (in the sRGB-encoded values, as an image editor's gradient map does). >= 1 colour.
    std::vector<Rgb8> diffuseColors;
    /// Mask value of each colour, non-decreasing in [0, 1]; empty: evenly spaced from 0 to 1.
    std::vector<double> diffuseStops;
    MaskMapping roughness{0.5, 0.5};
    MaskMapping metallic{0, 0};
    MaskMapping height{0, 1};
    double heightBlurPx = 0; ///< Gaussian blur of the height map, σ in pixels, [0, 64]
    /// Relief of the height map's full range [0, 1] as a fraction of the texture width, (0, 1]:
    /// the normal map's slopes are depth × size × dh/dpixel.
    double normalDepth = 0.01;
    bool tileable = true; ///< blur and differences wrap around the borders (else clamp)
};

/// Which maps generateMaps() makes (the height is made for the normal map in any case).
struct MapSelection {
    bool diffuse = true, roughness = true, metallic = true, height = true, normal = true;
};

struct MaterialMaps {
    RgbImage diffuse;              ///< sRGB-encoded values in [0, 1]
    GrayImage roughness, metallic; ///< [0, 1]
    GrayImage height;              ///< [0, 1]
    RgbImage normal;               ///< unit vectors, components in [-1, 1] (see normalsFromHeight)
};

/// The maps of one layer, all the size of `mask`; unselected ones stay empty. Throws
/// std::invalid_argument "bake::generateMaps(): ..." for an empty mask or a parameter out of range.
MaterialMaps generateMaps(const GrayImage& mask, const MaterialParams& params, const MapSelection& which = {});

/// Tangent-space normals of a height field by central differences (wrapping around the borders
/// when `wrap`, else one-sided there): n = normalize(-s ∂h/∂x, s ∂h/∂row, 1) with s = depth ×
/// width, i.e. x to the right, y up (towards row 0, the OpenGL / glTF convention), z out of the
/// surface. Cost: O(pixels).
RgbImage normalsFromHeight(const GrayImage& height, double depth, bool wrap);

/// Separable Gaussian blur, σ in pixels (0: a copy), wrapping around or clamping at the borders.
GrayImage blurGaussian(const GrayImage& image, double sigmaPx, bool wrap);

// ---- image files ----------------------------------------------------------------------------

/// Encoded normals decode as 2c / (2^bits - 1) - 1 to within this of unit length.
inline constexpr double kNormalLengthTolerance = 1e-3;

/// PNG bytes of a [0, 1] image, 8 or 16 bits per channel, values rounded to the nearest code.
std::string encodePng(const GrayImage& image, int bits);
std::string encodePng(const RgbImage& image, int bits);
std::string encodePng(const Rgb8Image& image);
/// PNG bytes of unit normals as (n + 1) / 2. 16 bits: the nearest code (length error < 5e-5,
/// direction error < 0.002°). 8 bits: of the codes whose decoded length is within
/// kNormalLengthTolerance of 1, the one closest to n in angle, so a shader may use the texel
/// unnormalized. The nearest code alone is up to 6e-3 off unit length (0.4° off in direction);
/// the unit-length code is up to 3° off in direction, where the 8-bit lattice has no code both
/// near n and near the unit sphere: prefer 16 bits for normals. Throws std::invalid_argument
/// for bits other than 8 and 16.
std::string encodeNormalPng(const RgbImage& normals, int bits);
/// The 8-bit code encodeNormalPng() stores for the unit vector n.
std::array<uint8_t, 3> encodeUnitNormal8(double nx, double ny, double nz);

/// Image samples as stored: channels 1, 3 (R G B) or 4 (R G B A), bits 8 or 16, row-major.
struct DecodedImage {
    int width = 0, height = 0, channels = 0, bits = 0;
    std::vector<uint16_t> samples;
};
/// Decodes PNG, JPEG, TIFF, BMP, ... bytes. Throws InputError "<label>: not a readable image".
DecodedImage decodeImage(std::string_view bytes, const std::string& label);
/// A colour image file as 8-bit RGB (alpha dropped, 16 bits reduced). InputError names the path.
Rgb8Image readRgb8Image(const std::filesystem::path& file, int maxSide = 8192);
/// A grayscale image file in [0, 1] (colour converted to luma). InputError names the path.
GrayImage readGrayImage(const std::filesystem::path& file, int maxSide = 4096);

// ---- texture spec and bake ------------------------------------------------------------------

/// Reference: the synthetic reference photograph of palette.reference (a look at what the
/// palette was extracted from; an authoring aid, never packaged into a case).
enum class MapKind { Mask, Diffuse, Roughness, Metallic, Height, Normal, Palette, Prominent, Reference };

/// "mask", "diffuse", ..., "prominent", "reference": the spec's key and the file name's suffix.
std::string_view mapName(MapKind kind);

struct MapRequest {
    MapKind kind = MapKind::Mask;
    int bits = 8; ///< 8 or 16 (unused by palette, prominent and reference: 8-bit colour images)
};

/// Where the palette comes from: explicit colours, a reference image file, or a synthetic
/// reference photograph (exactly one of the three).
struct PaletteSpec {
    std::vector<Rgb8> colors;               ///< explicit colours (empty otherwise)
    Rgb8Image image;                        ///< the reference image file's pixels (empty otherwise)
    std::string imageFile;                  ///< the image's path as written in the spec (empty otherwise)
    std::optional<ReferenceSpec> reference; ///< the synthetic reference (generated by generateTextureSet)
    PaletteParams params;                   ///< extraction (method, threshold or k, ...)
    double prominentThreshold = 64;         ///< threshold grouping for the proportional map, >= threshold
};

/// A sub-layer composited over the base material [A §6.2.2, Fig. 6.8: surface, granular,
/// connective, submucosa]: its own quadtree mask m (same size and tiling as the base), coverage
/// α = opacity · m, and the channels it paints. Each channel it names blends over the material
/// below, C = C + α (L - C), with L the layer's own map of m; the others show through. Layers
/// composite in order, before the height blur and the normals, so the normal map is the composite
/// height's.
struct LayerSpec {
    std::string name;                                       ///< files <spec name>_<layer name>_<map>.png
    QuadtreeParams quadtree;                                ///< size and tileable are the base's
    std::optional<PaletteSpec> palette;                     ///< empty: the base's palette
    double opacity = 1;                                     ///< [0, 1]
    MaterialParams material;                                ///< diffuseColors stays empty: it comes from diffuseIndices
    std::vector<int> diffuseIndices;                        ///< colours of the layer's palette (empty: all of them)
    MapSelection paints{false, false, false, false, false}; ///< channels composited (normal unused)
    std::vector<MapRequest> files;                          ///< the layer's own maps written (mask = the coverage α)
};

/// One material's texture job, as read from a spec file (see README "Texture spec").
struct TextureSpec {
    std::string origin; ///< the spec's name in messages
    std::string name;   ///< output files are <name>_<map>.png
    QuadtreeParams quadtree;
    std::optional<PaletteSpec> palette;
    MaterialParams material;         ///< diffuseColors stays empty: it comes from diffuseIndices
    std::vector<int> diffuseIndices; ///< palette colours of the diffuse gradient
    std::vector<MapRequest> maps;    ///< what to write, in MapKind order
    int swatchPx = 64;               ///< palette swatch size
    int prominentWidth = 512, prominentHeight = 64;
    std::vector<LayerSpec> layers; ///< composited over the base, in order
};

/// Parses a texture spec; files it names resolve against `folder` and are read here (the
/// palette's reference image, image tiles). Throws viscera::InputError, one line
/// "<origin>: <JSON path>: <rule>": invalid JSON, unknown field, missing field, wrong type,
/// number out of its range, size not a power of two, a path that is absolute or leaves the
/// folder ('..'), an unreadable image, a palette.reference breaking a rule of ReferenceSpec
/// (checked here in full, so generateReferenceImage() cannot refuse it; generated later).
TextureSpec parseTextureSpec(std::string_view text, const std::string& origin, const std::filesystem::path& folder);
/// Reads and parses a spec file; origin is the path as given, files resolve against its folder.
TextureSpec loadTextureSpec(const std::filesystem::path& file);
/// The JSON text of a spec (2-space indent, keys sorted, a final newline): every field the
/// reader reads, under its key, defaults written out, so that parseTextureSpec(text, origin,
/// folder) gives back an equal spec (origin aside) when the spec's folder is `folder`. Files
/// (the palette's image, image tiles) are the relative paths the spec holds, never written
/// here; a layer's seed is written only when it is not the default (base seed + 1 + index).
/// The spec's bit_depth is that of its palette, prominent or reference map (else 8); every
/// other map writes its own. Fields the reader derives rather than reads (origin,
/// material.tileable, the palettes' seeds, a layer's size and tiling, parameters of a palette
/// method not chosen) are not written; a spec that sets them otherwise, or a value the reader
/// refuses, does not read back equal. Cost: O(size of the spec).
std::string textureSpecText(const TextureSpec& spec);
/// The files a spec reads besides itself (the palette's image, image tiles), as written in it
/// (relative to the spec's folder), each once: what must travel with the spec.
std::vector<std::string> specInputFiles(const TextureSpec& spec);

/// What one layer makes: its coverage and its own maps (before compositing).
struct LayerSet {
    GrayImage coverage; ///< α = opacity · mask
    MaterialMaps maps;  ///< the channels the layer paints or writes; height unblurred
    std::vector<Rgb8> colors;
};

/// Everything a spec makes, in memory.
struct TextureSet {
    GrayImage mask;
    MaterialMaps maps;
    std::vector<Rgb8> colors;            ///< the palette used (explicit or extracted)
    std::vector<PaletteColor> palette;   ///< extracted palette (empty when explicit)
    std::vector<PaletteColor> prominent; ///< prominent colours (empty when explicit)
    Rgb8Image reference;                 ///< the synthetic reference photograph (empty unless palette.reference)
    std::vector<LayerSet> layers;        ///< one per spec layer
};

/// Blends `layer` over `below` in place with coverage α: for each channel `which` names (height:
/// into below.height), C = C + α (L - C). Every image has α's size. Throws std::invalid_argument
/// "bake::compositeLayer(): ..." when a named channel is missing or of another size.
void compositeLayer(MaterialMaps& below, const MaterialMaps& layer, const GrayImage& alpha, const MapSelection& which);

/// Generates the mask and the synthetic reference (palette.reference), extracts the palettes and
/// makes the requested maps. Throws InputError
/// "<origin>: maps.diffuse.colors[i]: ..." when a diffuse colour index exceeds an extracted palette.
TextureSet generateTextureSet(const TextureSpec& spec);

struct EncodedFile {
    std::string fileName; ///< "<name>_<map>.png" or "<name>_palette.json"
    std::string bytes;
};
/// The files of a spec's maps: one PNG per request, plus <name>_palette.json (colours as hex and
/// share) with the palette map; <name>_reference.png is the synthetic reference photograph.
std::vector<EncodedFile> encodeTextureSet(const TextureSpec& spec, const TextureSet& set);

/// Creates `dir` if needed and checks that a file can be written in it (a probe file is written
/// and removed). Throws InputError "<dir>: ..." naming the reason.
using viscera::requireWritableFolder;

struct WrittenFile {
    std::filesystem::path path;
    uintmax_t bytes = 0;
};

struct BakeTextureResult {
    TextureSet set;
    std::vector<WrittenFile> files;
    double generateSeconds = 0, encodeSeconds = 0, writeSeconds = 0; ///< wall time of each phase
};

/// requireWritableFolder(outDir), then generate, encode and write every file atomically
/// (sim/util/atomic_file.hpp).
BakeTextureResult bakeTexture(const TextureSpec& spec, const std::filesystem::path& outDir);

} // namespace viscera::bake
