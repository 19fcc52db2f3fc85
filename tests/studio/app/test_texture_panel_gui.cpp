// The "Material maps" dock under Xvfb (label gui): the selection's texture block as fields, its
// thumbnails made off the UI thread, typed edits as one undo step that undo restores exactly, a
// spec outside the project folder refused, the preview seed, and the palette picker.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/texture_panel.hpp"
#include "bake/texture.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "window_fixture.hpp"

#include <QClipboard>
#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QScrollArea>
#include <QSettings>
#include <QSpinBox>

#include <gtest/gtest.h>

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

TEST_F(TexturePanelFixture, TheSeedPreviewsWithoutWritingAndSupersededRequestsAreDropped) {
    const fs::path dir = open("liver");
    const std::string specBytes = readFile(dir / "textures" / "organ.json");
    w->selectBody(bodyIndex("organ"));
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_EQ(panel->thumbnails().seed, 11u); // the spec's
    const QImage spec = panel->thumbnails().diffuse;
    EXPECT_TRUE(panel->seedBox()->toolTip().contains("never written"));

    const uint64_t generation = panel->thumbnailGeneration();
    panel->seedBox()->setValue(5);
    panel->seedBox()->setValue(6);
    panel->seedBox()->setValue(7); // supersedes 5 and 6
    EXPECT_EQ(panel->thumbnailGeneration(), generation + 3);
    ASSERT_TRUE(waitForThumbnails());
    EXPECT_EQ(panel->thumbnails().seed, 7u);
    EXPECT_NE(panel->thumbnails().diffuse, spec);
    EXPECT_EQ(readFile(dir / "textures" / "organ.json"), specBytes); // the spec stays as it was
    EXPECT_EQ(w->document()->undoStack()->count(), 0);

    // the direct function: seed given, size capped
    const studio::TextureThumbnails t = studio::makeTextureThumbnails(dir / "textures" / "organ.json", 7, 64);
    EXPECT_EQ(t.size, 64);
    EXPECT_EQ(t.diffuse.width(), 64);
    EXPECT_EQ(t.colors.size(), 4u);

    // a broken spec: one line in the panel
    writeFileAtomic(dir / "textures" / "broken.json", "{\"name\": 3}");
    panel->specField()->setText("textures/broken.json");
    panel->regenerateThumbnails();
    ASSERT_TRUE(test::waitFor([&] { return !panel->thumbnailsPending(); }, 60000));
    const QString why = panel->thumbnailStatus()->text();
    EXPECT_TRUE(why.contains("broken.json")) << why.toStdString();
    EXPECT_FALSE(why.contains('\n'));
    EXPECT_TRUE(panel->thumbnails().diffuse.isNull());
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

    ASSERT_TRUE(waitForThumbnails());
    QDockWidget* dock = w->findChild<QDockWidget*>("textureDock");
    ASSERT_NE(dock, nullptr);
    dock->raise();
    w->resizeDocks({dock}, {560}, Qt::Horizontal);
    if (auto* scroll = qobject_cast<QScrollArea*>(dock->widget())) scroll->ensureWidgetVisible(panel->pickedSwatches());
    test::saveShot("texture_panel");
}

} // namespace
