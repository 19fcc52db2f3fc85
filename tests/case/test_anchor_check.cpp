// Trust anchors as OpenSSH treats authorized_keys (issue 58): a link in the trust folder, a key in
// a folder others may write, a state folder others may write or reach through a link — each
// refused with one line naming the file; rollback protection on with no --state-dir; and a
// package whose admission fails is refused before any entry but manifest.json and signature.json
// is inflated.
#include "case/anchor_check.hpp"
#include "case/case_package.hpp"
#include "case/case_writer.hpp"
#include "case/run_state.hpp"
#include "case/signing.hpp"
#include "case/trust.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "zip_craft.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <functional>

#include <sys/stat.h>

namespace viscera::vcase {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
namespace fs = std::filesystem;

using test::messageOf;

mode_t modeOf(const fs::path& p) {
    struct stat st {};
    EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
    return st.st_mode & 07777;
}

struct Anchors : ::testing::Test {
    test::ScratchDir dir;
    SigningKey key = SigningKey::generate();
    fs::path trusted, open;

    void SetUp() override {
        trusted = dir.path() / "trusted";
        open = dir.path() / "shared"; // a folder any local user may write (no sticky bit)
        fs::create_directories(trusted);
        fs::create_directories(open);
        fs::permissions(open, fs::perms::all);
    }
};

TEST_F(Anchors, ALinkInTheTrustFolderIsRefusedEvenToAGoodKey) {
    writeFileAtomic(dir.path() / "good.pem", key.publicPem());
    fs::create_symlink(dir.path() / "good.pem", trusted / "linked.pem");
    TrustStore store;
    EXPECT_EQ(messageOf([&] { store.addFolder(trusted); }),
              (trusted / "linked.pem").string() +
                  ": a trusted publisher key must not be a symbolic link (it points to " +
                  (dir.path() / "good.pem").string() + "); put the file itself there");
    EXPECT_TRUE(store.keys().empty()) << "a broken trust folder is never half read";
}

TEST_F(Anchors, ALinkToAKeyInAWorldWritableFolderIsRefused) {
    writeFileAtomic(open / "evil.pem", key.publicPem());
    fs::create_symlink(open / "evil.pem", trusted / "vendor.pem");
    TrustStore store;
    const std::string m = messageOf([&] { store.addFolder(trusted); });
    EXPECT_THAT(
        m, StartsWith((trusted / "vendor.pem").string() + ": a trusted publisher key must not be a symbolic link"));
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line";
}

TEST_F(Anchors, AKeyInAWorldWritableFolderIsRefusedAsTrust) {
    const fs::path k = open / "k.pub.pem";
    writeFileAtomic(k, key.publicPem());
    fs::permissions(k, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
    TrustStore store;
    EXPECT_EQ(messageOf([&] { store.addKeyFile(k); }),
              k.string() + ": a trusted publisher key lies in " + open.string() +
                  ", a folder writable by others than root and you (owner uid " + std::to_string(::geteuid()) +
                  ", mode 777); keep it where only root or you can change it");
    // Deeper down too: the whole chain up to / is checked.
    const fs::path deep = open / "a" / "b";
    fs::create_directories(deep);
    writeFileAtomic(deep / "k.pem", key.publicPem());
    EXPECT_THAT(messageOf([&] { store.addKeyFile(deep / "k.pem"); }), HasSubstr("lies in " + open.string() + ","));
    // And a trust folder below it, whatever the folder's own mode.
    EXPECT_THAT(messageOf([&] { store.addFolder(deep); }),
                StartsWith(deep.string() + ": a trust folder lies in " + open.string()));
    EXPECT_TRUE(store.keys().empty());
    // A key of one's own in a private folder under the sticky, root-owned temp folder is fine.
    writeFileAtomic(trusted / "mine.pem", key.publicPem());
    EXPECT_NO_THROW(store.addKeyFile(trusted / "mine.pem"));
}

TEST_F(Anchors, AStateFolderOthersMayWriteOrALinkIsRefused) {
    const fs::path state = open / "state";
    EXPECT_THAT(messageOf([&] { stateFolder(state, StateUse::Record); }),
                StartsWith(state.string() + ": the state folder lies in " + open.string()));
    EXPECT_FALSE(fs::exists(state)) << "refused before it was made";
    const fs::path wide = dir.path() / "wide";
    fs::create_directories(wide);
    fs::permissions(wide, fs::perms::all);
    EXPECT_THAT(messageOf([&] { stateFolder(wide, StateUse::Check); }),
                StartsWith(wide.string() + ": the state folder must be owned by root or by you and writable by no one "
                                           "else"));
    fs::create_symlink(trusted, dir.path() / "state-link");
    EXPECT_THAT(messageOf([&] { stateFolder(dir.path() / "state-link", StateUse::Check); }),
                StartsWith((dir.path() / "state-link").string() + ": the state folder must not be a symbolic link"));
    const fs::path fresh = dir.path() / "private" / "state";
    EXPECT_EQ(stateFolder(fresh, StateUse::Check), std::nullopt) << "a check makes nothing";
    EXPECT_FALSE(fs::exists(fresh));
    EXPECT_EQ(stateFolder(fresh, StateUse::Record), fresh);
    EXPECT_EQ(modeOf(fresh), 0700u) << "created 0700 on first use";
}

TEST_F(Anchors, LinksAreFollowedOnlyOutOfFoldersNobodyElseMayWrite) {
    // ".." after a link: resolved as the kernel does, through the link, into the open folder.
    fs::create_directories(open / "sub");
    fs::create_directories(open / "keys");
    writeFileAtomic(open / "keys" / "k.pem", key.publicPem());
    fs::create_directories(dir.path() / "safe");
    fs::create_symlink(open / "sub", dir.path() / "safe" / "link");
    const fs::path dotdot = dir.path() / "safe" / "link" / ".." / "keys" / "k.pem";
    TrustStore store;
    EXPECT_THAT(messageOf([&] { store.addKeyFile(dotdot); }),
                StartsWith(dotdot.string() + ": a trusted publisher key lies in " + open.string() + ","));
    // A link in a safe folder to a link in an open folder to a good key: the open folder is passed
    // through, so another user could swap where the key comes from.
    writeFileAtomic(trusted / "real.pem", key.publicPem());
    fs::create_symlink(trusted / "real.pem", open / "hop");
    fs::create_symlink(open / "hop", dir.path() / "safe" / "k");
    fs::create_directories(dir.path() / "safe2");
    const fs::path folderLink = dir.path() / "safe2" / "keys";
    fs::create_symlink(open / "keys", folderLink); // a link to a folder, then a file in it
    EXPECT_THAT(messageOf([&] { store.addKeyFile(folderLink / "k.pem"); }),
                StartsWith((folderLink / "k.pem").string() + ": a trusted publisher key lies in " + open.string()));
    EXPECT_THAT(messageOf([&] { store.addKeyFile(dir.path() / "safe" / "k"); }),
                HasSubstr("must not be a symbolic link"));
    EXPECT_TRUE(store.keys().empty());
    // A link between safe folders is followed: the key is read where it resolves.
    fs::create_symlink(trusted, dir.path() / "safe" / "trusted-link");
    EXPECT_NO_THROW(store.addKeyFile(dir.path() / "safe" / "trusted-link" / "real.pem"));
    EXPECT_EQ(store.keys().size(), 1u);
}

TEST_F(Anchors, AMissingTrustFolderAnywhereAddsNothing) {
    TrustStore store; // e.g. <prefix>/share/viscera/trusted-publishers under a group-writable prefix
    EXPECT_NO_THROW(store.addFolder(open / "share" / "viscera" / "trusted-publishers"));
    EXPECT_TRUE(store.keys().empty());
}

TEST_F(Anchors, AStickyFolderIsNoStateFolderAndATrailingSlashNoWayAroundALink) {
    const fs::path sticky = dir.path() / "sticky";
    fs::create_directories(sticky);
    fs::permissions(sticky, fs::perms::all | fs::perms::sticky_bit);
    EXPECT_THAT(messageOf([&] { stateFolder(sticky, StateUse::Check); }),
                StartsWith(sticky.string() + ": the state folder must be owned by root or by you and writable by no "
                                             "one else"));
    fs::create_symlink(trusted, dir.path() / "state-link");
    const fs::path slash = dir.path().string() + "/state-link/";
    EXPECT_THAT(messageOf([&] { stateFolder(slash, StateUse::Check); }),
                HasSubstr("the state folder must not be a symbolic link"));
}

TEST_F(Anchors, AStateFolderIsMadeSafeWhateverTheUmask) {
    const mode_t old = ::umask(002); // Debian's user-private-group umask
    const fs::path fresh = dir.path() / "home" / ".local" / "state" / "viscera";
    const std::optional<fs::path> made = stateFolder(fresh, StateUse::Record);
    ::umask(old);
    EXPECT_EQ(made, fresh);
    EXPECT_EQ(modeOf(fresh), 0700u);
    EXPECT_EQ(modeOf(fresh.parent_path()), 0755u) << "a parent the group may write would make it unsafe";
    EXPECT_EQ(stateFolder(fresh, StateUse::Record), fresh) << "and it is accepted the next time";
}

/// Sets an environment variable for one test and puts the old value back.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::string& value) : m_name(name) {
        if (const char* old = std::getenv(name)) m_old = old;
        ::setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() {
        if (m_old)
            ::setenv(m_name, m_old->c_str(), 1);
        else
            ::unsetenv(m_name);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* m_name;
    std::optional<std::string> m_old;
};

Manifest header(const std::string& version) {
    Manifest m;
    m.caseId = "rollback-case";
    m.caseVersion = version;
    m.minPlayerVersion = "0.1.0";
    m.features = {"xpbd"};
    return m;
}

std::string signedPackage(const Manifest& m, const SigningKey& key) {
    CaseWriter w(m);
    w.addFile("scene.json", "{}\n");
    w.addFile("meshes/a.vtet", test::unitTetVtet());
    w.sign(key, "Test publisher");
    return w.build();
}

TEST_F(Anchors, RollbackIsRefusedByDefaultInAFreshAccount) {
    if (fs::is_directory(kSystemStateFolder)) GTEST_SKIP() << "a kiosk state folder exists on this machine";
    const ScopedEnv xdg("XDG_STATE_HOME", (dir.path() / "fresh-home" / ".local" / "state").string());
    const fs::path expected = dir.path() / "fresh-home" / ".local" / "state" / "viscera";
    ASSERT_EQ(defaultStateFolder(), expected);
    ASSERT_FALSE(fs::exists(expected));
    writeFileAtomic(trusted / "publisher.pem", key.publicPem());
    TrustPolicy policy;
    policy.trusted.addKeyFile(trusted / "publisher.pem");
    policy.stateFolder = stateFolder(std::nullopt, StateUse::Record); // a run with no --state-dir
    EXPECT_EQ(modeOf(expected), 0700u);
    const auto v2 = CasePackage::fromBytes(signedPackage(header("2.0.0"), key), "v2.vcase");
    checkProvenance(*v2, policy);
    recordVersionRun(*policy.stateFolder, "rollback-case", "2.0.0"); // the player records a run
    EXPECT_THAT(messageOf([&] {
                    CasePackage::fromBytes(signedPackage(header("1.0.0"), key), "v1.vcase", {},
                                           [&](const PackageHead& h) { checkProvenance(h, policy); });
                }),
                StartsWith("v1.vcase: manifest.json: caseVersion 1.0.0 is older than 2.0.0"));
}

TEST_F(Anchors, AnUntrustedPackageIsRefusedBeforeItsPayloadIsInflated) {
    // A listed entry whose bytes do not match the manifest: inflating and hashing it would say
    // "sha256 mismatch"; the admission speaks first and nothing past the head is read.
    const std::vector<test::RawEntry> listed = {{"scene.json", "{}\n"}, {"big.bin", std::string(4096, 'a')}};
    std::vector<test::RawEntry> actual = listed;
    actual[1].bytes[0] = 'b';
    const std::string bytes = test::craftPackage(test::manifestFor(listed), actual);
    TrustPolicy policy; // trusts nothing, unsigned not allowed
    int admissions = 0;
    EXPECT_THAT(messageOf([&] {
                    CasePackage::fromBytes(bytes, "u.vcase", {}, [&](const PackageHead& h) {
                        ++admissions;
                        EXPECT_FALSE(h.signature);
                        EXPECT_EQ(h.manifest.files.size(), 2u);
                        checkProvenance(h, policy);
                    });
                }),
                StartsWith("u.vcase: not signed (no signature.json)"));
    EXPECT_EQ(admissions, 1);
    // Admitted, the rest is checked as before.
    EXPECT_THAT(messageOf([&] { CasePackage::fromBytes(bytes, "u.vcase", {}, [](const PackageHead&) {}); }),
                HasSubstr("big.bin: sha256 mismatch"));
    // The head alone, from a file (the launcher's listing).
    const fs::path file = dir.write("u.vcase", bytes);
    std::string signer = "unset";
    readPackageHead(file, [&](const PackageHead& h) { signer = h.signature ? h.signature->signer : ""; });
    EXPECT_EQ(signer, "");
}

} // namespace
} // namespace viscera::vcase
