// The launcher's picker window under a display (Xvfb in the test step): cases found in a scratch
// folder with their manifest fields, the selection moved by arrow keys and a click, the trainee id
// typed, and the player command line Start builds (captured, not spawned). With VISCERA_GUI_SHOTS
// set, screenshots of the picker and of the "no case" window are saved there.
#include "case/case_writer.hpp"
#include "case/signing.hpp"
#include "case_catalog.hpp"
#include "picker_window.hpp"
#include "player_command.hpp"
#include "support/scratch_dir.hpp"

#include <QGuiApplication>
#include <QScreen>
#include <QTest>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace viscera::launcher {
namespace {

namespace fs = std::filesystem;

QGuiApplication& app() {
    static int argc = 1;
    static char name[] = "viscera-launcher-gui-test";
    static char* argv[] = {name, nullptr};
    static QGuiApplication* a = new QGuiApplication(argc, argv);
    return *a;
}

struct TestCase {
    std::string file, caseId, version, title;
    const vcase::SigningKey* key = nullptr; ///< null: unsigned
    std::optional<std::string> expires;
};

fs::path writeCase(const fs::path& dir, const TestCase& t) {
    vcase::Manifest header;
    header.caseId = t.caseId;
    header.caseVersion = t.version;
    header.minPlayerVersion = "0.1.0";
    header.title = t.title;
    header.expires = t.expires;
    header.features = {"gravity", "xpbd"};
    vcase::CaseWriter w(header);
    w.addFile("scene.json", "{}\n"); // the launcher reads the manifest only; the scene is never loaded
    if (t.key) w.sign(*t.key, "Training site (test key)");
    const fs::path path = dir / t.file;
    w.write(path);
    return path;
}

void saveShot(PickerWindow& window, const char* name) {
    const char* dir = std::getenv("VISCERA_GUI_SHOTS");
    if (!dir || !*dir) return;
    fs::create_directories(dir);
    QTest::qWait(100);
    QImage img = window.screen() ? window.screen()->grabWindow(window.winId()).toImage() : QImage();
    if (img.isNull()) img = window.render(window.size()); // a platform without screen grabs
    ASSERT_TRUE(img.save(QString::fromStdString((fs::path(dir) / name).string() + ".png")));
}

QPoint centre(const QRect& r) {
    return r.center();
}

class launcherGui : public ::testing::Test {
protected:
    void SetUp() override {
        app();
        key = vcase::SigningKey::generate();
        writeCase(scratch.dir, {"liver.vcase", "liver-palpation", "1.2.0", "Liver palpation", &*key, {}});
        writeCase(scratch.dir, {"anastomosis.vcase", "anastomosis", "2.0.1", "Anastomosis, running suture", &*key, {}});
        writeCase(scratch.dir, {"slab.vcase", "tissue-slab", "1.0.0", "Tissue slab", nullptr, "2099-12-31T23:59:59Z"});
        std::ofstream(scratch.dir / "broken.vcase") << "not a zip archive";
        std::ofstream(scratch.dir / "notes.txt") << "not a case";
    }
    std::unique_ptr<PickerWindow> openPicker(std::vector<CaseInfo> cases) {
        LaunchSettings settings;
        settings.player = "/opt/test/viscera-player";
        settings.device = "keyboard";
        auto w = std::make_unique<PickerWindow>(PickerContent{std::move(cases), {scratch.dir}}, settings,
                                                [this](const PlayerCommand& c) {
                                                    launched.push_back(c);
                                                    return std::string();
                                                });
        w->resize(1280, 800);
        w->show();
        EXPECT_TRUE(QTest::qWaitForWindowExposed(w.get(), 10000)) << "the picker window was never shown";
        return w;
    }

    test::Scratch scratch{"viscera-launcher"};
    std::optional<vcase::SigningKey> key;
    std::vector<PlayerCommand> launched;
};

TEST_F(launcherGui, FindsTheCasesWithTheirManifests) {
    const std::vector<CaseInfo> cases = findCases(CaseFolders{{scratch.dir, scratch.dir / "missing"}});
    ASSERT_EQ(cases.size(), 4u); // three cases and the broken file; notes.txt is no case
    EXPECT_EQ(cases[0].title, "Anastomosis, running suture");
    EXPECT_EQ(cases[0].caseId, "anastomosis");
    EXPECT_EQ(cases[0].caseVersion, "2.0.1");
    EXPECT_EQ(cases[0].signer, "Training site (test key)");
    EXPECT_EQ(cases[1].title, "Liver palpation");
    EXPECT_EQ(cases[2].title, "Tissue slab");
    EXPECT_EQ(cases[2].signer, "");
    EXPECT_EQ(cases[2].description(), "gravity, xpbd · not signed · expires 2099-12-31");
    EXPECT_EQ(cases[3].title, "broken"); // the file name, and why it cannot be read
    EXPECT_FALSE(cases[3].usable());
    EXPECT_NE(cases[3].problem.find("broken.vcase"), std::string::npos) << cases[3].problem;
}

TEST_F(launcherGui, KeysAndClicksChooseTypeAndStart) {
    auto w = openPicker(findCases(CaseFolders{{scratch.dir}}));
    ASSERT_EQ(w->selected(), 0);
    QTest::keyClick(w.get(), Qt::Key_Right);
    EXPECT_EQ(w->selected(), 1);
    QTest::keyClick(w.get(), Qt::Key_Down); // two tiles a row at 1280 pixels
    EXPECT_EQ(w->selected(), 3);
    QTest::keyClick(w.get(), Qt::Key_Down); // the last row: stays
    EXPECT_EQ(w->selected(), 3);
    QTest::keyClick(w.get(), Qt::Key_Up);
    QTest::keyClick(w.get(), Qt::Key_Left);
    EXPECT_EQ(w->selected(), 0);
    QTest::mouseClick(w.get(), Qt::LeftButton, Qt::NoModifier, centre(w->tileRect(2, w->size())));
    EXPECT_EQ(w->selected(), 2);

    for (char c : std::string("trainee-08"))
        QTest::keyClick(w.get(), c);
    QTest::keyClick(w.get(), Qt::Key_Backspace);
    QTest::keyClick(w.get(), '7');
    QTest::keyClick(w.get(), '#'); // refused, said in the status line
    EXPECT_EQ(w->traineeId(), "trainee-07");
    EXPECT_NE(w->status().find("only letters"), std::string::npos) << w->status();

    QTest::keyClick(w.get(), Qt::Key_Return); // the slab
    ASSERT_EQ(launched.size(), 1u);
    std::vector<std::string> expected{"run", (scratch.dir / "slab.vcase").string(), "--device", "keyboard"};
    if (kPlayerHasTraineeOption) expected.insert(expected.end(), {"--trainee", "trainee-07"});
    EXPECT_EQ(launched[0].program, "/opt/test/viscera-player");
    EXPECT_EQ(launched[0].arguments, expected);
    EXPECT_NE(w->status().find("Started Tissue slab for trainee trainee-07"), std::string::npos) << w->status();

    QTest::keyClick(w.get(), Qt::Key_End); // the broken package: not started, said why
    QTest::keyClick(w.get(), Qt::Key_Enter);
    EXPECT_EQ(launched.size(), 1u);
    EXPECT_NE(w->status().find("cannot be started"), std::string::npos) << w->status();

    QTest::keyClick(w.get(), Qt::Key_Home);
    QTest::keyClick(w.get(), Qt::Key_Right);
    saveShot(*w, "launcher_picker");
    // The selected tile has the accent border (drawn, not only remembered).
    const QImage drawn = w->render(w->size());
    const QRect sel = w->tileRect(1, w->size());
    EXPECT_EQ(drawn.pixelColor(sel.left() + 3, sel.center().y()), QColor(90, 200, 120));
    QTest::mouseClick(w.get(), Qt::LeftButton, Qt::NoModifier, centre(w->startButtonRect(w->size())));
    ASSERT_EQ(launched.size(), 2u);
    EXPECT_EQ(launched[1].arguments[1], (scratch.dir / "liver.vcase").string());

    QTest::keyClick(w.get(), Qt::Key_Escape);
    EXPECT_FALSE(w->isVisible());
}

TEST_F(launcherGui, SaysSoWhenNoCaseIsFound) {
    auto w = openPicker({});
    EXPECT_EQ(w->selected(), -1);
    QTest::keyClick(w.get(), Qt::Key_Down);
    QTest::keyClick(w.get(), Qt::Key_Return);
    EXPECT_TRUE(launched.empty());
    EXPECT_EQ(w->status(), "There is no case to start.");
    saveShot(*w, "launcher_no_cases");
}

TEST(launcherCommand, BuildsThePlayerCommandLine) {
    LaunchSettings s;
    s.device = "console:10.0.0.2:9000";
    s.pairingKey = "/etc/viscera/pairing.key";
    const PlayerCommand c = playerCommand(s, "/usr/share/viscera/samples/liver.vcase", "nurse.1");
    std::vector<std::string> expected{"run",           "/usr/share/viscera/samples/liver.vcase",
                                      "--device",      "console:10.0.0.2:9000",
                                      "--pairing-key", "/etc/viscera/pairing.key"};
    if (kPlayerHasTraineeOption) expected.insert(expected.end(), {"--trainee", "nurse.1"});
    EXPECT_EQ(c.program, "viscera-player");
    EXPECT_EQ(c.arguments, expected);
    EXPECT_EQ(traineeIdProblem(""), "the trainee id is empty");
    EXPECT_EQ(traineeIdProblem("a b"), "the trainee id may hold only letters, digits and . _ - @");
    EXPECT_EQ(traineeIdProblem(std::string(65, 'x')), "the trainee id has 65 characters, more than 64");
    EXPECT_EQ(traineeIdProblem("x@site-2_b.c"), "");
}

} // namespace
} // namespace viscera::launcher
