// The main window on a 1920 × 1080 screen [issue 57 item 7] under Xvfb: with every dock open it
// fits the screen's work area (1920 × 1040 where a panel takes 40 px), the status bar is on
// the screen, and a failing action's error is shown in the window (the banner over the viewport),
// not only in the log.
#include "app/error_banner.hpp"
#include "app/viewport.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QDockWidget>
#include <QLabel>
#include <QPlainTextEdit>
#include <QScreen>
#include <QStatusBar>
#include <QToolButton>

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

using namespace viscera;
namespace fs = std::filesystem;

namespace {

struct FitFixture : test::MainWindowFixture {
    FitFixture() : MainWindowFixture("viscera-window-fit-gui") {}
};

std::string text(const QRect& r) {
    return std::to_string(r.x()) + "," + std::to_string(r.y()) + " " + std::to_string(r.width()) + "x" +
           std::to_string(r.height());
}

QRect globalRect(const QWidget* w) {
    return QRect(w->mapToGlobal(QPoint(0, 0)), w->size());
}

} // namespace

TEST_F(FitFixture, EveryDockOpenTheWindowFitsA1080pScreenAndAnErrorIsSeen) {
    open("liver");
    const QRect avail = w->screen()->availableGeometry();
    // a 1920 × 1080 screen's work area; on a taller test screen the same rectangle at its top
    const QRect target = avail.intersected(QRect(avail.topLeft(), QSize(1920, 1040)));
    ASSERT_GE(target.width(), 1920) << "the test needs a screen at least 1920 wide: " << text(avail);
    ASSERT_GE(target.height(), 1040) << "the test needs a screen at least 1040 high: " << text(avail);
    // every dock open, by the View menu's actions (the paint tools' docks included)
    const auto docks = w->findChildren<QDockWidget*>();
    ASSERT_GE(docks.size(), 8);
    for (QDockWidget* d : docks)
        if (!d->toggleViewAction()->isChecked()) d->toggleViewAction()->trigger();
    w->setGeometry(target);
    QTest::qWait(300); // the layout settles
    for (QDockWidget* d : docks) {
        EXPECT_TRUE(d->toggleViewAction()->isChecked()) << d->objectName().toStdString();
        EXPECT_FALSE(d->isFloating()) << d->objectName().toStdString();
    }
    std::printf("screen %s, work area %s; window minimum size hint %dx%d, frame %s\n",
                text(w->screen()->geometry()).c_str(), text(avail).c_str(), w->minimumSizeHint().width(),
                w->minimumSizeHint().height(), text(w->frameGeometry()).c_str());
    EXPECT_LE(w->minimumSizeHint().height(), target.height());
    EXPECT_LE(w->minimumSizeHint().width(), target.width());
    EXPECT_TRUE(target.contains(w->frameGeometry())) << text(w->frameGeometry()) << " in " << text(target);
    QStatusBar* status = w->statusBar();
    EXPECT_TRUE(status->isVisible());
    EXPECT_TRUE(avail.contains(globalRect(status))) << "status bar at " << text(globalRect(status));
    if (std::getenv("VISCERA_GUI_SHOTS")) { // a picture with the liver drawn: meshing and the first frames take a while
        test::waitFor([&] { return w->viewport()->meshCount() > 0 && w->preview()->snapshot().frames > 3; }, 180000);
        QTest::qWait(8000);
    }
    test::saveShot("window_1080_every_dock");

    // a failing action: a project whose project.json is broken; its one line is in the window
    const fs::path bad = scratch.dir / "broken";
    fs::create_directories(bad);
    std::ofstream(bad / "project.json") << "{\"schemaVersion\": 1, \"bodies\": 3}";
    EXPECT_FALSE(w->openProject(QString::fromStdString(bad.string())));
    studio::ErrorBanner* banner = w->errorBanner();
    ASSERT_TRUE(test::waitFor([&] { return banner->isVisible(); }, 2000));
    EXPECT_TRUE(banner->text().contains("project.json")) << banner->text().toStdString();
    EXPECT_TRUE(w->log()->toPlainText().contains(banner->text())) << "the log keeps it too";
    EXPECT_TRUE(avail.contains(globalRect(banner))) << "banner at " << text(globalRect(banner));
    EXPECT_GE(banner->height(), banner->label()->fontMetrics().height()) << "a line of text tall";
    EXPECT_TRUE(target.contains(w->frameGeometry()))
        << "the banner made the window taller: " << text(w->frameGeometry());
    test::saveShot("window_1080_error");
    QTest::mouseClick(banner->closeButton(), Qt::LeftButton);
    EXPECT_FALSE(banner->isVisible());
    EXPECT_EQ(banner->text(), "");
    // an export to a folder that does not exist: refused before the work, shown the same way
    EXPECT_FALSE(w->startExport("/proc/nonexistent/x.vcase", studio::MainWindow::Signing::Unsigned));
    EXPECT_TRUE(banner->isVisible());
    EXPECT_TRUE(banner->text().contains("does not exist")) << banner->text().toStdString();
}
