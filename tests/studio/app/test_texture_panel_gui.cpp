// The "Material maps" dock under Xvfb (label gui): the selection's texture block as fields, its
// thumbnails made off the UI thread, typed edits as one undo step that undo restores exactly, a
// spec outside the project folder refused, the generator's parameters edited through the real
// widgets (undo steps, merged arrow steps, refusals, live thumbnails), a new generator, and the
// palette picker with its colours used in the material.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/texture_panel.hpp"
#include "bake/texture.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "render/scene_view.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "window_fixture.hpp"

#include <QCheckBox>
#include <QClipboard>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QGroupBox>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QScrollArea>
#include <QSettings>
#include <QSpinBox>
#include <QToolButton>
#include <QUndoStack>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <set>

namespace {

using namespace viscera;
namespace fs = std::filesystem;

struct TexturePanelFixture : test::MainWindowFixture {
    studio::TexturePanel* panel = nullptr;

    TexturePanelFixture() : MainWindowFixture("viscera-gui-texture") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        panel = w->texturePanel();
        ASSERT_NE(panel, nullptr);
    }
    int bodyIndex(const std::string& name) const {
        const auto& bodies = w->document()->project().bodies;
        for (size_t i = 0; i < bodies.size(); ++i)
            if (bodies[i].scene.name == name) return static_cast<int>(i);
        return -1;
    }
    bool waitForThumbnails() {
        return test::waitFor([&] { return !panel->thumbnailsPending() && !panel->thumbnails().diffuse.isNull(); },
                             180000);
    }
    std::string text() const { return studio::projectJsonText(w->document()->project()); }
    void type(QLineEdit* field, const QString& value) {
        field->setFocus();
        field->selectAll();
        QTest::keyClicks(field, value);
        QTest::keyClick(field, Qt::Key_Return);
    }
};

/// Distinct colours of a label's pixmap (1: a uniform image).
size_t distinctColours(const QLabel* label) {
    const QImage img = label->pixmap().toImage();
    std::set<QRgb> seen;
    for (int y = 0; y < img.height(); y += 2)
        for (int x = 0; x < img.width(); x += 2)
            seen.insert(img.pixel(x, y));
    return seen.size();
}

QList<QLabel*> swatches(QWidget* host) {
    return host->findChildren<QLabel*>("swatch");
}

/// A 96 × 64 image of three vertical bands of exact colours.
fs::path threeColourImage(const fs::path& dir) {
    bake::Rgb8Image img;
    img.width = 96;
    img.height = 64;
    const bake::Rgb8 colours[3] = {{200, 30, 40}, {30, 160, 60}, {20, 40, 190}};
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const bake::Rgb8 c = colours[x / 32];
            img.pixels.insert(img.pixels.end(), {c.r, c.g, c.b});
        }
    const fs::path file = dir / "three.png";
    writeFileAtomic(file, bake::encodePng(img));
    return file;
}

TEST_F(TexturePanelFixture, ShowsTheOrgansMapsAndEditsTheBlockAsOneUndoStep) {
    const fs::path dir = open("liver");
    ASSERT_NE(w->findChild<QDockWidget*>("textureDock"), nullptr);
    const int organ = bodyIndex("organ");
    ASSERT_GE(organ, 0);
    w->selectBody(organ);
    EXPECT_EQ(panel->specField()->text(), "textures/organ.json");
    EXPECT_EQ(panel->tilesField()->text(), "20");
    EXPECT_EQ(panel->normalField()->text(), "1");
    EXPECT_TRUE(panel->removeButton()->isEnabled());

    // thumbnails, made off the UI thread: real images, not one flat colour
    ASSERT_TRUE(waitForThumbnails()) << panel->thumbnailStatus()->text().toStdString();
    EXPECT_EQ(panel->thumbnails().size, studio::TexturePanel::kThumbnailSide);
    for (int m = 0; m < 3; ++m) {
        const QLabel* l = panel->thumbnailLabel(m);
        ASSERT_FALSE(l->pixmap().isNull()) << m;
        EXPECT_GT(distinctColours(l), 10u) << m;
    }
    const auto specSwatches = swatches(panel->specSwatches());
    // organ.json's palette: four colours extracted from its synthetic reference photograph
    const bake::TextureSet full = bake::generateTextureSet(bake::loadTextureSpec(dir / "textures/organ.json"));
    ASSERT_EQ(specSwatches.size(), 4);
    ASSERT_EQ(full.colors.size(), 4u);
    const QString first = QString::fromStdString(bake::hexColor(full.colors[0]));
    EXPECT_EQ(specSwatches[0]->text(), first);
    EXPECT_TRUE(specSwatches[0]->toolTip().contains(first));

    // tiles per metre typed + Enter: one undo step; undo restores the project text exactly
    QUndoStack* undo = w->document()->undoStack();
    const std::string before = text();
    const int steps = undo->count();
    type(panel->tilesField(), "35");
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty()) << panel->statusLabel()->text().toStdString();
    ASSERT_EQ(undo->count(), steps + 1);
    ASSERT_TRUE(w->document()->project().bodies[organ].texture);
    EXPECT_EQ(w->document()->project().bodies[organ].texture->tilesPerMetre, 35.0f);
    EXPECT_NE(text(), before);
    undo->undo();
    EXPECT_EQ(text(), before);
    EXPECT_EQ(panel->tilesField()->text(), "20"); // the field follows the model
    // Enter again with nothing changed: no empty undo step
    type(panel->tilesField(), "20");
    EXPECT_EQ(undo->index(), steps);

    // a spec outside the project folder (a real, valid spec) is refused; the model is unchanged
    fs::create_directories(scratch.dir / "outside");
    fs::copy_file(dir / "textures" / "organ.json", scratch.dir / "outside" / "organ.json");
    for (const QString& bad : {QString("../outside/organ.json"),
                               QString::fromStdString((scratch.dir / "outside" / "organ.json").string())}) {
        type(panel->specField(), bad);
        const QString why = panel->statusLabel()->text();
        EXPECT_FALSE(why.isEmpty()) << bad.toStdString();
        EXPECT_FALSE(why.contains('\n')) << why.toStdString();
        EXPECT_TRUE(why.contains("spec")) << why.toStdString();
        EXPECT_EQ(undo->index(), steps);
        EXPECT_EQ(text(), before);
    }
    // a spec inside the folder that does not exist: refused by the spec reader
    type(panel->specField(), "textures/missing.json");
    EXPECT_TRUE(panel->statusLabel()->text().contains("missing.json")) << panel->statusLabel()->text().toStdString();
    EXPECT_EQ(text(), before);
    type(panel->specField(), "textures/organ.json");
    EXPECT_EQ(undo->index(), steps); // back to the model's value: nothing to apply
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty());

    // Remove: one step, undone exactly
    panel->removeButton()->click();
    EXPECT_EQ(undo->index(), steps + 1);
    EXPECT_FALSE(w->document()->project().bodies[organ].texture);
    EXPECT_FALSE(panel->removeButton()->isEnabled());
    undo->undo();
    EXPECT_EQ(text(), before);
    EXPECT_TRUE(panel->removeButton()->isEnabled());

    // the fascia surface shows its own block
    w->selectSurface(0);
    EXPECT_EQ(panel->specField()->text(), "textures/fascia.json");
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_EQ(swatches(panel->specSwatches()).size(), 3);
    EXPECT_EQ(text(), before);
}

/// The organ's block as the model holds it, its generator parsed (null when it names a file).
nlohmann::json generatorOf(const studio::Project& p, int body) {
    const auto& t = p.bodies[body].texture;
    return t && !t->generator.empty() ? nlohmann::json::parse(t->generator) : nlohmann::json();
}

/// The mean of blue minus red over the organ's diffuse-map texels in the preview's scene, in
/// [-1, 1] (nullopt when it has no maps yet).
std::optional<double> organBlueness(studio::MainWindow& w) {
    const auto view = w.preview()->sceneView();
    if (!view) return std::nullopt;
    for (const render::RenderMesh& m : view->meshes()) {
        if (m.name != "organ") continue;
        const auto& maps = view->materials().at(m.material).maps;
        if (!maps || maps->diffuse.empty()) return std::nullopt;
        double sum = 0;
        const size_t n = maps->diffuse.rgba.size() / 4;
        for (size_t i = 0; i < n; ++i)
            sum += (static_cast<double>(maps->diffuse.rgba[4 * i + 2]) - maps->diffuse.rgba[4 * i]) / 255.0;
        return sum / static_cast<double>(n);
    }
    return std::nullopt;
}

/// `value` typed into a spin box, then Enter: one edit.
void typeSpin(QAbstractSpinBox* box, const QString& value) {
    box->setFocus();
    box->selectAll();
    QTest::keyClicks(box, value);
    QTest::keyClick(box, Qt::Key_Return);
}

/// organBlueness() of the organ's diffuse map as the export bakes it from `p`.
double bakedOrganBlueness(const studio::Project& p) {
    for (const auto& [path, bytes] : studio::bakeProjectTextures(p).files) {
        if (path != "textures/organ_diffuse.png") continue;
        const bake::DecodedImage im = bake::decodeImage(bytes, path);
        const double top = im.bits == 16 ? 65535.0 : 255.0;
        double sum = 0;
        const size_t n = im.samples.size() / static_cast<size_t>(im.channels);
        for (size_t i = 0; i < n; ++i)
            sum += (im.samples[i * im.channels + 2] - static_cast<double>(im.samples[i * im.channels])) / top;
        return sum / static_cast<double>(n);
    }
    return -9;
}

TEST_F(TexturePanelFixture, GeneratorParametersAreUndoableEditsOfTheModelWithLiveThumbnails) {
    const fs::path dir = open("liver");
    const std::string specBytes = readFile(dir / "textures" / "organ.json");
    const int organ = bodyIndex("organ");
    w->selectBody(organ);
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_EQ(panel->thumbnails().seed, 11u); // the spec's
    EXPECT_TRUE(panel->generatorBox()->isEnabled());
    EXPECT_EQ(panel->seedBox()->value(), 11);
    EXPECT_EQ(panel->levelsBox()->value(), 7);
    EXPECT_EQ(panel->patternBox()->count(), 3);
    const QImage firstDiffuse = panel->thumbnails().diffuse;
    const QImage firstPattern = panel->thumbnails().pattern;
    ASSERT_FALSE(firstPattern.isNull());
    QUndoStack* undo = w->document()->undoStack();
    const std::string before = text();
    ASSERT_EQ(undo->count(), 0);

    // typed seed + Enter: the spec is copied into project.json (the file stays) as one undo step
    typeSpin(panel->seedBox(), "5");
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty()) << panel->statusLabel()->text().toStdString();
    ASSERT_EQ(undo->count(), 1);
    nlohmann::json g = generatorOf(w->document()->project(), organ);
    ASSERT_TRUE(g.is_object());
    EXPECT_EQ(g["seed"], 5);
    EXPECT_EQ(g["name"], "liver_organ");
    EXPECT_TRUE(w->document()->project().bodies[organ].texture->spec.empty());
    EXPECT_TRUE(panel->specField()->text().isEmpty());
    EXPECT_EQ(readFile(dir / "textures" / "organ.json"), specBytes);
    // three arrow steps of the same field merge into that step; the thumbnails follow, made off
    // the UI thread, each request superseding the one before
    const uint64_t generation = panel->thumbnailGeneration();
    for (int k = 0; k < 3; ++k)
        QTest::keyClick(panel->seedBox(), Qt::Key_Up);
    EXPECT_EQ(undo->count(), 1);
    EXPECT_EQ(generatorOf(w->document()->project(), organ)["seed"], 8);
    EXPECT_GE(panel->thumbnailGeneration(), generation + 3);
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_EQ(panel->thumbnails().seed, 8u);
    EXPECT_NE(panel->thumbnails().diffuse, firstDiffuse);
    EXPECT_NE(panel->thumbnails().pattern, firstPattern);

    // a pattern's fields: the opacity range's upper end typed, the blend mode by keyboard
    panel->patternBox()->setFocus();
    QTest::keyClick(panel->patternBox(), Qt::Key_Down); // level 5 · bell
    ASSERT_EQ(panel->patternIndex(), 1);
    EXPECT_EQ(panel->patternLevelBox()->value(), 5);
    EXPECT_EQ(panel->shapeBox()->currentText(), "bell");
    EXPECT_TRUE(panel->uniformBox()->isChecked());
    EXPECT_DOUBLE_EQ(panel->opacityEdit().hi->value(), 0.7);
    typeSpin(panel->opacityEdit().hi, "0.4");
    ASSERT_EQ(undo->count(), 2);
    g = generatorOf(w->document()->project(), organ);
    EXPECT_EQ(g["patterns"][1]["opacity"], nlohmann::json::parse("[0.25, 0.4]"));
    const std::string blendBefore = g["patterns"][1]["blend"];
    panel->blendBox()->setFocus();
    QTest::keyClick(panel->blendBox(), Qt::Key_Down);
    ASSERT_EQ(undo->count(), 3);
    g = generatorOf(w->document()->project(), organ);
    EXPECT_NE(g["patterns"][1]["blend"], blendBefore);
    EXPECT_EQ(g["patterns"][1]["blend"], panel->blendBox()->currentData().toString().toStdString());

    // refused by the spec reader with its one-line message; model and fields unchanged
    const std::string accepted = text();
    typeSpin(panel->rotationEdit().lo, "300"); // above the upper end, 360 → fine
    typeSpin(panel->rotationEdit().hi, "100"); // [300, 100]: not an interval
    QString why = panel->statusLabel()->text();
    EXPECT_TRUE(why.contains("rotation_deg") && why.contains("not an interval")) << why.toStdString();
    EXPECT_FALSE(why.contains('\n'));
    EXPECT_DOUBLE_EQ(panel->rotationEdit().hi->value(), 360.0); // the field shows the model again
    undo->undo();                                               // the accepted lower end
    EXPECT_EQ(text(), accepted);
    const int steps = undo->index();
    typeSpin(panel->levelsBox(), "4"); // the level-5 and level-6 patterns do not fit
    why = panel->statusLabel()->text();
    EXPECT_TRUE(why.contains("level")) << why.toStdString();
    EXPECT_EQ(undo->index(), steps);
    EXPECT_EQ(text(), accepted);
    EXPECT_EQ(panel->levelsBox()->value(), 7);

    // add and remove a pattern: one step each
    QTest::mouseClick(panel->addPatternButton(), Qt::LeftButton);
    ASSERT_EQ(undo->index(), steps + 1);
    g = generatorOf(w->document()->project(), organ);
    ASSERT_EQ(g["patterns"].size(), 4u);
    EXPECT_EQ(g["patterns"][3]["level"], 0); // the first level without a pattern
    EXPECT_EQ(panel->patternIndex(), 3);
    EXPECT_EQ(panel->patternBox()->count(), 4);
    QTest::mouseClick(panel->removePatternButton(), Qt::LeftButton);
    EXPECT_EQ(generatorOf(w->document()->project(), organ)["patterns"].size(), 3u);
    EXPECT_EQ(text(), accepted);

    // a palette colour: the synthetic reference photograph's first colour
    ASSERT_TRUE(test::waitFor([&] { return organBlueness(*w).has_value(); }, 180000));
    const double reddish = *organBlueness(*w);
    EXPECT_LT(reddish, -0.2); // the liver's reds
    ASSERT_EQ(panel->paletteButtons().size(), 4);
    EXPECT_TRUE(panel->setPaletteColor(0, {20, 30, 200}).isEmpty());
    g = generatorOf(w->document()->project(), organ);
    EXPECT_EQ(g["palette"]["reference"]["colors"][0], "#141ec8");
    EXPECT_FALSE(panel->setPaletteColor(9, {0, 0, 0}).isEmpty()); // no tenth colour
    // the viewport's scene gets the new maps on the meshes already built, those the export bakes:
    // the organ turns bluer (the blue ground is one of the k-means palette's four colours)
    const double expected = bakedOrganBlueness(w->document()->project());
    EXPECT_GT(expected, reddish + 0.01);
    EXPECT_TRUE(test::waitFor([&] { return std::abs(organBlueness(*w).value_or(-9) - expected) < 1e-6; }, 180000))
        << reddish << " -> " << organBlueness(*w).value_or(-9) << ", baked " << expected;
    QDockWidget* dock = w->findChild<QDockWidget*>("textureDock");
    ASSERT_NE(dock, nullptr);
    dock->raise();
    w->resizeDocks({dock}, {620}, Qt::Horizontal);
    if (auto* scroll = qobject_cast<QScrollArea*>(dock->widget()))
        scroll->ensureWidgetVisible(panel->thumbnailLabel(0));
    QTest::qWait(300);
    test::saveShot("texture_generator");

    // the export bakes what the model holds; Save writes it into project.json and it reads back
    ASSERT_TRUE(waitForThumbnails());
    const studio::ProjectTextures baked = studio::bakeProjectTextures(w->document()->project());
    ASSERT_FALSE(baked.files.empty());
    EXPECT_EQ(baked.files[0].first, "textures/organ_diffuse.png");
    w->document()->save();
    const std::string saved = readFile(dir / "project.json");
    EXPECT_NE(saved.find("\"generator\""), std::string::npos);
    EXPECT_EQ(studio::projectJsonText(studio::loadProject(dir)), text());
    EXPECT_EQ(readFile(dir / "textures" / "organ.json"), specBytes);

    // undo all the way: the file-backed block exactly as opened
    while (undo->canUndo())
        undo->undo();
    EXPECT_EQ(text(), before);
    EXPECT_EQ(panel->specField()->text(), "textures/organ.json");
    EXPECT_EQ(panel->seedBox()->value(), 11);

    // the direct function: a file block, size capped
    studio::TextureProject file;
    file.spec = "textures/organ.json";
    const studio::TextureThumbnails t = studio::makeTextureThumbnails(file, dir, 64);
    EXPECT_EQ(t.size, 64);
    EXPECT_EQ(t.diffuse.width(), 64);
    EXPECT_EQ(t.colors.size(), 4u);

    // a broken spec file typed in the field: one line in the panel
    writeFileAtomic(dir / "textures" / "broken.json", "{\"name\": 3}");
    panel->specField()->setText("textures/broken.json");
    panel->regenerateThumbnails();
    ASSERT_TRUE(test::waitFor([&] { return !panel->thumbnailsPending(); }, 60000));
    why = panel->thumbnailStatus()->text();
    EXPECT_TRUE(why.contains("broken.json")) << why.toStdString();
    EXPECT_FALSE(why.contains('\n'));
    EXPECT_TRUE(panel->thumbnails().diffuse.isNull());
}

TEST_F(TexturePanelFixture, NewGeneratorGivesAnUntexturedBodyMapsInOneUndoStep) {
    open("tissue-slab");
    w->selectBody(0);
    EXPECT_FALSE(panel->generatorBox()->isEnabled());
    EXPECT_FALSE(panel->removeButton()->isEnabled());
    const std::string before = text();
    QTest::mouseClick(panel->newButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty()) << panel->statusLabel()->text().toStdString();
    ASSERT_EQ(w->document()->undoStack()->count(), 1);
    ASSERT_TRUE(w->document()->project().bodies[0].texture);
    EXPECT_FALSE(w->document()->project().bodies[0].texture->generator.empty());
    EXPECT_TRUE(panel->generatorBox()->isEnabled());
    ASSERT_TRUE(waitForThumbnails()) << panel->thumbnailStatus()->text().toStdString();
    for (int m = 0; m < 4; ++m)
        EXPECT_GT(distinctColours(panel->thumbnailLabel(m)), 10u) << m;
    EXPECT_EQ(panel->paletteButtons().size(), 3);
    const QImage basePattern = panel->thumbnails().pattern;

    // a sub-layer [A Fig. 6.8]: Add layer is one step and chooses it; its fields edit layers[0]
    QUndoStack* undo = w->document()->undoStack();
    EXPECT_FALSE(panel->removeLayerButton()->isEnabled());
    EXPECT_FALSE(panel->layerOpacityBox()->isEnabled());
    QTest::mouseClick(panel->addLayerButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty()) << panel->statusLabel()->text().toStdString();
    ASSERT_EQ(undo->count(), 2);
    nlohmann::json g = generatorOf(w->document()->project(), 0);
    ASSERT_EQ(g["layers"].size(), 1u);
    EXPECT_EQ(g["layers"][0]["name"], "layer1");
    EXPECT_EQ(panel->layerIndex(), 1);
    EXPECT_EQ(panel->layerBox()->count(), 2);
    EXPECT_EQ(panel->layerBox()->currentText(), "layer1");
    EXPECT_TRUE(panel->removeLayerButton()->isEnabled());
    EXPECT_FALSE(panel->sizeBox()->isEnabled()); // the base's
    EXPECT_DOUBLE_EQ(panel->layerOpacityBox()->value(), 0.6);
    EXPECT_EQ(panel->patternBox()->count(), 1);
    EXPECT_EQ(panel->shapeBox()->currentText(), "disc");
    EXPECT_EQ(panel->paletteButtons().size(), 3); // the base's palette, shared
    ASSERT_TRUE(waitForThumbnails()) << panel->thumbnailStatus()->text().toStdString();
    const QImage layerPattern = panel->thumbnails().pattern;
    EXPECT_NE(layerPattern, basePattern); // the layer's coverage
    const QImage layeredDiffuse = panel->thumbnails().diffuse;
    typeSpin(panel->layerOpacityBox(), "0.3");
    ASSERT_EQ(undo->count(), 3);
    g = generatorOf(w->document()->project(), 0);
    EXPECT_EQ(g["layers"][0]["opacity"], 0.3);
    typeSpin(panel->seedBox(), "41"); // the layer's own seed
    ASSERT_EQ(undo->count(), 4);
    g = generatorOf(w->document()->project(), 0);
    EXPECT_EQ(g["layers"][0]["seed"], 41);
    EXPECT_EQ(g["seed"], 1);
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_NE(panel->thumbnails().pattern, layerPattern);
    EXPECT_NE(panel->thumbnails().diffuse, layeredDiffuse);
    if (QDockWidget* dock = w->findChild<QDockWidget*>("textureDock")) {
        dock->raise();
        w->resizeDocks({dock}, {620}, Qt::Horizontal);
        QTest::qWait(300);
        test::saveShot("texture_layer");
    }
    // a palette colour of the shared palette changes the base's
    EXPECT_TRUE(panel->setPaletteColor(1, {10, 200, 10}).isEmpty());
    g = generatorOf(w->document()->project(), 0);
    EXPECT_EQ(g["palette"]["colors"][1], "#0ac80a");
    EXPECT_FALSE(g["layers"][0].contains("palette"));
    // the layer combo back to the base shows the base's fields
    panel->layerBox()->setCurrentIndex(0);
    EXPECT_EQ(panel->layerIndex(), 0);
    EXPECT_EQ(panel->seedBox()->value(), 1);
    EXPECT_FALSE(panel->layerOpacityBox()->isEnabled());
    // undo to before Add layer: the combo lists the base only and the base is chosen
    panel->layerBox()->setCurrentIndex(1);
    while (undo->index() > 1)
        undo->undo();
    EXPECT_EQ(panel->layerBox()->count(), 1);
    EXPECT_EQ(panel->layerIndex(), 0);
    // Remove layer: one step back to the base
    QTest::mouseClick(panel->addLayerButton(), Qt::LeftButton);
    ASSERT_EQ(panel->layerIndex(), 1);
    const int added = undo->index();
    QTest::mouseClick(panel->removeLayerButton(), Qt::LeftButton);
    EXPECT_EQ(undo->index(), added + 1);
    EXPECT_FALSE(generatorOf(w->document()->project(), 0).contains("layers"));
    EXPECT_EQ(panel->layerIndex(), 0);

    while (undo->canUndo())
        undo->undo();
    EXPECT_EQ(text(), before);
    EXPECT_FALSE(panel->generatorBox()->isEnabled());
}

TEST_F(TexturePanelFixture, PicksThePaletteOfAPhoto) {
    open("liver");
    const fs::path image = threeColourImage(scratch.dir);
    // the core function, without the dialog
    for (const bake::PaletteMethod method : {bake::PaletteMethod::Threshold, bake::PaletteMethod::KMeans}) {
        bake::PaletteParams params;
        params.method = method;
        const std::vector<bake::PaletteColor> colours = studio::pickPalette(image, params);
        ASSERT_EQ(colours.size(), 3u);
        std::set<std::string> hex;
        for (const bake::PaletteColor& c : colours)
            hex.insert(bake::hexColor(c.color));
        EXPECT_EQ(hex, (std::set<std::string>{"#c81e28", "#1ea03c", "#1428be"}));
    }
    EXPECT_THROW(studio::pickPalette(scratch.dir / "none.png", {}), InputError);

    // in the panel: off the UI thread, swatches with their hex values, Copy hex
    w->selectBody(bodyIndex("organ"));
    EXPECT_FALSE(panel->copyHexButton()->isEnabled());
    panel->pickMethod()->setCurrentIndex(1); // k-means
    panel->pickPaletteFrom(QString::fromStdString(image.string()));
    ASSERT_TRUE(test::waitFor([&] { return !panel->palettePending(); }, 60000));
    ASSERT_EQ(panel->pickedPalette().size(), 3u);
    const auto picked = swatches(panel->pickedSwatches());
    ASSERT_EQ(picked.size(), 3);
    for (QLabel* s : picked)
        EXPECT_TRUE(s->text().startsWith('#') && s->text().size() == 7) << s->text().toStdString();
    EXPECT_EQ(panel->pickedHexText().split('\n').size(), 3);
    ASSERT_TRUE(panel->copyHexButton()->isEnabled());
    panel->copyHexButton()->click();
    EXPECT_EQ(QGuiApplication::clipboard()->text(), panel->pickedHexText());
    EXPECT_EQ(w->document()->undoStack()->count(), 0); // picking edits nothing

    // Use in layer: the picked colours become the organ's palette, one undo step; its diffuse
    // gradient named four colours, so it now runs over the three
    ASSERT_TRUE(panel->usePickedButton()->isEnabled());
    QTest::mouseClick(panel->usePickedButton(), Qt::LeftButton);
    EXPECT_TRUE(panel->statusLabel()->text().isEmpty()) << panel->statusLabel()->text().toStdString();
    ASSERT_EQ(w->document()->undoStack()->count(), 1);
    const nlohmann::json g = generatorOf(w->document()->project(), bodyIndex("organ"));
    ASSERT_EQ(g["palette"]["colors"].size(), 3u);
    EXPECT_EQ(g["palette"]["colors"][0], bake::hexColor(panel->pickedPalette()[0].color));
    EXPECT_FALSE(g["maps"]["diffuse"].contains("colors"));
    EXPECT_EQ(panel->paletteButtons().size(), 3);

    ASSERT_TRUE(waitForThumbnails());
    QDockWidget* dock = w->findChild<QDockWidget*>("textureDock");
    ASSERT_NE(dock, nullptr);
    dock->raise();
    w->resizeDocks({dock}, {560}, Qt::Horizontal);
    if (auto* scroll = qobject_cast<QScrollArea*>(dock->widget())) scroll->ensureWidgetVisible(panel->pickedSwatches());
    test::saveShot("texture_panel");
}

} // namespace
