#pragma once
// Shared by the studio's main-window GUI tests: a fresh main window per test (settings cleared,
// no discard prompt, XDG_CONFIG_HOME in the scratch folder (no publisher key unless a test makes
// one), 1500 × 950, shown and exposed), a scratch copy of a sample project opened
// in it, and the live preview stopped at the end.
#include "app/main_window.hpp"
#include "gui_test_support.hpp"

#include <QSettings>

#include <gtest/gtest.h>

#include <memory>

namespace viscera::test {

struct MainWindowFixture : ::testing::Test {
    Scratch scratch;
    std::unique_ptr<studio::MainWindow> w;

    explicit MainWindowFixture(const std::string& scratchPrefix) : scratch(scratchPrefix) {}

    void SetUp() override {
        guiApp();
        // the publisher key export signs with by default: the test's own folder, never the user's
        std::filesystem::create_directories(scratch.dir / "config");
        qputenv("XDG_CONFIG_HOME", QByteArray::fromStdString((scratch.dir / "config").string()));
        QSettings().clear();
        w = std::make_unique<studio::MainWindow>();
        w->setConfirmDiscard(false);
        w->resize(1500, 950);
        w->show();
        ASSERT_TRUE(QTest::qWaitForWindowExposed(w.get()));
    }
    void TearDown() override {
        w->preview()->stop();
        w.reset();
    }
    /// Opens a scratch copy of projects/<sample>; returns its folder.
    std::filesystem::path open(const std::string& sample) {
        const std::filesystem::path dir = copySample(scratch, sample);
        EXPECT_TRUE(w->openProject(QString::fromStdString(dir.string())));
        return dir;
    }
};

} // namespace viscera::test
