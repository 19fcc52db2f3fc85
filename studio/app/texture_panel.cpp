#include "app/texture_panel.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"

#include <QCheckBox>
#include <QClipboard>
#include <QColorDialog>
#include <QComboBox>
#include <QDateTime>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QFutureWatcher>
#include <QGridLayout>
#include <QGroupBox>
#include <QGuiApplication>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPixmap>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QToolButton>
#include <QUndoStack>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <stdexcept>

namespace viscera::studio {
namespace {

using nlohmann::json;

constexpr int kThumbPx = 96;      ///< side of a thumbnail on screen
constexpr int kSwatchColumns = 4; ///< swatches per row
const char* const kMapTitles[4] = {"diffuse", "roughness", "normal", "pattern"};
const char* const kShapes[4] = {"disc", "gaussian", "bell", "image"};
const char* const kBlends[5] = {"add", "subtract", "max", "min", "multiply"};

struct ThumbnailResult {
    TextureThumbnails thumbs;
    QString error;
};

struct PaletteResult {
    std::vector<bake::PaletteColor> colors;
    QString error;
};

uchar toByte(float v) {
    return static_cast<uchar>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

QImage toQImage(const bake::RgbImage& img, bool normal) {
    if (img.pixels.empty()) return {};
    QImage out(img.width, img.height, QImage::Format_RGB888);
    for (int y = 0; y < img.height; ++y) {
        uchar* row = out.scanLine(y);
        const float* src = img.pixels.data() + static_cast<size_t>(3) * y * img.width;
        for (int i = 0; i < 3 * img.width; ++i)
            row[i] = toByte(normal ? 0.5f * (src[i] + 1.0f) : src[i]);
    }
    return out;
}

QImage toQImage(const bake::GrayImage& img) {
    if (img.pixels.empty()) return {};
    QImage out(img.width, img.height, QImage::Format_Grayscale8);
    for (int y = 0; y < img.height; ++y) {
        uchar* row = out.scanLine(y);
        for (int x = 0; x < img.width; ++x)
            row[x] = toByte(img.at(x, y));
    }
    return out;
}

/// Replaces the swatches in `grid` by one label per colour: the colour as background, its hex
/// value as text (selectable) and tooltip, with its share when known.
void fillSwatches(QGridLayout* grid, const std::vector<bake::Rgb8>& colors, const std::vector<double>& shares) {
    while (QLayoutItem* item = grid->takeAt(0)) {
        delete item->widget();
        delete item;
    }
    for (size_t i = 0; i < colors.size(); ++i) {
        const bake::Rgb8 c = colors[i];
        const QString hex = QString::fromStdString(bake::hexColor(c));
        auto* sw = new QLabel(hex);
        sw->setObjectName("swatch");
        sw->setAlignment(Qt::AlignCenter);
        sw->setMinimumSize(68, 28);
        sw->setTextInteractionFlags(Qt::TextSelectableByMouse);
        const double luma = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
        sw->setStyleSheet(QStringLiteral("background-color: %1; color: %2; border: 1px solid #404040")
                              .arg(hex, luma > 140 ? "#000000" : "#ffffff"));
        sw->setToolTip(
            i < shares.size() ? QObject::tr("%1 — %2 % of the pixels").arg(hex, numberText(100 * shares[i], 3)) : hex);
        grid->addWidget(sw, static_cast<int>(i) / kSwatchColumns, static_cast<int>(i) % kSwatchColumns);
    }
}

/// The JSON of layer `layer` of a spec (0: the spec itself); null when there is none.
json* layerJson(json& root, int layer) {
    if (layer == 0) return &root;
    auto it = root.find("layers");
    if (it == root.end() || !it->is_array() || layer > static_cast<int>(it->size())) return nullptr;
    return &(*it)[static_cast<size_t>(layer - 1)];
}

json rangeJson(double lo, double hi) {
    return lo == hi ? json(lo) : json::array({lo, hi});
}

QDoubleSpinBox* makeSpin(QWidget* parent, double lo, double hi, double step, int decimals, const QString& tip) {
    auto* s = new QDoubleSpinBox(parent);
    s->setRange(lo, hi);
    s->setSingleStep(step);
    s->setDecimals(decimals);
    s->setKeyboardTracking(false); // a change is one edit: Enter, focus out or an arrow step
    s->setToolTip(tip);
    return s;
}

} // namespace

json defaultGenerator(const std::string& name) {
    json g = {{"size", 512},
              {"seed", 1},
              {"levels", 7},
              {"tileable", true},
              {"patterns", json::array({{{"level", 3},
                                         {"tile", {{"shape", "bell"}}},
                                         {"rotation_deg", {0, 360}},
                                         {"offset", {{"radius", {0, 0.6}}, {"angle_deg", {0, 360}}}},
                                         {"scale", {{"uniform", {0.8, 1.6}}}},
                                         {"opacity", {0.5, 1.0}},
                                         {"blend", "add"}},
                                        {{"level", 5},
                                         {"tile", {{"shape", "gaussian"}, {"sigma", 0.35}}},
                                         {"offset", {{"radius", {0, 0.5}}, {"angle_deg", {0, 360}}}},
                                         {"scale", {{"uniform", {0.6, 1.2}}}},
                                         {"opacity", {0.2, 0.6}},
                                         {"probability", 0.8},
                                         {"blend", "add"}}})},
              {"palette", {{"colors", {"#7a1f1c", "#b4483c", "#e0a090"}}}},
              {"maps",
               {{"diffuse", json::object()},
                {"roughness", {{"values", {0.55, 0.35}}}},
                {"height", {{"blur_px", 1.5}}},
                {"normal", {{"depth", 0.01}}}}}};
    if (!name.empty() && name.find('/') == std::string::npos && !sim::entryNameProblem(name)) g["name"] = name;
    return g;
}

TextureThumbnails makeTextureThumbnails(const TextureProject& block, const std::filesystem::path& projectDir,
                                        int maxSide, int layer) {
    if (maxSide < 8 || maxSide > 4096 || !std::has_single_bit(static_cast<unsigned>(maxSide)))
        throw std::invalid_argument("studio::makeTextureThumbnails(): maxSide " + std::to_string(maxSide) +
                                    " is not a power of two in [8, 4096]");
    bake::TextureSpec spec = loadTextureBlock(block, projectDir, "the texture generator");
    if (spec.quadtree.size > maxSide) {
        const double factor = static_cast<double>(maxSide) / spec.quadtree.size;
        const int maxLevels = std::bit_width(static_cast<unsigned>(maxSide)); // log2(maxSide) + 1
        auto shrink = [&](bake::QuadtreeParams& q) {
            q.size = maxSide;
            q.levels = std::min(q.levels, maxLevels);
            std::erase_if(q.patterns, [&](const bake::LevelPattern& p) { return p.level >= q.levels; });
        };
        shrink(spec.quadtree);
        for (bake::LayerSpec& l : spec.layers)
            shrink(l.quadtree);
        spec.material.heightBlurPx *= factor;
    }
    for (bake::LayerSpec& l : spec.layers)
        l.files.clear(); // the layers' own files are not shown
    std::vector<bake::MapRequest> maps;
    for (const bake::MapRequest& r : spec.maps)
        if (r.kind == bake::MapKind::Diffuse || r.kind == bake::MapKind::Roughness || r.kind == bake::MapKind::Normal)
            maps.push_back({r.kind, 8});
    spec.maps = std::move(maps);

    const bake::TextureSet set = bake::generateTextureSet(spec);
    TextureThumbnails out;
    out.size = spec.quadtree.size;
    out.seed = spec.quadtree.seed;
    out.colors = set.colors;
    for (const bake::PaletteColor& c : set.palette)
        out.shares.push_back(c.share);
    out.diffuse = toQImage(set.maps.diffuse, false);
    out.roughness = toQImage(set.maps.roughness);
    out.normal = toQImage(set.maps.normal, true);
    const bool ofLayer = layer > 0 && layer <= static_cast<int>(set.layers.size());
    out.pattern = toQImage(ofLayer ? set.layers[static_cast<size_t>(layer - 1)].coverage : set.mask);
    return out;
}

std::vector<bake::PaletteColor> pickPalette(const std::filesystem::path& image, const bake::PaletteParams& params) {
    const bake::Rgb8Image pixels = bake::readRgb8Image(image, 2048);
    try {
        return bake::extractPalette(pixels, params);
    } catch (const std::invalid_argument& e) {
        throw InputError(image.string() + ": " + e.what());
    }
}

TexturePanel::TexturePanel(Document* doc, QWidget* parent) : QWidget(parent), m_doc(doc) {
    auto* root = new QVBoxLayout(this);
    buildBlockFields(root);
    buildThumbnails(root);
    buildGeneratorBox(root);
    buildPicker(root);
    root->addStretch(1);

    connectBlockFields();
    connectGeneratorFields();
    connect(m_doc, &Document::changed, this, [this](const Change& what) {
        if (what.touches(Change::Texture | Change::Structure)) refresh(); // a material drag redraws nothing here
    });
    refresh();
}

TexturePanel::~TexturePanel() {
    // A thumbnail or palette job still running would outlive the panel (at exit, the application
    // whose image types it builds): wait for it, as the other panels with background jobs do.
    for (QFutureWatcherBase* w : findChildren<QFutureWatcherBase*>())
        w->waitForFinished();
}

void TexturePanel::buildBlockFields(QVBoxLayout* root) {
    m_header = new QLabel(this);
    m_header->setObjectName("textureHeader");
    root->addWidget(m_header);

    auto* form = new QFormLayout;
    m_spec = new QLineEdit(this);
    m_spec->setObjectName("textureSpec");
    m_spec->setPlaceholderText("textures/organ.json");
    m_spec->setToolTip(tr("A texture spec file, relative to the project folder (it must lie inside it); empty when "
                          "the generator below is kept in project.json"));
    m_tiles = new QLineEdit(this);
    m_tiles->setObjectName("textureTilesPerMetre");
    m_tiles->setToolTip(tr("How many times the maps repeat per metre of the surface"));
    m_normal = new QLineEdit(this);
    m_normal->setObjectName("textureNormalStrength");
    m_normal->setToolTip(tr("Scale of the normal map's relief (1: as generated)"));
    form->addRow(tr("Spec file"), m_spec);
    form->addRow(tr("Tiles per metre"), m_tiles);
    form->addRow(tr("Normal strength"), m_normal);
    root->addLayout(form);

    auto* buttons = new QHBoxLayout;
    m_apply = new QPushButton(tr("Apply"), this);
    m_apply->setObjectName("textureApply");
    m_apply->setToolTip(tr("Writes the spec file, tiles and normal strength into the selection's block"));
    m_new = new QPushButton(tr("New generator"), this);
    m_new->setObjectName("textureNew");
    m_new->setToolTip(tr("Gives the selection a generator kept in project.json, to edit below"));
    m_remove = new QPushButton(tr("Remove"), this);
    m_remove->setObjectName("textureRemove");
    buttons->addWidget(m_apply);
    buttons->addWidget(m_new);
    buttons->addWidget(m_remove);
    buttons->addStretch(1);
    root->addLayout(buttons);
    m_status = new QLabel(this);
    m_status->setObjectName("textureStatus");
    m_status->setWordWrap(true);
    root->addWidget(m_status);
}

void TexturePanel::buildThumbnails(QVBoxLayout* root) {
    auto* grid = new QGridLayout;
    for (int m = 0; m < 4; ++m) {
        m_thumbLabels[m] = new QLabel(this);
        m_thumbLabels[m]->setObjectName(QStringLiteral("thumbnail_%1").arg(kMapTitles[m]));
        m_thumbLabels[m]->setFixedSize(kThumbPx, kThumbPx);
        m_thumbLabels[m]->setAlignment(Qt::AlignCenter);
        m_thumbLabels[m]->setFrameShape(QFrame::StyledPanel);
        grid->addWidget(m_thumbLabels[m], 0, m);
        auto* caption = new QLabel(tr(kMapTitles[m]), this);
        caption->setAlignment(Qt::AlignCenter);
        grid->addWidget(caption, 1, m);
    }
    grid->setColumnStretch(4, 1);
    root->addLayout(grid);
    m_thumbStatus = new QLabel(this);
    m_thumbStatus->setObjectName("thumbnailStatus");
    m_thumbStatus->setWordWrap(true);
    root->addWidget(m_thumbStatus);
    root->addWidget(new QLabel(tr("Palette the maps use"), this));
    m_specSwatchHost = new QWidget(this);
    m_specSwatchHost->setObjectName("specSwatches");
    m_specSwatches = new QGridLayout(m_specSwatchHost);
    m_specSwatches->setContentsMargins(0, 0, 0, 0);
    root->addWidget(m_specSwatchHost);
}

void TexturePanel::buildPicker(QVBoxLayout* root) {
    auto* pickRow = new QHBoxLayout;
    m_pick = new QPushButton(tr("Pick palette from image…"), this);
    m_pick->setObjectName("pickPalette");
    m_method = new QComboBox(this);
    m_method->setObjectName("pickMethod");
    m_method->addItems({tr("threshold (24)"), tr("k-means (k = 6)")});
    m_method->setToolTip(tr("Threshold: colours within 24 of a group's leading colour join it; k-means: 6 clusters"));
    m_copyHex = new QPushButton(tr("Copy hex"), this);
    m_copyHex->setObjectName("copyHex");
    m_copyHex->setEnabled(false);
    m_usePicked = new QPushButton(tr("Use in layer"), this);
    m_usePicked->setObjectName("usePickedPalette");
    m_usePicked->setToolTip(tr("Makes the picked colours the palette of the chosen layer"));
    m_usePicked->setEnabled(false);
    pickRow->addWidget(m_pick);
    pickRow->addWidget(m_copyHex);
    pickRow->addWidget(m_usePicked);
    pickRow->addStretch(1);
    root->addLayout(pickRow);
    auto* methodRow = new QFormLayout;
    methodRow->addRow(tr("Method"), m_method);
    root->addLayout(methodRow);
    m_pickStatus = new QLabel(this);
    m_pickStatus->setObjectName("pickStatus");
    m_pickStatus->setWordWrap(true);
    root->addWidget(m_pickStatus);
    m_pickedSwatchHost = new QWidget(this);
    m_pickedSwatchHost->setObjectName("pickedSwatches");
    m_pickedSwatches = new QGridLayout(m_pickedSwatchHost);
    m_pickedSwatches->setContentsMargins(0, 0, 0, 0);
    root->addWidget(m_pickedSwatchHost);
}

void TexturePanel::connectBlockFields() {
    connect(m_apply, &QPushButton::clicked, this, [this] { applyFields(); });
    connect(m_new, &QPushButton::clicked, this, [this] { newGenerator(); });
    connect(m_remove, &QPushButton::clicked, this, [this] { removeTexture(); });
    for (QLineEdit* f : {m_spec, m_tiles, m_normal})
        connect(f, &QLineEdit::returnPressed, this, [this] { applyFields(); });
    connect(m_pick, &QPushButton::clicked, this, [this] {
        const QString dir = m_doc->hasProject() ? m_doc->folder() : QString();
        const QString file = QFileDialog::getOpenFileName(this, tr("Photo to pick a palette from"), dir,
                                                          tr("Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp)"));
        if (!file.isEmpty()) pickPaletteFrom(file);
    });
    connect(m_copyHex, &QPushButton::clicked, this, [this] { QGuiApplication::clipboard()->setText(pickedHexText()); });
    connect(m_usePicked, &QPushButton::clicked, this, [this] { usePickedPalette(); });
}

void TexturePanel::buildGeneratorBox(QVBoxLayout* root) {
    m_genBox = new QGroupBox(tr("Generator"), this);
    m_genBox->setObjectName("generatorBox");
    auto* box = new QVBoxLayout(m_genBox);
    m_genSource = new QLabel(m_genBox);
    m_genSource->setObjectName("generatorSource");
    m_genSource->setWordWrap(true);
    box->addWidget(m_genSource);
    buildQuadtreeFields(box);
    buildPatternFields(box);

    m_paletteNote = new QLabel(m_genBox);
    m_paletteNote->setObjectName("paletteNote");
    m_paletteNote->setWordWrap(true);
    box->addWidget(m_paletteNote);
    m_paletteHost = new QWidget(m_genBox);
    m_paletteHost->setObjectName("paletteColours");
    m_paletteRow = new QHBoxLayout(m_paletteHost);
    m_paletteRow->setContentsMargins(0, 0, 0, 0);
    box->addWidget(m_paletteHost);
    root->addWidget(m_genBox);
}

void TexturePanel::buildQuadtreeFields(QVBoxLayout* box) {
    auto* form = new QFormLayout;
    m_layerBox = new QComboBox(m_genBox);
    m_layerBox->setObjectName("generatorLayer");
    m_layerBox->setToolTip(tr("The base material or one of the layers composited over it [A Fig. 6.8]"));
    m_addLayer = new QPushButton(tr("Add layer"), m_genBox);
    m_addLayer->setObjectName("addLayer");
    m_addLayer->setToolTip(tr("A sub-layer (granular, connective, ...) blended over the material by its own "
                              "pattern"));
    m_removeLayer = new QPushButton(tr("Remove"), m_genBox);
    m_removeLayer->setObjectName("removeLayer");
    m_removeLayer->setToolTip(tr("Removes the chosen layer"));
    auto* layerRow = new QHBoxLayout;
    layerRow->addWidget(m_layerBox, 1);
    layerRow->addWidget(m_addLayer);
    layerRow->addWidget(m_removeLayer);
    form->addRow(tr("Layer"), layerRow);
    m_layerOpacity = makeSpin(m_genBox, 0, 1, 0.05, 3, tr("The layer's coverage is its pattern × this"));
    m_layerOpacity->setObjectName("layerOpacity");
    form->addRow(tr("Layer opacity"), m_layerOpacity);
    m_size = new QComboBox(m_genBox);
    m_size->setObjectName("generatorSize");
    for (int s = 64; s <= 4096; s *= 2)
        m_size->addItem(QStringLiteral("%1 × %1").arg(s), s);
    m_size->setToolTip(tr("Side of every map in pixels (all layers)"));
    form->addRow(tr("Size"), m_size);
    m_seed = new QSpinBox(m_genBox);
    m_seed->setObjectName("generatorSeed");
    m_seed->setRange(0, INT_MAX);
    m_seed->setKeyboardTracking(false);
    m_seed->setToolTip(tr("The same seed gives byte-identical maps"));
    form->addRow(tr("Seed"), m_seed);
    m_levels = new QSpinBox(m_genBox);
    m_levels->setObjectName("generatorLevels");
    m_levels->setRange(1, 13);
    m_levels->setKeyboardTracking(false);
    m_levels->setToolTip(tr("Quadtree depth: level L has 2^L × 2^L nodes"));
    form->addRow(tr("Levels"), m_levels);
    m_tileable = new QCheckBox(tr("wraps across the borders"), m_genBox);
    m_tileable->setObjectName("generatorTileable");
    form->addRow(tr("Tileable"), m_tileable);
    m_base = makeSpin(m_genBox, 0, 1, 0.05, 3, tr("The canvas value before the first level"));
    m_base->setObjectName("generatorBase");
    form->addRow(tr("Base"), m_base);
    box->addLayout(form);
}

void TexturePanel::buildPatternFields(QVBoxLayout* box) {
    auto* patternRow = new QHBoxLayout;
    m_patternBox = new QComboBox(m_genBox);
    m_patternBox->setObjectName("generatorPattern");
    m_addPattern = new QPushButton(tr("Add"), m_genBox);
    m_addPattern->setObjectName("addPattern");
    m_addPattern->setToolTip(tr("A new pattern on the first level without one"));
    m_removePattern = new QPushButton(tr("Remove"), m_genBox);
    m_removePattern->setObjectName("removePattern");
    patternRow->addWidget(new QLabel(tr("Pattern"), m_genBox));
    patternRow->addWidget(m_patternBox, 1);
    patternRow->addWidget(m_addPattern);
    patternRow->addWidget(m_removePattern);
    box->addLayout(patternRow);

    auto* pf = new QFormLayout;
    m_pLevel = new QSpinBox(m_genBox);
    m_pLevel->setObjectName("patternLevel");
    m_pLevel->setRange(0, 12);
    m_pLevel->setKeyboardTracking(false);
    pf->addRow(tr("Level"), m_pLevel);
    m_pShape = new QComboBox(m_genBox);
    m_pShape->setObjectName("patternShape");
    for (const char* s : kShapes)
        m_pShape->addItem(tr(s), QString(s));
    m_pShape->setToolTip(tr("Image: a grayscale picture of the project stretched over the tile"));
    pf->addRow(tr("Tile"), m_pShape);
    m_pSigma = makeSpin(m_genBox, 0.01, 4, 0.05, 3, tr("Gaussian: σ in units of the tile's half-size"));
    m_pSigma->setObjectName("patternSigma");
    pf->addRow(tr("σ"), m_pSigma);
    auto range = [&](RangeEdit& r, const QString& label, const QString& name, double lo, double hi, double step,
                     const QString& tip) {
        r.lo = makeSpin(m_genBox, lo, hi, step, 3, tip + tr(" (lower end)"));
        r.hi = makeSpin(m_genBox, lo, hi, step, 3, tip + tr(" (upper end)"));
        r.lo->setObjectName(name + "Lo");
        r.hi->setObjectName(name + "Hi");
        auto* row = new QHBoxLayout;
        row->addWidget(r.lo);
        row->addWidget(new QLabel(QStringLiteral("–"), m_genBox));
        row->addWidget(r.hi);
        pf->addRow(label, row);
    };
    range(m_pRotation, tr("Rotation °"), "patternRotation", -360, 360, 15, tr("Tile rotation, degrees"));
    range(m_pRadius, tr("Offset radius"), "patternRadius", 0, 2, 0.05,
          tr("Distance of the tile from its node's centre, × node size"));
    range(m_pAngle, tr("Offset angle °"), "patternAngle", -360, 360, 15, tr("Direction of the offset, degrees"));
    m_pUniform = new QCheckBox(tr("uniform (height = width)"), m_genBox);
    m_pUniform->setObjectName("patternUniform");
    pf->addRow(tr("Scale"), m_pUniform);
    range(m_pWidth, tr("Width"), "patternWidth", 0.01, 4, 0.1, tr("Tile width, × node size"));
    range(m_pHeight, tr("Height"), "patternHeight", 0.01, 4, 0.1, tr("Tile height, × node size"));
    range(m_pOpacity, tr("Opacity"), "patternOpacity", 0, 1, 0.05, tr("The tile's values are multiplied by this"));
    m_pProbability = makeSpin(m_genBox, 0, 1, 0.05, 3, tr("Chance that a node has a tile"));
    m_pProbability->setObjectName("patternProbability");
    pf->addRow(tr("Probability"), m_pProbability);
    m_pBlend = new QComboBox(m_genBox);
    m_pBlend->setObjectName("patternBlend");
    for (const char* b : kBlends)
        m_pBlend->addItem(tr(b), QString(b));
    m_pBlend->setToolTip(tr("How this level combines with the coarser levels above it"));
    pf->addRow(tr("Blend"), m_pBlend);
    box->addLayout(pf);
}

void TexturePanel::connectGeneratorFields() {
    connectQuadtreeFields();
    connectPatternFields();
    connectPatternButtons();
}

void TexturePanel::connectQuadtreeFields() {
    connect(m_layerBox, &QComboBox::currentIndexChanged, this, [this](int i) { chooseLayer(std::max(0, i)); });
    connect(m_addLayer, &QPushButton::clicked, this, [this] { addLayer(); });
    connect(m_removeLayer, &QPushButton::clicked, this, [this] { removeLayer(); });
    connect(m_layerOpacity, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        if (m_layer == 0) return;
        editGenerator(tr("Set the layer opacity"), m_layerOpacity, [&](json& layer, json&) { layer["opacity"] = v; });
    });
    connect(m_patternBox, &QComboBox::currentIndexChanged, this, [this](int i) {
        m_pattern = std::max(0, i);
        m_lastSource = nullptr;
        fillGenerator();
    });
    connect(m_size, &QComboBox::currentIndexChanged, this, [this](int i) {
        const int size = m_size->itemData(i).toInt();
        editGenerator(tr("Set the texture size"), m_size, [&](json&, json& root) { root["size"] = size; });
    });
    connect(m_seed, &QSpinBox::valueChanged, this, [this](int v) {
        editGenerator(tr("Set the seed"), m_seed, [&](json& layer, json&) { layer["seed"] = v; });
    });
    connect(m_levels, &QSpinBox::valueChanged, this, [this](int v) {
        editGenerator(tr("Set the quadtree levels"), m_levels, [&](json& layer, json&) { layer["levels"] = v; });
    });
    connect(m_tileable, &QCheckBox::toggled, this, [this](bool on) {
        editGenerator(tr("Set tiling"), m_tileable, [&](json&, json& root) { root["tileable"] = on; });
    });
    connect(m_base, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        editGenerator(tr("Set the base value"), m_base, [&](json& layer, json&) { layer["base"] = v; });
    });
}

void TexturePanel::connectPatternFields() {
    // pattern fields: each writes its key of the chosen pattern
    auto pattern = [this](const QString& what, const void* source, const std::function<void(json & p)>& fn) {
        const int index = m_pattern;
        editGenerator(what, source, [&](json& layer, json&) {
            json& list = layer["patterns"];
            if (!list.is_array() || index >= static_cast<int>(list.size()))
                throw InputError("the chosen pattern is not in the spec any more");
            fn(list[static_cast<size_t>(index)]);
        });
    };
    connect(m_pLevel, &QSpinBox::valueChanged, this, [this, pattern](int v) {
        pattern(tr("Set the pattern's level"), m_pLevel, [&](json& p) { p["level"] = v; });
    });
    connect(m_pShape, &QComboBox::currentIndexChanged, this, [this, pattern](int i) {
        const QString shape = m_pShape->itemData(i).toString();
        std::string file;
        if (shape == "image") {
            const QString dir = m_doc->hasProject() ? m_doc->folder() : QString();
            const QString picked = QFileDialog::getOpenFileName(this, tr("Grayscale tile image (inside the project)"),
                                                                dir, tr("Images (*.png *.jpg *.jpeg *.tif *.tiff)"));
            if (picked.isEmpty()) {
                fillGenerator(); // back to the spec's shape
                return;
            }
            file = std::filesystem::path(picked.toStdString())
                       .lexically_relative(m_doc->project().dir)
                       .generic_string(); // the model's rules refuse one outside the folder
        }
        const double sigma = m_pSigma->value();
        pattern(tr("Set the tile shape"), m_pShape, [&](json& p) {
            json tile = {{"shape", shape.toStdString()}};
            if (shape == "gaussian") tile["sigma"] = sigma;
            if (shape == "image") tile["file"] = file;
            p["tile"] = tile;
        });
    });
    connect(m_pSigma, &QDoubleSpinBox::valueChanged, this, [this, pattern](double v) {
        pattern(tr("Set the tile's σ"), m_pSigma, [&](json& p) {
            if (!p["tile"].is_object() || p["tile"].value("shape", "") != "gaussian")
                throw InputError("σ applies to Gaussian tiles only");
            p["tile"]["sigma"] = v;
        });
    });
    auto rangeField = [this, pattern](const RangeEdit& r, const QString& what,
                                      const std::function<json&(json & p)>& slot) {
        for (QDoubleSpinBox* box : {r.lo, r.hi})
            connect(box, &QDoubleSpinBox::valueChanged, this, [r, what, slot, pattern, box](double) {
                pattern(what, box, [&](json& p) { slot(p) = rangeJson(r.lo->value(), r.hi->value()); });
            });
    };
    rangeField(m_pRotation, tr("Set the rotation range"), [](json& p) -> json& { return p["rotation_deg"]; });
    rangeField(m_pRadius, tr("Set the offset radius"), [](json& p) -> json& { return p["offset"]["radius"]; });
    rangeField(m_pAngle, tr("Set the offset angle"), [](json& p) -> json& { return p["offset"]["angle_deg"]; });
    rangeField(m_pOpacity, tr("Set the opacity range"), [](json& p) -> json& { return p["opacity"]; });
    // the scale: {"uniform": w} or {"width": w, "height": h}
    auto writeScale = [this](json& p) {
        const json w = rangeJson(m_pWidth.lo->value(), m_pWidth.hi->value());
        p["scale"] = m_pUniform->isChecked()
                         ? json{{"uniform", w}}
                         : json{{"width", w}, {"height", rangeJson(m_pHeight.lo->value(), m_pHeight.hi->value())}};
    };
    for (QDoubleSpinBox* box : {m_pWidth.lo, m_pWidth.hi, m_pHeight.lo, m_pHeight.hi})
        connect(box, &QDoubleSpinBox::valueChanged, this,
                [pattern, writeScale, box, this](double) { pattern(tr("Set the tile size"), box, writeScale); });
    connect(m_pUniform, &QCheckBox::toggled, this,
            [pattern, writeScale, this](bool) { pattern(tr("Set uniform scaling"), m_pUniform, writeScale); });
    connect(m_pProbability, &QDoubleSpinBox::valueChanged, this, [this, pattern](double v) {
        pattern(tr("Set the tile probability"), m_pProbability, [&](json& p) { p["probability"] = v; });
    });
    connect(m_pBlend, &QComboBox::currentIndexChanged, this, [this, pattern](int i) {
        const std::string mode = m_pBlend->itemData(i).toString().toStdString();
        pattern(tr("Set the blend mode"), m_pBlend, [&](json& p) { p["blend"] = mode; });
    });
}

void TexturePanel::connectPatternButtons() {
    connect(m_addPattern, &QPushButton::clicked, this, [this] {
        const bake::QuadtreeParams* q = chosenQuadtree();
        if (!q) return;
        int free = -1;
        for (int l = 0; l < q->levels && free < 0; ++l)
            if (std::none_of(q->patterns.begin(), q->patterns.end(),
                             [&](const bake::LevelPattern& p) { return p.level == l; }))
                free = l;
        if (free < 0) {
            setStatus(tr("every level has a pattern: add a level first"));
            return;
        }
        const int next = static_cast<int>(q->patterns.size());
        const QString why = editGenerator(tr("Add a pattern"), m_addPattern, [&](json& layer, json&) {
            layer["patterns"].push_back({{"level", free},
                                         {"tile", {{"shape", "gaussian"}, {"sigma", 0.4}}},
                                         {"offset", {{"radius", {0, 0.5}}, {"angle_deg", {0, 360}}}},
                                         {"opacity", {0.5, 1.0}},
                                         {"blend", "add"}});
        });
        if (why.isEmpty()) {
            m_pattern = next;
            fillGenerator();
        }
    });
    connect(m_removePattern, &QPushButton::clicked, this, [this] {
        const int index = m_pattern;
        const QString why = editGenerator(tr("Remove a pattern"), m_removePattern, [&](json& layer, json&) {
            json& list = layer["patterns"];
            if (list.is_array() && index < static_cast<int>(list.size())) list.erase(static_cast<size_t>(index));
        });
        if (why.isEmpty()) {
            m_pattern = std::max(0, index - 1);
            fillGenerator();
        }
    });
}

bool TexturePanel::hasTarget() const {
    if (!m_doc->hasProject() || m_index < 0) return false;
    const Project& p = m_doc->project();
    if (m_kind == Target::Body) return m_index < static_cast<int>(p.bodies.size());
    if (m_kind == Target::Surface) return m_index < static_cast<int>(p.surfaces.size());
    if (m_kind == Target::Scenery) return m_index < static_cast<int>(p.scenery.size());
    return false;
}

std::optional<TextureProject>& TexturePanel::textureSlot(Project& p, Target kind, int index) {
    const auto i = static_cast<size_t>(index);
    if (kind == Target::Body) return p.bodies.at(i).texture;
    if (kind == Target::Surface) return p.surfaces.at(i).texture;
    if (p.sceneryTextures.size() < p.scenery.size()) p.sceneryTextures.resize(p.scenery.size()); // one each
    return p.sceneryTextures.at(i);
}

const TextureProject* TexturePanel::current() const {
    if (!hasTarget()) return nullptr;
    const Project& p = m_doc->project();
    const auto i = static_cast<size_t>(m_index);
    if (m_kind == Target::Scenery)
        return i < p.sceneryTextures.size() && p.sceneryTextures[i] ? &*p.sceneryTextures[i] : nullptr;
    const std::optional<TextureProject>& t = m_kind == Target::Body ? p.bodies[i].texture : p.surfaces[i].texture;
    return t ? &*t : nullptr;
}

QString TexturePanel::targetName() const {
    if (!hasTarget()) return {};
    const Project& p = m_doc->project();
    const auto i = static_cast<size_t>(m_index);
    return QString::fromStdString(m_kind == Target::Body      ? p.bodies[i].scene.name
                                  : m_kind == Target::Surface ? p.surfaces[i].scene.name
                                                              : p.scenery[i].name);
}

const bake::QuadtreeParams* TexturePanel::chosenQuadtree() const {
    const bake::TextureSpec* spec = parsed();
    if (!spec) return nullptr;
    if (m_layer == 0) return &spec->quadtree;
    return m_layer <= static_cast<int>(spec->layers.size()) ? &spec->layers[static_cast<size_t>(m_layer - 1)].quadtree
                                                            : nullptr;
}

void TexturePanel::chooseLayer(int layer) {
    const bake::TextureSpec* spec = parsed();
    const int layers = spec ? static_cast<int>(spec->layers.size()) : 0;
    layer = std::clamp(layer, 0, layers);
    if (layer == m_layer) return;
    m_layer = layer;
    m_pattern = 0;
    m_lastSource = nullptr;
    fillGenerator();
    regenerateThumbnails();
}

QString TexturePanel::addLayer() {
    const bake::TextureSpec* spec = parsed();
    if (!spec) {
        setStatus(tr("the selection has no readable generator"));
        return m_status->text();
    }
    auto wants = [&](bake::MapKind k) {
        return std::any_of(spec->maps.begin(), spec->maps.end(),
                           [&](const bake::MapRequest& r) { return r.kind == k; });
    };
    json maps = {{"mask", json::object()}};
    if (wants(bake::MapKind::Diffuse)) maps["diffuse"] = json::object(); // the gradient over its palette
    if (wants(bake::MapKind::Roughness)) maps["roughness"] = {{"values", {0.3, 0.7}}};
    if (wants(bake::MapKind::Height) || wants(bake::MapKind::Normal)) maps["height"] = {{"values", {0.2, 0.8}}};
    if (maps.size() == 1) {
        setStatus(tr("the base material makes no diffuse, roughness or height map for a layer to paint"));
        return m_status->text();
    }
    std::string name;
    for (int n = static_cast<int>(spec->layers.size()) + 1; name.empty(); ++n) {
        const std::string candidate = "layer" + std::to_string(n);
        if (std::none_of(spec->layers.begin(), spec->layers.end(),
                         [&](const bake::LayerSpec& l) { return l.name == candidate; }))
            name = candidate;
    }
    const int levels = spec->quadtree.levels;
    json layer = {{"name", name},
                  {"levels", levels},
                  {"opacity", 0.6},
                  {"patterns", json::array({{{"level", std::min(4, levels - 1)},
                                             {"tile", {{"shape", "disc"}}},
                                             {"offset", {{"radius", {0, 0.4}}, {"angle_deg", {0, 360}}}},
                                             {"scale", {{"uniform", {0.3, 0.8}}}},
                                             {"probability", 0.6},
                                             {"blend", "max"}}})},
                  {"maps", maps}};
    const int next = static_cast<int>(spec->layers.size()) + 1;
    const QString why = editGenerator(tr("Add layer '%1'").arg(QString::fromStdString(name)), m_addLayer,
                                      [&](json&, json& root) { root["layers"].push_back(layer); });
    if (why.isEmpty()) {
        m_layer = -1; // chooseLayer() refills
        chooseLayer(next);
    }
    return why;
}

QString TexturePanel::removeLayer() {
    if (m_layer == 0) {
        setStatus(tr("the base material is not a layer: choose a layer to remove"));
        return m_status->text();
    }
    const int index = m_layer - 1;
    const QString why = editGenerator(tr("Remove a layer"), m_removeLayer, [&](json&, json& root) {
        json& list = root["layers"];
        if (!list.is_array() || index >= static_cast<int>(list.size()))
            throw InputError("the chosen layer is not in the spec any more");
        list.erase(static_cast<size_t>(index));
        if (list.empty()) root.erase("layers");
    });
    if (why.isEmpty()) {
        m_layer = -1;
        chooseLayer(index); // the layer before it, or the base
    }
    return why;
}

void TexturePanel::setTarget(Target kind, int index) {
    if (kind == m_kind && index == m_index) return;
    m_kind = kind;
    m_index = index;
    m_layer = 0;
    m_pattern = 0;
    m_lastSource = nullptr;                 // no undo step merges across selections
    m_shownFields = QStringLiteral("\x01"); // refill the fields from the new selection
    setStatus({});
    refresh();
}

void TexturePanel::refresh() {
    const bool target = hasTarget();
    const TextureProject* t = current();
    m_header->setText(!target                     ? tr("Select a body, a fascia surface or a surrounding")
                      : m_kind == Target::Body    ? tr("Body '%1'").arg(targetName())
                      : m_kind == Target::Surface ? tr("Surface '%1'").arg(targetName())
                                                  : tr("Surrounding '%1'").arg(targetName()));
    for (QWidget* w : std::initializer_list<QWidget*>{m_spec, m_tiles, m_normal, m_apply, m_new})
        w->setEnabled(target);
    m_remove->setEnabled(t != nullptr);
    // The fields follow the model when its block changed (an edit, undo, another selection);
    // text being typed survives changes elsewhere in the project.
    const QString fields = !target ? QString()
                           : t     ? QString::fromStdString(t->spec) + "|" + numberText(t->tilesPerMetre) + "|" +
                                     numberText(t->normalStrength) + "|" + QString::fromStdString(t->generator)
                               : QStringLiteral("none");
    if (fields != m_shownFields) {
        m_shownFields = fields;
        const TextureProject defaults;
        m_spec->setText(t ? QString::fromStdString(t->spec) : QString());
        m_spec->setPlaceholderText(t && !t->generator.empty() ? tr("(kept in project.json)")
                                                              : QStringLiteral("textures/organ.json"));
        m_tiles->setText(numberText(t ? t->tilesPerMetre : defaults.tilesPerMetre));
        m_normal->setText(numberText(t ? t->normalStrength : defaults.normalStrength));
        m_parsed.reset();
        QString problem;
        if (t) {
            try {
                m_parsed = loadTextureBlock(*t, m_doc->project().dir, "the texture generator");
            } catch (const std::exception& e) {
                m_parsed.reset();
                problem = QString::fromStdString(e.what());
            }
        }
        m_genSource->setText(!t                      ? tr("No material maps: New generator, or a spec file and Apply")
                             : !problem.isEmpty()    ? problem
                             : !t->generator.empty() ? tr("Kept in project.json; every change is one undo step")
                                                     : tr("From %1: the first change copies it into project.json "
                                                          "(the file stays as it is)")
                                                           .arg(QString::fromStdString(t->spec)));
        m_genSource->setStyleSheet(problem.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
        // an undo may take the chosen layer away: the last one left is chosen
        if (const int layers = m_parsed ? static_cast<int>(m_parsed->layers.size()) : 0; m_layer > layers) {
            m_layer = layers;
            m_pattern = 0;
        }
        fillGenerator();
    }
    if (previewKey() != m_shownKey) regenerateThumbnails();
}

void TexturePanel::fillGenerator() {
    const bake::TextureSpec* spec = parsed();
    const bake::QuadtreeParams* q = chosenQuadtree();
    m_genBox->setEnabled(spec != nullptr && q != nullptr);
    // the fields show the model: setting them is not an edit
    std::vector<QSignalBlocker> blockers;
    for (QObject* o : std::initializer_list<QObject*>{
             m_layerBox,    m_size,      m_seed,         m_levels,       m_tileable,     m_base,       m_patternBox,
             m_pLevel,      m_pShape,    m_pSigma,       m_pRotation.lo, m_pRotation.hi, m_pRadius.lo, m_pRadius.hi,
             m_pAngle.lo,   m_pAngle.hi, m_pWidth.lo,    m_pWidth.hi,    m_pHeight.lo,   m_pHeight.hi, m_pOpacity.lo,
             m_pOpacity.hi, m_pUniform,  m_pProbability, m_pBlend,       m_layerOpacity})
        blockers.emplace_back(o);
    m_layerBox->clear();
    m_layerBox->addItem(tr("base"));
    if (spec)
        for (const bake::LayerSpec& l : spec->layers)
            m_layerBox->addItem(QString::fromStdString(l.name));
    m_layerBox->setCurrentIndex(q ? m_layer : 0);
    m_patternBox->clear();
    if (!spec || !q) return;
    m_size->setCurrentIndex(std::max(0, m_size->findData(spec->quadtree.size)));
    m_size->setEnabled(m_layer == 0);
    m_tileable->setEnabled(m_layer == 0);
    m_removeLayer->setEnabled(m_layer > 0);
    m_addLayer->setEnabled(spec->layers.size() < 8);
    m_layerOpacity->setEnabled(m_layer > 0);
    m_layerOpacity->setValue(m_layer > 0 ? spec->layers[static_cast<size_t>(m_layer - 1)].opacity : 1.0);
    m_seed->setValue(static_cast<int>(std::min<uint64_t>(q->seed, INT_MAX)));
    m_levels->setMaximum(std::countr_zero(static_cast<unsigned>(q->size)) + 1);
    m_levels->setValue(q->levels);
    m_tileable->setChecked(spec->quadtree.tileable);
    m_base->setValue(q->base);
    for (const bake::LevelPattern& p : q->patterns)
        m_patternBox->addItem(tr("level %1 · %2").arg(p.level).arg(kShapes[static_cast<int>(p.tile.shape)]));
    m_pattern = std::clamp(m_pattern, 0, std::max(0, static_cast<int>(q->patterns.size()) - 1));
    m_patternBox->setCurrentIndex(m_pattern);
    m_removePattern->setEnabled(q->patterns.size() > 1);
    if (m_pattern < static_cast<int>(q->patterns.size())) {
        const bake::LevelPattern& p = q->patterns[static_cast<size_t>(m_pattern)];
        m_pLevel->setMaximum(q->levels - 1);
        m_pLevel->setValue(p.level);
        m_pShape->setCurrentIndex(static_cast<int>(p.tile.shape));
        m_pSigma->setValue(p.tile.sigma);
        m_pSigma->setEnabled(p.tile.shape == bake::TileShape::Gaussian);
        auto set = [](const RangeEdit& r, const bake::Range& v) {
            r.lo->setValue(v.lo);
            r.hi->setValue(v.hi);
        };
        set(m_pRotation, p.rotationDeg);
        set(m_pRadius, p.offsetRadius);
        set(m_pAngle, p.offsetAngleDeg);
        set(m_pWidth, p.width);
        set(m_pHeight, p.uniformScale ? p.width : p.height);
        set(m_pOpacity, p.opacity);
        m_pUniform->setChecked(p.uniformScale);
        m_pHeight.lo->setEnabled(!p.uniformScale);
        m_pHeight.hi->setEnabled(!p.uniformScale);
        m_pProbability->setValue(p.probability);
        m_pBlend->setCurrentIndex(static_cast<int>(p.blend));
    }
    fillPaletteColours(*spec);
    m_usePicked->setEnabled(!m_picked.empty() && current() != nullptr);
}

void TexturePanel::fillPaletteColours(const bake::TextureSpec& spec) {
    // the palette's editable colours: explicit ones, or those of the synthetic reference photograph
    while (QLayoutItem* item = m_paletteRow->takeAt(0)) {
        delete item->widget();
        delete item;
    }
    std::vector<bake::Rgb8> colors;
    QString note;
    const bake::LayerSpec* chosen = m_layer > 0 ? &spec.layers[static_cast<size_t>(m_layer - 1)] : nullptr;
    const bool shared = chosen && !chosen->palette;
    if (const std::optional<bake::PaletteSpec>& pal = shared || !chosen ? spec.palette : chosen->palette; !pal) {
        note = tr("No palette (the spec writes no diffuse map)");
    } else if (shared && !pal->colors.empty()) {
        colors = pal->colors;
        note = tr("The layer uses the base material's palette (click a colour to change it there, or Use in layer "
                  "for its own):");
    } else if (!pal->colors.empty()) {
        colors = pal->colors;
        note = tr("Palette colours (click one to change it):");
    } else if (pal->reference) {
        colors = pal->reference->colors;
        note = tr("Colours of the synthetic reference photograph the palette is extracted from (click to change):");
    } else {
        note = tr("Palette extracted from %1 (pick colours from a photo to replace it)")
                   .arg(QString::fromStdString(pal->imageFile));
    }
    m_paletteNote->setText(note);
    for (size_t i = 0; i < colors.size(); ++i) {
        const QString hex = QString::fromStdString(bake::hexColor(colors[i]));
        auto* b = new QToolButton(m_paletteHost);
        b->setObjectName("paletteColour");
        b->setFixedSize(28, 28);
        b->setToolTip(hex);
        b->setStyleSheet(QStringLiteral("background-color: %1; border: 1px solid #404040").arg(hex));
        const bake::Rgb8 c = colors[i];
        connect(b, &QToolButton::clicked, this, [this, i, c] {
            const QColor picked = QColorDialog::getColor(QColor(c.r, c.g, c.b), this, tr("Palette colour"));
            if (picked.isValid())
                setPaletteColor(static_cast<int>(i),
                                {static_cast<uint8_t>(picked.red()), static_cast<uint8_t>(picked.green()),
                                 static_cast<uint8_t>(picked.blue())});
        });
        m_paletteRow->addWidget(b);
    }
    m_paletteRow->addStretch(1);
}

QList<QToolButton*> TexturePanel::paletteButtons() const {
    return m_paletteHost->findChildren<QToolButton*>("paletteColour");
}

std::optional<TextureProject> TexturePanel::previewBlock() const {
    if (!hasTarget()) return std::nullopt;
    const QString typed = m_spec->text().trimmed();
    const TextureProject* t = current();
    if (!typed.isEmpty() && (!t || QString::fromStdString(t->spec) != typed)) {
        TextureProject file; // a spec file typed, not applied yet
        file.spec = typed.toStdString();
        return file;
    }
    if (t) return *t;
    return std::nullopt;
}

QString TexturePanel::previewKey() const {
    const std::optional<TextureProject> block = previewBlock();
    if (!block) return {};
    QString key = QString::number(m_layer) + "|" + QString::fromStdString(block->generator);
    if (block->generator.empty()) {
        const QString file = QString::fromStdString((m_doc->project().dir / block->spec).string());
        // the file's time: an edit of the spec in another program shows on the next change here
        key += file + "|" + QString::number(QFileInfo(file).lastModified().toMSecsSinceEpoch());
    }
    return key;
}

void TexturePanel::setStatus(const QString& error) {
    m_status->setText(error);
    m_status->setStyleSheet(error.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
}

QString TexturePanel::applyFields() {
    if (!hasTarget()) {
        setStatus(tr("select a body, a fascia surface or a surrounding first"));
        return m_status->text();
    }
    QString why;
    const std::optional<double> tiles = parseNumberText(m_tiles->text(), tr("tiles per metre"), why);
    const std::optional<double> strength =
        tiles ? parseNumberText(m_normal->text(), tr("normal strength"), why) : std::nullopt;
    if (!tiles || !strength) {
        setStatus(why);
        return why;
    }
    const TextureProject* old = current();
    TextureProject t;
    t.spec = m_spec->text().trimmed().toStdString();
    if (t.spec.empty() && old) t.generator = old->generator; // the block's generator stays
    t.tilesPerMetre = static_cast<float>(*tiles);
    t.normalStrength = static_cast<float>(*strength);
    if (old && *old == t) {
        setStatus({});
        return {}; // nothing to change: no empty undo step
    }
    if (t.spec.empty() && t.generator.empty()) {
        setStatus(tr("name a spec file, or make a New generator"));
        return m_status->text();
    }
    const Target kind = m_kind;
    const int index = m_index;
    why = m_doc->edit(
        tr("Set the material maps of '%1'").arg(targetName()),
        [&](Project& p) {
            textureSlot(p, kind, index) = t;
            // the project's rules first (the spec path lies inside the project folder, a generator
            // parses), then a spec file must parse: a block the preview and the export cannot bake
            // never enters the model
            if (const QString rule = Document::check(p); !rule.isEmpty()) throw InputError(rule.toStdString());
            if (t.generator.empty()) bake::loadTextureSpec(p.dir / t.spec);
        },
        0, Change{Change::Texture});
    setStatus(why);
    return why;
}

QString TexturePanel::newGenerator() {
    if (!hasTarget()) {
        setStatus(tr("select a body, a fascia surface or a surrounding first"));
        return m_status->text();
    }
    TextureProject t;
    if (const TextureProject* old = current()) {
        t.tilesPerMetre = old->tilesPerMetre;
        t.normalStrength = old->normalStrength;
    }
    t.generator = defaultGenerator(targetName().toStdString()).dump();
    const Target kind = m_kind;
    const int index = m_index;
    const QString why = m_doc->edit(
        tr("New material generator for '%1'").arg(targetName()), [&](Project& p) { textureSlot(p, kind, index) = t; },
        0, Change{Change::Texture});
    setStatus(why);
    return why;
}

QString TexturePanel::removeTexture() {
    if (!current()) {
        setStatus(tr("the selection has no material maps"));
        return m_status->text();
    }
    const Target kind = m_kind;
    const int index = m_index;
    const QString why = m_doc->edit(
        tr("Remove the material maps of '%1'").arg(targetName()),
        [&](Project& p) { textureSlot(p, kind, index).reset(); }, 0, Change{Change::Texture});
    setStatus(why);
    return why;
}

QString TexturePanel::editGenerator(const QString& what, const void* source,
                                    const std::function<void(json& layer, json& root)>& fn) {
    const TextureProject* old = current();
    if (!old) {
        setStatus(tr("the selection has no material maps"));
        return m_status->text();
    }
    TextureProject t;
    json root;
    try {
        t = embedTextureSpec(*old, m_doc->project().dir);
        root = json::parse(t.generator);
        json* layer = layerJson(root, m_layer);
        if (!layer) throw InputError("the chosen layer is not in the spec any more");
        fn(*layer, root);
    } catch (const std::exception& e) {
        setStatus(QString::fromStdString(e.what()));
        fillGenerator(); // the fields show the model again
        return m_status->text();
    }
    t.generator = root.dump();
    if (t == *old) {
        setStatus({});
        return {};
    }
    // a run of changes of one field, nothing else in between, is one undo step
    QUndoStack* undo = m_doc->undoStack();
    if (source != m_lastSource || undo->index() != m_lastUndoIndex || m_lastMergeKey == 0)
        m_lastMergeKey = m_doc->newMergeKey();
    const Target kind = m_kind;
    const int index = m_index;
    const bool embedding = old->generator.empty();
    const QString why = m_doc->edit(
        tr("%1 of '%2'").arg(what, targetName()), [&](Project& p) { textureSlot(p, kind, index) = t; }, m_lastMergeKey,
        Change{Change::Texture});
    if (why.isEmpty()) {
        m_lastSource = source;
        m_lastUndoIndex = undo->index();
        setStatus({});
        if (embedding)
            m_genSource->setText(tr("Copied from %1 into project.json (the file stays as it is); every change is one "
                                    "undo step")
                                     .arg(QString::fromStdString(old->spec)));
    } else {
        m_lastSource = nullptr;
        setStatus(why);
        fillGenerator(); // the refused value leaves the field
    }
    return why;
}

QString TexturePanel::setPaletteColor(int i, bake::Rgb8 color) {
    return editGenerator(tr("Set palette colour %1").arg(i + 1), nullptr, [&](json& layer, json& root) {
        json& pal = layer.contains("palette") ? layer["palette"] : root["palette"]; // a layer may share the base's
        json* list = nullptr;
        if (pal.is_object() && pal.contains("colors"))
            list = &pal["colors"];
        else if (pal.is_object() && pal.contains("reference") && pal["reference"].is_object())
            list = &pal["reference"]["colors"];
        if (!list || !list->is_array() || i < 0 || i >= static_cast<int>(list->size()))
            throw InputError("the palette has no editable colour " + std::to_string(i + 1));
        (*list)[static_cast<size_t>(i)] = bake::hexColor(color);
    });
}

QString TexturePanel::usePickedPalette() {
    if (m_picked.empty()) {
        setStatus(tr("pick a palette from an image first"));
        return m_status->text();
    }
    json colors = json::array();
    for (const bake::PaletteColor& c : m_picked)
        colors.push_back(bake::hexColor(c.color));
    const int n = static_cast<int>(m_picked.size());
    return editGenerator(tr("Use the picked palette"), m_usePicked, [&](json& layer, json&) {
        layer["palette"] = {{"colors", colors}};
        // the reference photograph and its proportional map went with the old palette
        if (layer.contains("maps") && layer["maps"].is_object()) {
            layer["maps"].erase("reference");
            layer["maps"].erase("prominent");
        }
        // diffuse indices beyond the new palette: the gradient over all its colours
        if (layer.contains("maps") && layer["maps"].contains("diffuse")) {
            json& d = layer["maps"]["diffuse"];
            bool fits = true;
            if (d.contains("colors"))
                for (const json& i : d["colors"])
                    fits = fits && i.is_number_integer() && i.get<int>() < n;
            if (!fits) {
                d.erase("colors");
                d.erase("stops");
            }
        }
    });
}

void TexturePanel::regenerateThumbnails() {
    const uint64_t generation = ++m_thumbGeneration;
    m_shownKey = previewKey();
    const std::optional<TextureProject> block = previewBlock();
    if (m_shownKey.isEmpty() || !block) {
        m_thumbPending = false;
        showThumbnails({});
        m_thumbStatus->setText(hasTarget() ? tr("no material maps") : QString());
        m_thumbStatus->setStyleSheet({});
        return;
    }
    const std::filesystem::path dir = m_doc->project().dir;
    const int layer = m_layer;
    m_thumbPending = true;
    m_thumbStatus->setText(tr("generating the thumbnails…"));
    m_thumbStatus->setStyleSheet({});
    // The studio's task type, in process: a newer request supersedes this one (its result dropped).
    m_thumbTask.runInProcess(
        tr("thumbnails"),
        [b = *block, dir, layer]() -> std::any {
            ThumbnailResult r;
            try {
                r.thumbs = makeTextureThumbnails(b, dir, kThumbnailSide, layer);
            } catch (const std::exception& e) {
                r.error = QString::fromStdString(e.what());
            }
            return r;
        },
        [this, generation](std::any result) {
            if (generation != m_thumbGeneration) return;
            m_thumbPending = false;
            const ThumbnailResult r = std::any_cast<ThumbnailResult>(std::move(result));
            showThumbnails(r.thumbs);
            m_thumbStatus->setText(
                r.error.isEmpty()
                    ? tr("%1 × %1 px preview, seed %2").arg(r.thumbs.size).arg(QString::number(r.thumbs.seed))
                    : r.error);
            m_thumbStatus->setStyleSheet(r.error.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
        });
}

void TexturePanel::showThumbnails(const TextureThumbnails& t) {
    m_thumbs = t;
    const QImage* images[4] = {&t.diffuse, &t.roughness, &t.normal, &t.pattern};
    for (int m = 0; m < 4; ++m) {
        QLabel* l = m_thumbLabels[m];
        if (images[m]->isNull()) {
            l->setPixmap({});
            l->setText(t.size > 0 ? tr("not in\nthe spec") : QString());
            l->setToolTip({});
            continue;
        }
        l->setPixmap(QPixmap::fromImage(
            images[m]->scaled(kThumbPx - 4, kThumbPx - 4, Qt::KeepAspectRatio, Qt::SmoothTransformation)));
        l->setToolTip(tr("%1, %2 × %2 px preview").arg(tr(kMapTitles[m])).arg(t.size));
    }
    fillSwatches(m_specSwatches, t.colors, t.shares);
}

void TexturePanel::pickPaletteFrom(const QString& file) {
    bake::PaletteParams params;
    params.method = m_method->currentIndex() == 1 ? bake::PaletteMethod::KMeans : bake::PaletteMethod::Threshold;
    const uint64_t generation = ++m_paletteGeneration;
    m_palettePending = true;
    m_pickStatus->setText(tr("extracting the palette of %1…").arg(QFileInfo(file).fileName()));
    m_pickStatus->setStyleSheet({});
    auto* watcher = new QFutureWatcher<PaletteResult>(this);
    connect(watcher, &QFutureWatcherBase::finished, this, [this, watcher, generation, file] {
        watcher->deleteLater();
        if (generation != m_paletteGeneration) return; // another image was picked meanwhile
        m_palettePending = false;
        const PaletteResult r = watcher->result();
        m_picked = r.colors;
        showPicked();
        m_pickStatus->setText(
            r.error.isEmpty() ? tr("%1 colours of %2").arg(r.colors.size()).arg(QFileInfo(file).fileName()) : r.error);
        m_pickStatus->setStyleSheet(r.error.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
    });
    const std::filesystem::path path = file.toStdString();
    watcher->setFuture(QtConcurrent::run([path, params] {
        PaletteResult r;
        try {
            r.colors = pickPalette(path, params);
        } catch (const std::exception& e) {
            r.error = QString::fromStdString(e.what());
        }
        return r;
    }));
}

void TexturePanel::showPicked() {
    std::vector<bake::Rgb8> colors;
    std::vector<double> shares;
    for (const bake::PaletteColor& c : m_picked) {
        colors.push_back(c.color);
        shares.push_back(c.share);
    }
    fillSwatches(m_pickedSwatches, colors, shares);
    m_copyHex->setEnabled(!m_picked.empty());
    m_usePicked->setEnabled(!m_picked.empty() && current() != nullptr);
}

QString TexturePanel::pickedHexText() const {
    QStringList lines;
    for (const bake::PaletteColor& c : m_picked)
        lines << QString::fromStdString(bake::hexColor(c.color));
    return lines.join('\n');
}

} // namespace viscera::studio
