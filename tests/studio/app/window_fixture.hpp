#pragma once
// Shared by the studio's main-window GUI tests: a fresh main window per test (settings cleared,
// no discard prompt, XDG_CONFIG_HOME in the scratch folder (no publisher key unless a test makes
// one), 1500 × 950, shown and exposed), a scratch copy of a sample project opened
// in it, and the live preview stopped at the end.
#include "app/main_window.hpp"
#include "app/viewport.hpp"
#include "gui_test_support.hpp"

#include <QApplication>
#include <QContextMenuEvent>
#include <QFileDialog>
#include <QLineEdit>
#include <QMenu>
#include <QSettings>
#include <QTimer>
#include <QTreeWidget>

#include <gtest/gtest.h>

#include <functional>
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
    /// A left click on the viewport at `at` as a user does (its embedded window or its widget).
    void viewportClick(QPoint at) {
        if (QWindow* win = w->viewport()->canvasWindow()) {
            QTest::mousePress(win, Qt::LeftButton, {}, at);
            QTest::mouseRelease(win, Qt::LeftButton, {}, at);
        } else {
            click(w->viewport()->canvasWidget(), at);
        }
        QCoreApplication::processEvents();
    }
    /// A drag on the viewport with `button` (left: paint or pick, right: orbit, middle: pan) from
    /// `from` to `to` in 30 moves.
    /// Opens `item`'s context menu in `tree` as a right click does, triggers the entry whose
    /// object name is `trigger` (none: only looks) and closes the menu; returns the entries' texts.
    static QStringList contextMenu(QTreeWidget* tree, QTreeWidgetItem* item, const char* trigger = nullptr) {
        QStringList shown;
        QTimer::singleShot(0, tree, [&] {
            test::waitFor([] { return QApplication::activePopupWidget() != nullptr; }, 2000);
            if (auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget())) {
                for (QAction* a : menu->actions())
                    shown << a->text();
                for (QAction* a : menu->actions())
                    if (trigger && a->objectName() == trigger) a->trigger();
                menu->close();
            }
        });
        const QPoint at = tree->visualItemRect(item).center();
        QContextMenuEvent menuEvent(QContextMenuEvent::Mouse, at, tree->viewport()->mapToGlobal(at));
        QApplication::sendEvent(tree->viewport(), &menuEvent);
        return shown;
    }
    void viewportDrag(QPoint from, QPoint to, Qt::MouseButton button = Qt::LeftButton) {
        if (QWindow* win = w->viewport()->canvasWindow()) {
            QTest::mousePress(win, button, {}, from);
            for (int i = 1; i <= 30; ++i)
                QTest::mouseMove(win, from + (to - from) * i / 30);
            QTest::mouseRelease(win, button, {}, to);
        } else {
            drag(w->viewport()->canvasWidget(), from, to, 30, button);
        }
        QCoreApplication::processEvents();
    }
    /// The next modal file dialog gets `path` typed into its name field and Enter; `trigger` opens
    /// it (and runs the dialog's loop until the keys accept it).
    void typeIntoFileDialog(const QString& path, const std::function<void()>& trigger) {
        QTimer typer;
        QObject::connect(&typer, &QTimer::timeout, [&] {
            auto* dlg = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
            if (!dlg || !dlg->isVisible()) return;
            typer.stop();
            auto* name = dlg->findChild<QLineEdit*>("fileNameEdit");
            name->clear();
            QTest::keyClicks(name, path);
            QTest::keyClick(name, Qt::Key_Return);
        });
        typer.start(100);
        trigger();
        EXPECT_FALSE(typer.isActive()) << "no file dialog appeared";
    }
    /// A viewport position over a drawn surface whose mesh is named `name` (empty: any), on a
    /// 20 × 20 grid; (-1, -1): none.
    QPoint over(const QString& name = {}) const {
        const studio::Viewport* v = w->viewport();
        for (int y = v->height() / 10; y < v->height(); y += v->height() / 20)
            for (int x = v->width() / 10; x < v->width(); x += v->width() / 20)
                if (const auto hit = v->hitAt(QPoint(x, y)); hit && (name.isEmpty() || hit->name == name))
                    return {x, y};
        return {-1, -1};
    }
    /// Opens a scratch copy of projects/<sample>; returns its folder.
    std::filesystem::path open(const std::string& sample) {
        const std::filesystem::path dir = copySample(scratch, sample);
        EXPECT_TRUE(w->openProject(QString::fromStdString(dir.string())));
        return dir;
    }
};

} // namespace viscera::test
