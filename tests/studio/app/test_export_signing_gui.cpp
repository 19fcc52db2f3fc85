// File → Export case… signs [issue 57 item 7], driven through the save dialog under Xvfb: with
// the publisher key where `viscera-studio export` looks for it (~/.config/viscera, here the
// fixture's XDG_CONFIG_HOME) the package carries signature.json, which vcase::checkProvenance
// accepts with that key trusted; with no key nothing starts until the user has read why and
// chosen: make a key (as `viscera-studio keygen`) and sign, or export unsigned.
#include "app/export_runner.hpp"
#include "case/case_package.hpp"
#include "case/trust.hpp"
#include "project/publishing.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QApplication>
#include <QFileDialog>
#include <QLineEdit>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QStatusBar>

#include <gtest/gtest.h>

using namespace viscera;
namespace fs = std::filesystem;

namespace {

struct SigningFixture : test::MainWindowFixture {
    SigningFixture() : MainWindowFixture("viscera-export-signing-gui") {}
    bool done = false, ok = false;
    QString message;

    void SetUp() override {
        MainWindowFixture::SetUp();
        w->exportRunner()->setProgram(VISCERA_STUDIO_EXE);
        QObject::connect(w->exportRunner(), &studio::ExportRunner::finished, [this](bool k, const QString& m) {
            done = true;
            ok = k;
            message = m;
        });
    }

    /// File → Export case…: the save dialog gets `out` typed and Enter.
    void exportByDialog(const fs::path& out) {
        auto* action = w->findChild<QAction*>("actionExportCase");
        ASSERT_NE(action, nullptr);
        typeIntoFileDialog(QString::fromStdString(out.string()), [action] { action->trigger(); });
    }

    /// The package at `out` checked as a player checks it, `trusted` its only trust anchor.
    vcase::Provenance provenance(const fs::path& out, const fs::path& trusted) {
        const auto pkg = vcase::CasePackage::open(out);
        vcase::TrustPolicy policy;
        policy.trusted.addKeyFile(trusted);
        return vcase::checkProvenance(*pkg, policy);
    }
};

} // namespace

TEST_F(SigningFixture, WithThePublisherKeyTheGuiExportIsSignedAndTrusted) {
    open("tissue-slab");
    w->preview()->stop();
    const studio::NewPublisherKey key = studio::makePublisherKey(studio::defaultPublisherKeyPath());
    ASSERT_TRUE(key.privateFile.string().rfind(scratch.dir.string(), 0) == 0) << "the test's own config folder";
    const fs::path out = scratch.dir / "signed.vcase";
    exportByDialog(out);
    ASSERT_FALSE(HasFailure());
    EXPECT_EQ(w->unsignedExportBox(), nullptr) << "nothing to ask: the key is there";
    ASSERT_TRUE(test::waitFor([&] { return done; }, 120000));
    ASSERT_TRUE(ok) << message.toStdString() << "\n" << w->exportRunner()->output().toStdString();
    EXPECT_TRUE(message.contains("signed by 'publisher' (" + QString::fromStdString(key.keyId) + ")"))
        << message.toStdString();
    EXPECT_TRUE(w->statusBar()->currentMessage().contains("signed by 'publisher'"));
    ASSERT_TRUE(vcase::CasePackage::open(out)->signature()) << "signature.json";
    const vcase::Provenance p = provenance(out, key.publicFile);
    EXPECT_EQ(p.signature, "trusted");
    EXPECT_EQ(p.keyId, key.keyId);
    // another key trusted instead: refused (the signature is the publisher's, not any key's)
    const studio::NewPublisherKey other = studio::makePublisherKey(scratch.dir / "other" / "key.pem");
    EXPECT_THROW(provenance(out, other.publicFile), InputError);
}

TEST_F(SigningFixture, WithNoKeyTheUserIsToldWhyAndChoosesUnsignedOrANewKey) {
    open("tissue-slab");
    w->preview()->stop();
    const fs::path out = scratch.dir / "case.vcase";
    exportByDialog(out);
    ASSERT_FALSE(HasFailure());
    ASSERT_TRUE(test::waitFor([&] { return w->unsignedExportBox() && w->unsignedExportBox()->isVisible(); }, 5000));
    QMessageBox* box = w->unsignedExportBox();
    const QString said = box->text();
    EXPECT_TRUE(said.contains(QString::fromStdString(studio::defaultPublisherKeyPath().string())))
        << said.toStdString();
    EXPECT_TRUE(said.contains("viscera-studio keygen")) << said.toStdString();
    EXPECT_TRUE(said.contains("--allow-unsigned")) << said.toStdString();
    EXPECT_FALSE(w->exportRunner()->running()) << "nothing starts before the user has chosen";
    EXPECT_TRUE(w->log()->toPlainText().contains("the case is not signed: no publisher key at"));
    test::saveShot("export_no_publisher_key");
    QTest::mouseClick(box->findChild<QPushButton*>("exportUnsigned"), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return done; }, 120000));
    ASSERT_TRUE(ok) << message.toStdString();
    EXPECT_TRUE(message.contains("UNSIGNED: players refuse it without --allow-unsigned")) << message.toStdString();
    EXPECT_FALSE(vcase::CasePackage::open(out)->signature());

    // again, and this time the key is made from the question: the case is signed with it
    done = false;
    const fs::path signedOut = scratch.dir / "case-signed.vcase";
    exportByDialog(signedOut);
    ASSERT_TRUE(test::waitFor([&] { return w->unsignedExportBox() && w->unsignedExportBox()->isVisible(); }, 5000));
    QTest::mouseClick(w->unsignedExportBox()->findChild<QPushButton*>("makeKeyAndSign"), Qt::LeftButton);
    ASSERT_TRUE(fs::exists(studio::defaultPublisherKeyPath()));
    EXPECT_EQ(fs::status(studio::defaultPublisherKeyPath()).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
    ASSERT_TRUE(test::waitFor([&] { return done; }, 120000));
    ASSERT_TRUE(ok) << message.toStdString();
    EXPECT_EQ(provenance(signedOut, studio::publicKeyPathFor(studio::defaultPublisherKeyPath())).signature, "trusted");
}
