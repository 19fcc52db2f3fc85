#include "app/texture_panel.hpp"

#include "app/document.hpp"
#include "app/number_text.hpp"
#include "sim/util/error.hpp"

#include <QClipboard>
#include <QComboBox>
#include <QDateTime>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QFutureWatcher>
#include <QGridLayout>
#include <QGuiApplication>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPixmap>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>
#include <bit>
#include <climits>
#include <stdexcept>

namespace viscera::studio {
namespace {

constexpr int kThumbPx = 96;      ///< side of a thumbnail on screen
constexpr int kSwatchColumns = 4; ///< swatches per row
const char* const kMapTitles[3] = {"diffuse", "roughness", "normal"};
constexpr bake::MapKind kMapKinds[3] = {bake::MapKind::Diffuse, bake::MapKind::Roughness, bake::MapKind::Normal};

struct ThumbnailResult {
    TextureThumbnails thumbs;
    QString error;
};

struct PaletteResult {
    std::vector<bake::PaletteColor> colors;
    QString error;
};

/// Replaces the swatches in `row` by one label per colour: the colour as background, its hex
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

} // namespace

TextureThumbnails makeTextureThumbnails(const std::filesystem::path& specFile, std::optional<uint64_t> seed,
                                        int maxSide) {
    if (maxSide < 8 || maxSide > 4096 || !std::has_single_bit(static_cast<unsigned>(maxSide)))
        throw std::invalid_argument("studio::makeTextureThumbnails(): maxSide " + std::to_string(maxSide) +
                                    " is not a power of two in [8, 4096]");
    bake::TextureSpec spec = bake::loadTextureSpec(specFile);
    if (seed) spec.quadtree.seed = *seed;
    if (spec.quadtree.size > maxSide) {
        const double factor = static_cast<double>(maxSide) / spec.quadtree.size;
        spec.quadtree.size = maxSide;
        const int maxLevels = std::bit_width(static_cast<unsigned>(maxSide)); // log2(maxSide) + 1
        spec.quadtree.levels = std::min(spec.quadtree.levels, maxLevels);
        std::erase_if(spec.quadtree.patterns,
                      [&](const bake::LevelPattern& p) { return p.level >= spec.quadtree.levels; });
        spec.material.heightBlurPx *= factor;
    }
    std::vector<bake::MapRequest> maps;
    for (const bake::MapRequest& r : spec.maps)
        if (std::find(std::begin(kMapKinds), std::end(kMapKinds), r.kind) != std::end(kMapKinds))
            maps.push_back({r.kind, 8});
    spec.maps = std::move(maps);

    const bake::TextureSet set = bake::generateTextureSet(spec);
    TextureThumbnails out;
    out.size = spec.quadtree.size;
    out.seed = spec.quadtree.seed;
    out.colors = set.colors;
    for (const bake::PaletteColor& c : set.palette)
        out.shares.push_back(c.share);
    for (const bake::EncodedFile& f : bake::encodeTextureSet(spec, set))
        for (int m = 0; m < 3; ++m)
            if (f.fileName == spec.name + "_" + std::string(bake::mapName(kMapKinds[m])) + ".png") {
                QImage img = QImage::fromData(reinterpret_cast<const uchar*>(f.bytes.data()),
                                              static_cast<int>(f.bytes.size()), "PNG");
                (m == 0 ? out.diffuse : m == 1 ? out.roughness : out.normal) = std::move(img);
            }
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
    m_header = new QLabel(this);
    m_header->setObjectName("textureHeader");
    root->addWidget(m_header);

    auto* form = new QFormLayout;
    m_spec = new QLineEdit(this);
    m_spec->setObjectName("textureSpec");
    m_spec->setPlaceholderText("textures/organ.json");
    m_spec->setToolTip(tr("The texture spec file, relative to the project folder (it must lie inside it)"));
    m_tiles = new QLineEdit(this);
    m_tiles->setObjectName("textureTilesPerMetre");
    m_tiles->setToolTip(tr("How many times the maps repeat per metre of the surface"));
    m_normal = new QLineEdit(this);
    m_normal->setObjectName("textureNormalStrength");
    m_normal->setToolTip(tr("Scale of the normal map's relief (1: as generated)"));
    form->addRow(tr("Spec file"), m_spec);
    form->addRow(tr("Tiles per metre"), m_tiles);
    form->addRow(tr("Normal strength"), m_normal);
    m_seed = new QSpinBox(this);
    m_seed->setObjectName("textureSeed");
    m_seed->setRange(-1, INT_MAX);
    m_seed->setValue(-1);
    m_seed->setSpecialValueText(tr("the spec's"));
    m_seed->setToolTip(tr("Previews the maps with another seed. The spec file is never written: to keep a seed, "
                          "edit the spec's \"seed\""));
    form->addRow(tr("Preview seed"), m_seed);
    root->addLayout(form);

    auto* buttons = new QHBoxLayout;
    m_apply = new QPushButton(tr("Apply to selection"), this);
    m_apply->setObjectName("textureApply");
    m_remove = new QPushButton(tr("Remove"), this);
    m_remove->setObjectName("textureRemove");
    buttons->addWidget(m_apply);
    buttons->addWidget(m_remove);
    buttons->addStretch(1);
    root->addLayout(buttons);
    m_status = new QLabel(this);
    m_status->setObjectName("textureStatus");
    m_status->setWordWrap(true);
    root->addWidget(m_status);

    auto* grid = new QGridLayout;
    for (int m = 0; m < 3; ++m) {
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
    grid->setColumnStretch(3, 1);
    root->addLayout(grid);
    m_thumbStatus = new QLabel(this);
    m_thumbStatus->setObjectName("thumbnailStatus");
    m_thumbStatus->setWordWrap(true);
    root->addWidget(m_thumbStatus);
    root->addWidget(new QLabel(tr("Palette of the spec"), this));
    m_specSwatchHost = new QWidget(this);
    m_specSwatchHost->setObjectName("specSwatches");
    m_specSwatches = new QGridLayout(m_specSwatchHost);
    m_specSwatches->setContentsMargins(0, 0, 0, 0);
    root->addWidget(m_specSwatchHost);

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
    pickRow->addWidget(m_pick);
    pickRow->addWidget(m_copyHex);
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
    root->addStretch(1);

    connect(m_apply, &QPushButton::clicked, this, [this] { applyFields(); });
    connect(m_remove, &QPushButton::clicked, this, [this] { removeTexture(); });
    for (QLineEdit* f : {m_spec, m_tiles, m_normal})
        connect(f, &QLineEdit::returnPressed, this, [this] { applyFields(); });
    connect(m_seed, &QSpinBox::valueChanged, this, [this](int) { regenerateThumbnails(); });
    connect(m_pick, &QPushButton::clicked, this, [this] {
        const QString dir = m_doc->hasProject() ? m_doc->folder() : QString();
        const QString file = QFileDialog::getOpenFileName(this, tr("Photo to pick a palette from"), dir,
                                                          tr("Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp)"));
        if (!file.isEmpty()) pickPaletteFrom(file);
    });
    connect(m_copyHex, &QPushButton::clicked, this, [this] { QGuiApplication::clipboard()->setText(pickedHexText()); });
    connect(m_doc, &Document::changed, this, &TexturePanel::refresh);
    refresh();
}

TexturePanel::~TexturePanel() = default;

bool TexturePanel::hasTarget() const {
    if (!m_doc->hasProject() || m_index < 0) return false;
    const Project& p = m_doc->project();
    if (m_kind == Target::Body) return m_index < static_cast<int>(p.bodies.size());
    if (m_kind == Target::Surface) return m_index < static_cast<int>(p.surfaces.size());
    return false;
}

const TextureProject* TexturePanel::current() const {
    if (!hasTarget()) return nullptr;
    const Project& p = m_doc->project();
    const std::optional<TextureProject>& t =
        m_kind == Target::Body ? p.bodies[m_index].texture : p.surfaces[m_index].texture;
    return t ? &*t : nullptr;
}

QString TexturePanel::targetName() const {
    if (!hasTarget()) return {};
    const Project& p = m_doc->project();
    return QString::fromStdString(m_kind == Target::Body ? p.bodies[m_index].scene.name
                                                         : p.surfaces[m_index].scene.name);
}

void TexturePanel::setTarget(Target kind, int index) {
    if (kind == m_kind && index == m_index) return;
    m_kind = kind;
    m_index = index;
    m_shownFields = QStringLiteral("\x01"); // refill the fields from the new selection
    setStatus({});
    refresh();
}

void TexturePanel::refresh() {
    const bool target = hasTarget();
    const TextureProject* t = current();
    m_header->setText(!target                  ? tr("Select a body or a fascia surface")
                      : m_kind == Target::Body ? tr("Body '%1'").arg(targetName())
                                               : tr("Surface '%1'").arg(targetName()));
    for (QWidget* w : std::initializer_list<QWidget*>{m_spec, m_tiles, m_normal, m_seed, m_apply})
        w->setEnabled(target);
    m_remove->setEnabled(t != nullptr);
    // The fields follow the model when its block changed (an edit, undo, another selection);
    // text being typed survives changes elsewhere in the project.
    const QString fields =
        !target ? QString()
        : t ? QString::fromStdString(t->spec) + "|" + numberText(t->tilesPerMetre) + "|" + numberText(t->normalStrength)
            : QStringLiteral("none");
    if (fields != m_shownFields) {
        m_shownFields = fields;
        const TextureProject defaults;
        m_spec->setText(t ? QString::fromStdString(t->spec) : QString());
        m_tiles->setText(numberText(t ? t->tilesPerMetre : defaults.tilesPerMetre));
        m_normal->setText(numberText(t ? t->normalStrength : defaults.normalStrength));
    }
    if (previewKey() != m_shownKey) regenerateThumbnails();
}

QString TexturePanel::previewKey() const {
    const QString spec = m_spec->text().trimmed();
    if (!hasTarget() || spec.isEmpty()) return {};
    const QString file = QString::fromStdString((m_doc->project().dir / spec.toStdString()).string());
    // the file's time: an edit of the spec in another program shows on the next change here
    return file + "|" + QString::number(m_seed->value()) + "|" +
           QString::number(QFileInfo(file).lastModified().toMSecsSinceEpoch());
}

void TexturePanel::setStatus(const QString& error) {
    m_status->setText(error);
    m_status->setStyleSheet(error.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
}

QString TexturePanel::applyFields() {
    if (!hasTarget()) {
        setStatus(tr("select a body or a fascia surface first"));
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
    TextureProject t;
    t.spec = m_spec->text().trimmed().toStdString();
    t.tilesPerMetre = static_cast<float>(*tiles);
    t.normalStrength = static_cast<float>(*strength);
    if (const TextureProject* old = current(); old && old->spec == t.spec && old->tilesPerMetre == t.tilesPerMetre &&
                                               old->normalStrength == t.normalStrength) {
        setStatus({});
        return {}; // nothing to change: no empty undo step
    }
    const Target kind = m_kind;
    const int index = m_index;
    why = m_doc->edit(tr("Set the material maps of '%1'").arg(targetName()), [&](Project& p) {
        (kind == Target::Body ? p.bodies[index].texture : p.surfaces[index].texture) = t;
        // the project's rules first (the spec path lies inside the project folder), then the spec
        // must parse: a block the preview and the export cannot bake never enters the model
        if (const QString rule = Document::check(p); !rule.isEmpty()) throw InputError(rule.toStdString());
        bake::loadTextureSpec(p.dir / t.spec);
    });
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
    const QString why = m_doc->edit(tr("Remove the material maps of '%1'").arg(targetName()), [&](Project& p) {
        (kind == Target::Body ? p.bodies[index].texture : p.surfaces[index].texture).reset();
    });
    setStatus(why);
    return why;
}

void TexturePanel::regenerateThumbnails() {
    const uint64_t generation = ++m_thumbGeneration;
    m_shownKey = previewKey();
    if (m_shownKey.isEmpty()) {
        m_thumbPending = false;
        showThumbnails({});
        m_thumbStatus->setText(hasTarget() ? tr("no spec file") : QString());
        m_thumbStatus->setStyleSheet({});
        return;
    }
    const std::filesystem::path file = m_doc->project().dir / m_spec->text().trimmed().toStdString();
    std::optional<uint64_t> seed;
    if (m_seed->value() >= 0) seed = static_cast<uint64_t>(m_seed->value());
    m_thumbPending = true;
    m_thumbStatus->setText(tr("generating the thumbnails…"));
    m_thumbStatus->setStyleSheet({});
    auto* watcher = new QFutureWatcher<ThumbnailResult>(this);
    connect(watcher, &QFutureWatcherBase::finished, this, [this, watcher, generation] {
        watcher->deleteLater();
        if (generation != m_thumbGeneration) return; // superseded by a later request
        m_thumbPending = false;
        const ThumbnailResult r = watcher->result();
        showThumbnails(r.thumbs);
        m_thumbStatus->setText(
            r.error.isEmpty() ? tr("%1 × %1 px preview, seed %2").arg(r.thumbs.size).arg(QString::number(r.thumbs.seed))
                              : r.error);
        m_thumbStatus->setStyleSheet(r.error.isEmpty() ? QString() : QStringLiteral("color: #b00020"));
    });
    watcher->setFuture(QtConcurrent::run([file, seed] {
        ThumbnailResult r;
        try {
            r.thumbs = makeTextureThumbnails(file, seed, kThumbnailSide);
        } catch (const std::exception& e) {
            r.error = QString::fromStdString(e.what());
        }
        return r;
    }));
}

void TexturePanel::showThumbnails(const TextureThumbnails& t) {
    m_thumbs = t;
    const QImage* images[3] = {&t.diffuse, &t.roughness, &t.normal};
    for (int m = 0; m < 3; ++m) {
        QLabel* l = m_thumbLabels[m];
        if (images[m]->isNull()) {
            l->setPixmap({});
            l->setText(t.size > 0 ? tr("not in\nthe spec") : QString());
            l->setToolTip({});
            continue;
        }
        l->setPixmap(QPixmap::fromImage(
            images[m]->scaled(kThumbPx - 4, kThumbPx - 4, Qt::KeepAspectRatio, Qt::SmoothTransformation)));
        l->setToolTip(tr("%1 map, %2 × %2 px preview").arg(tr(kMapTitles[m])).arg(t.size));
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
}

QString TexturePanel::pickedHexText() const {
    QStringList lines;
    for (const bake::PaletteColor& c : m_picked)
        lines << QString::fromStdString(bake::hexColor(c.color));
    return lines.join('\n');
}

} // namespace viscera::studio
