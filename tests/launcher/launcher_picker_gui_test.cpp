// The launcher's picker window under a display (Xvfb in the test step): cases found in a scratch
// folder with their manifest fields and what verified, the selection moved by arrow keys and a
// click, the trainee id typed, and the player command line Start builds (captured, not spawned).
// Tampered, foreign-key, expired and unsigned cases say why on their tiles and cannot be started;
// a player that stops with an error shows its reason. With VISCERA_GUI_SHOTS set, screenshots of
// the picker, the refused tiles and the "no case" window are saved there.
#include "case/case_writer.hpp"
#include "case/signing.hpp"
#include "case_catalog.hpp"
#include "picker_window.hpp"
#include "player_command.hpp"
#include "sim/util/atomic_file.hpp"
#include "support/scratch_dir.hpp"
#include "verify_cache.hpp"

#include <QGuiApplication>
#include <QScreen>
#include <QTest>

#include <gtest/gtest.h>
#include <zip.h>

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

/// Replaces entry `name` of the zip at `path` with `bytes` (libzip), as someone editing a package
/// would: the archive stays valid, the signature no longer covers what it holds.
void replaceEntry(const fs::path& path, const std::string& name, const std::string& bytes) {
    int error = 0;
    zip_t* z = zip_open(path.c_str(), 0, &error);
    ASSERT_NE(z, nullptr) << error;
    const zip_int64_t index = zip_name_locate(z, name.c_str(), 0);
    ASSERT_GE(index, 0) << name;
    zip_source_t* src = zip_source_buffer(z, bytes.data(), bytes.size(), 0);
    ASSERT_NE(src, nullptr);
    ASSERT_EQ(zip_file_replace(z, zip_uint64_t(index), src, 0), 0);
    ASSERT_EQ(zip_close(z), 0);
}

/// manifest.json of the package at `path`, read with libzip.
std::string readEntry(const fs::path& path, const std::string& name) {
    int error = 0;
    zip_t* z = zip_open(path.c_str(), ZIP_RDONLY, &error);
    EXPECT_NE(z, nullptr);
    zip_stat_t st;
    zip_stat(z, name.c_str(), 0, &st);
    std::string out(st.size, '\0');
    zip_file_t* f = zip_fopen(z, name.c_str(), 0);
    zip_fread(f, out.data(), st.size);
    zip_fclose(f);
    zip_discard(z);
    return out;
}

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
        writeCase(scratch.dir, {"slab.vcase", "tissue-slab", "1.0.0", "Tissue slab", &*key, "2099-12-31T23:59:59Z"});
        writeFileAtomic(keys / "site.pub.pem", key->publicPem());
        check.trust.trusted.addKeyFile(keys / "site.pub.pem");
        check.trust.now = 1'796'000'000; // 2026-11-29
        check.trust.stateFolder = scratch.dir / "state";
        std::ofstream(scratch.dir / "broken.vcase") << "not a zip archive";
        std::ofstream(scratch.dir / "notes.txt") << "not a case";
    }
    std::unique_ptr<PickerWindow> openPicker(std::vector<CaseInfo> cases) {
        LaunchSettings settings;
        settings.player = "/opt/test/viscera-player";
        settings.device = "keyboard";
        auto w = std::make_unique<PickerWindow>(PickerContent{std::move(cases), {scratch.dir}}, settings,
                                                [this](const PlayerCommand& c, ExitHandler onExit) {
                                                    launched.push_back(c);
                                                    exits.push_back(std::move(onExit));
                                                    return std::string();
                                                });
        w->resize(1280, 800);
        w->show();
        EXPECT_TRUE(QTest::qWaitForWindowExposed(w.get(), 10000)) << "the picker window was never shown";
        return w;
    }

    test::Scratch scratch{"viscera-launcher"};
    fs::path keys = [this] {
        fs::create_directories(scratch.dir / "keys");
        return scratch.dir / "keys";
    }();
    std::optional<vcase::SigningKey> key;
    Verification check;
    std::vector<PlayerCommand> launched;
    std::vector<ExitHandler> exits;
};

TEST_F(launcherGui, FindsTheCasesWithTheirManifests) {
    const std::vector<CaseInfo> cases = findCases(CaseFolders{{scratch.dir, scratch.dir / "missing"}}, check);
    ASSERT_EQ(cases.size(), 4u); // three cases and the broken file; notes.txt is no case
    EXPECT_EQ(cases[0].title, "Anastomosis, running suture");
    EXPECT_EQ(cases[0].caseId, "anastomosis");
    EXPECT_EQ(cases[0].caseVersion, "2.0.1");
    EXPECT_EQ(cases[0].signer, "site") << "the name of the key trusted here, not the one the package claims";
    EXPECT_TRUE(cases[0].usable()) << cases[0].problem;
    EXPECT_EQ(cases[0].verdict(), "verified: signed by site (" + vcase::keyId(key->publicKey()) + ")");
    EXPECT_EQ(cases[1].title, "Liver palpation");
    EXPECT_EQ(cases[2].title, "Tissue slab");
    EXPECT_EQ(cases[2].description(), "gravity, xpbd · expires 2099-12-31");
    EXPECT_EQ(cases[3].title, "broken"); // the file name, and why it cannot be read
    EXPECT_FALSE(cases[3].usable());
    EXPECT_NE(cases[3].problem.find("broken.vcase"), std::string::npos) << cases[3].problem;
    EXPECT_EQ(cases[3].refusal, "cannot be read");
}

TEST_F(launcherGui, KeysAndClicksChooseTypeAndStart) {
    auto w = openPicker(findCases(CaseFolders{{scratch.dir}}, check));
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

TEST_F(launcherGui, RefusedCasesSayWhyAndCannotBeStartedAndAStoppedPlayerSaysWhy) {
    const fs::path dir = scratch.dir / "mixed";
    fs::create_directories(dir);
    const vcase::SigningKey stranger = vcase::SigningKey::generate();
    writeCase(dir, {"a-genuine.vcase", "genuine", "1.0.0", "A genuine case", &*key, {}});
    // The same case, its manifest edited after signing (a title and a version changed).
    const fs::path edited = writeCase(dir, {"b-edited.vcase", "genuine", "1.0.0", "B edited manifest", &*key, {}});
    std::string manifest = readEntry(edited, "manifest.json");
    manifest.replace(manifest.find("1.0.0"), 5, "9.9.9");
    replaceEntry(edited, "manifest.json", manifest);
    // A file swapped under a signed manifest: only the whole check (cached) tells.
    const fs::path swapped = writeCase(dir, {"c-swapped.vcase", "swapped", "1.0.0", "C swapped scene", &*key, {}});
    replaceEntry(swapped, "scene.json", "[]\n");                                             // same size, other bytes
    writeCase(dir, {"d-foreign.vcase", "foreign", "1.0.0", "D foreign key", &stranger, {}}); // same signer name
    writeCase(dir, {"e-expired.vcase", "expired", "1.0.0", "E expired", &*key, "2020-01-01T00:00:00Z"});
    writeCase(dir, {"f-unsigned.vcase", "unsigned", "1.0.0", "F unsigned", nullptr, {}});

    VerifyCache cache(scratch.dir / "cache.json");
    check.cache = &cache;
    std::vector<CaseInfo> cases = findCases(CaseFolders{{dir}}, check);
    ASSERT_EQ(cases.size(), 6u);
    const std::vector<std::string> refusals{"", "tampered", "tampered", "untrusted key", "expired", "not signed"};
    for (size_t i = 0; i < cases.size(); ++i) {
        EXPECT_EQ(cases[i].refusal, refusals[i]) << cases[i].title << ": " << cases[i].problem;
        EXPECT_EQ(cases[i].usable(), i == 0) << cases[i].title;
        EXPECT_EQ(cases[i].verdict().find('\n'), std::string::npos);
    }
    EXPECT_NE(cases[1].verdict().find("does not match manifest.json"), std::string::npos) << cases[1].verdict();
    EXPECT_NE(cases[2].verdict().find("scene.json: sha256 mismatch"), std::string::npos) << cases[2].verdict();
    EXPECT_NE(cases[3].verdict().find("a key this player does not trust"), std::string::npos) << cases[3].verdict();
    EXPECT_NE(cases[4].verdict().find("the case expired at 2020-01-01"), std::string::npos) << cases[4].verdict();
    // The whole checks were remembered: a second listing reads them back from the cache file.
    VerifyCache reread(scratch.dir / "cache.json");
    ASSERT_TRUE(fs::exists(scratch.dir / "cache.json"));
    check.cache = &reread;
    const std::vector<CaseInfo> again = findCases(CaseFolders{{dir}}, check);
    for (size_t i = 0; i < again.size(); ++i)
        EXPECT_EQ(again[i].refusal, refusals[i]) << again[i].title;

    auto w = openPicker(std::move(cases));
    for (int i = 1; i < 6; ++i) { // every refused tile: Enter and a double click start nothing
        QTest::keyClick(w.get(), Qt::Key_Right);
        ASSERT_EQ(w->selected(), i);
        QTest::keyClick(w.get(), Qt::Key_Return);
        EXPECT_NE(w->status().find("cannot be started: " + refusals[size_t(i)]), std::string::npos) << w->status();
    }
    QTest::mouseDClick(w.get(), Qt::LeftButton, Qt::NoModifier, centre(w->tileRect(3, w->size())));
    EXPECT_TRUE(launched.empty()) << "a refused case was started";
    saveShot(*w, "launcher_refused_tiles");
    // The tiles are drawn with their verdicts: red for the refused, green for the verified.
    const QImage drawn = w->render(w->size());
    auto hasColour = [&](QRect r, QColor c) {
        for (int y = r.top(); y < r.bottom(); ++y)
            for (int x = r.left(); x < r.right(); ++x)
                if (drawn.pixelColor(x, y) == c) return true;
        return false;
    };
    const QRect t0 = w->tileRect(0, w->size()), t1 = w->tileRect(1, w->size());
    EXPECT_TRUE(hasColour(t0.adjusted(20, 78, -20, -40), QColor(90, 200, 120))) << "the verified line is green";
    EXPECT_TRUE(hasColour(t1.adjusted(20, 78, -20, -40), QColor(235, 110, 100))) << "the refusal line is red";

    QTest::keyClick(w.get(), Qt::Key_Home);
    QTest::keyClick(w.get(), Qt::Key_Return);
    ASSERT_EQ(launched.size(), 1u);
    EXPECT_EQ(launched[0].arguments[1], (dir / "a-genuine.vcase").string());
    ASSERT_EQ(exits.size(), 1u);
    exits[0](1, "a-genuine.vcase: scene.json: gravity: must be 3 numbers");
    EXPECT_EQ(w->status(), "A genuine case stopped (exit 1): a-genuine.vcase: scene.json: gravity: must be 3 numbers");
}

TEST_F(launcherGui, AWatchedPlayerHandsBackItsExitAndReason) {
    std::optional<std::pair<int, std::string>> got;
    PlayerCommand c{
        "/bin/sh",
        {"-c", "echo 'session starting'; printf 'viscera-player: x.vcase: not signed\\033[31m\\n' >&2; exit 1"}};
    ASSERT_EQ(launchWatched(c, [&](int code, const std::string& why) { got = {code, why}; }), "");
    ASSERT_TRUE(QTest::qWaitFor([&] { return got.has_value(); }, 10000)) << "the player's exit never came back";
    EXPECT_EQ(got->first, 1);
    EXPECT_EQ(got->second, "x.vcase: not signed [31m") << "the program's name dropped, escapes made inert";
    EXPECT_EQ(exitReason("line 1\nviscera-player: why\n\n"), "why");
    EXPECT_NE(launchWatched({"/nonexistent/viscera-player", {}}, {}), "");
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
