// End-to-end: signed case packages [issue 40 item 2]. The studio signs at export with a publisher
// key kept outside the project; viscera-player verify and run accept a case only when a trusted
// publisher signed it (or with --allow-unsigned, said in the summary and the report), refuse a
// tampered, expired or rolled-back case with one line, and record which bytes ran.
#include "case/case_package.hpp"
#include "case/sha256.hpp"
#include "case/signing.hpp"
#include "case/zip_craft.hpp"
#include "sim/util/atomic_file.hpp"
#include "support/run_process.hpp"
#include "support/slab_case.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

using namespace viscera;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;
using vcase::test::RawEntry;
using vcase::test::ScratchDir;

namespace {

// These tests spell out every trust option: no helper adds --trust or --sign-key here.
test::ProcessResult player(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_PLAYER_EXE, args);
}
test::ProcessResult studio(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_STUDIO_EXE, args);
}

int lineCount(const std::string& s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

/// The slab case (slab_case.hpp) as "trust-slab" at `version`; `key` signs it (empty: unsigned).
fs::path writeSlab(const ScratchDir& dir, const std::string& name, const std::string& version = "1.0.0",
                   const std::string& key = VISCERA_SAMPLE_KEY, std::optional<std::string> expires = std::nullopt) {
    test::SlabCase slab;
    slab.caseId = "trust-slab";
    slab.caseVersion = version;
    slab.signingKey = key;
    slab.expires = std::move(expires);
    return test::writeSlabCase(dir.path() / name, slab);
}

const std::string kTrust = VISCERA_SAMPLE_PUBLIC_KEY;

} // namespace

TEST(PackageTrust, ASignedCaseRunsAndTheReportNamesItsBytesAndSigner) {
    ScratchDir dir;
    const fs::path c = writeSlab(dir, "slab.vcase");
    const auto v = player({"verify", c.string(), "--trust", kTrust});
    ASSERT_EQ(v.exitCode, 0) << v.err;
    const std::string digest = vcase::sha256Hex(readFile(c));
    EXPECT_THAT(v.out, HasSubstr("package signed by viscera-samples (ed25519:"));
    EXPECT_THAT(v.out, HasSubstr("sha256 " + digest));
    const fs::path report = dir.path() / "r.json";
    const auto r =
        player({"run", c.string(), "--headless", "--frames", "5", "--trust", kTrust, "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("package       signed by viscera-samples"));
    const nlohmann::json p = nlohmann::json::parse(readFile(report))["package"];
    EXPECT_EQ(p["sha256"], digest);
    EXPECT_EQ(p["bytes"].get<uint64_t>(), fs::file_size(c));
    EXPECT_EQ(p["signature"], "trusted");
    EXPECT_EQ(p["signer"], "viscera-samples");
    EXPECT_EQ(p["key_id"], vcase::keyId(vcase::SigningKey::load(VISCERA_SAMPLE_KEY).publicKey()));
    EXPECT_FALSE(p["allow_unsigned"].get<bool>());
    // Without --trust the same case is by an unknown publisher.
    const auto untrusted = player({"verify", c.string()});
    EXPECT_EQ(untrusted.exitCode, 1);
    EXPECT_THAT(untrusted.err, HasSubstr("a key this player does not trust"));
}

TEST(PackageTrust, TamperedExpiredAndUnsignedCasesAreRefusedWithOneLineEach) {
    ScratchDir dir;
    const fs::path signedCase = writeSlab(dir, "signed.vcase");
    const auto original = vcase::CasePackage::open(signedCase);
    // Tampered: gravity switched off in scene.json, the manifest re-hashed, the signature kept.
    test::SlabCase weightless;
    weightless.caseId = "trust-slab";
    weightless.gravity = sim::Vec3::Zero();
    std::vector<RawEntry> edited = test::slabCaseFiles(weightless);
    vcase::Manifest m = test::slabCaseHeader(weightless);
    m.files = vcase::test::manifestFor(edited).files;
    edited.emplace_back("signature.json", original->signature()->toJsonText());
    const fs::path tampered = dir.write("tampered.vcase", vcase::test::craftPackage(m, edited));
    const fs::path expired = writeSlab(dir, "expired.vcase", "1.0.0", VISCERA_SAMPLE_KEY, "2020-01-01T00:00:00Z");
    const fs::path unsignedCase = writeSlab(dir, "unsigned.vcase", "1.0.0", "");
    const struct {
        fs::path file;
        std::string rule;
    } cases[] = {
        {tampered, "signature.json: the signature by ed25519:"},
        {expired, "manifest.json: expires: the case expired at 2020-01-01T00:00:00Z (now "},
        {unsignedCase, "not signed (no signature.json); a case runs only when a trusted publisher signed it, or with "
                       "--allow-unsigned"},
    };
    for (const auto& c : cases)
        for (const char* cmd : {"verify", "run"}) {
            std::vector<std::string> args{cmd, c.file.string(), "--trust", kTrust};
            if (std::string(cmd) == "run") args.insert(args.end(), {"--headless", "--frames", "2"});
            const auto r = player(args);
            EXPECT_EQ(r.exitCode, 1) << cmd << " " << c.file << ": " << r.out;
            EXPECT_EQ(lineCount(r.err), 1) << r.err;
            EXPECT_THAT(r.err, HasSubstr(c.file.string() + ": " + c.rule)) << cmd;
            EXPECT_THAT(r.out, Not(HasSubstr("status"))) << "refused before the first frame";
        }
    // --allow-unsigned runs the unsigned case, says so, and still refuses the tampered one.
    const fs::path report = dir.path() / "r.json";
    const auto u = player(
        {"run", unsignedCase.string(), "--headless", "--frames", "2", "--allow-unsigned", "--report", report.string()});
    ASSERT_EQ(u.exitCode, 0) << u.err;
    EXPECT_THAT(u.out, HasSubstr("package       UNSIGNED (run with --allow-unsigned); sha256 "));
    const nlohmann::json p = nlohmann::json::parse(readFile(report))["package"];
    EXPECT_EQ(p["signature"], "unsigned");
    EXPECT_TRUE(p["signer"].is_null());
    EXPECT_TRUE(p["allow_unsigned"].get<bool>());
    const auto t = player({"verify", tampered.string(), "--allow-unsigned"});
    EXPECT_EQ(t.exitCode, 1);
    EXPECT_THAT(t.err, HasSubstr("does not match manifest.json (the package was changed after it was signed)"));
}

TEST(PackageTrust, AnOlderVersionIsRefusedOnceANewerOneRanWithAStateFolder) {
    ScratchDir dir;
    const fs::path state = dir.path() / "state";
    const fs::path v12 = writeSlab(dir, "v12.vcase", "1.2.0");
    const fs::path v11 = writeSlab(dir, "v11.vcase", "1.1.0");
    auto run = [&](const fs::path& c) {
        return player(
            {"run", c.string(), "--headless", "--frames", "2", "--trust", kTrust, "--state-dir", state.string()});
    };
    ASSERT_EQ(run(v11).exitCode, 0) << "nothing ran before";
    ASSERT_EQ(run(v12).exitCode, 0);
    const auto r = run(v11);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_THAT(r.err, HasSubstr(v11.string() + ": manifest.json: caseVersion 1.1.0 is older than 1.2.0, already run "
                                                "for case 'trust-slab' (state folder "));
    EXPECT_EQ(player({"verify", v11.string(), "--trust", kTrust, "--state-dir", state.string()}).exitCode, 1)
        << "verify makes the same check";
    EXPECT_EQ(player({"verify", v11.string(), "--trust", kTrust}).exitCode, 0)
        << "the default state folder is another one, and it has no record";
    EXPECT_THAT(readFile(state / "case-versions.json"), HasSubstr("\"trust-slab\": \"1.2.0\""));
    // An unsigned run allowed once records nothing: it cannot lock the trusted versions out.
    const fs::path v99 = writeSlab(dir, "v99.vcase", "99.0.0", "");
    EXPECT_EQ(
        player({"run", v99.string(), "--headless", "--frames", "2", "--allow-unsigned", "--state-dir", state.string()})
            .exitCode,
        0);
    EXPECT_EQ(run(v12).exitCode, 0) << "the trusted 1.2.0 still runs";
    EXPECT_THAT(readFile(state / "case-versions.json"), HasSubstr("\"trust-slab\": \"1.2.0\""));
}

TEST(PackageTrust, AFreshAccountRefusesARollbackWithNoStateDir) {
    ScratchDir dir;
    const fs::path home = dir.path() / "home";
    fs::create_directories(home);
    const fs::path v2 = writeSlab(dir, "v2.vcase", "2.0.0"), v1 = writeSlab(dir, "v1.vcase", "1.0.0");
    // A fresh account: HOME with nothing in it, no XDG_STATE_HOME, no --state-dir.
    auto asFreshUser = [&](const std::vector<std::string>& args) {
        std::vector<std::string> env{"-u", "XDG_STATE_HOME", "HOME=" + home.string(), VISCERA_PLAYER_EXE};
        env.insert(env.end(), args.begin(), args.end());
        return test::runProcess("/usr/bin/env", env);
    };
    const auto r2 = asFreshUser({"run", v2.string(), "--headless", "--frames", "2", "--trust", kTrust});
    ASSERT_EQ(r2.exitCode, 0) << r2.err;
    const fs::path state = home / ".local/state/viscera";
    EXPECT_EQ(fs::status(state).permissions() & fs::perms::all, fs::perms::owner_all) << "created 0700";
    EXPECT_THAT(readFile(state / "case-versions.json"), HasSubstr("\"trust-slab\": \"2.0.0\""));
    const auto r1 = asFreshUser({"run", v1.string(), "--headless", "--frames", "2", "--trust", kTrust});
    EXPECT_EQ(r1.exitCode, 1);
    EXPECT_THAT(r1.err, HasSubstr(v1.string() +
                                  ": manifest.json: caseVersion 1.0.0 is older than 2.0.0, already run "
                                  "for case 'trust-slab' (state folder " +
                                  state.string() + ")"));
    EXPECT_EQ(lineCount(r1.err), 1) << r1.err;
    EXPECT_EQ(asFreshUser({"verify", v1.string(), "--trust", kTrust}).exitCode, 1) << "verify makes the same check";
    // A world-writable state folder, or one reached through a link, is refused with one line.
    const fs::path open = dir.path() / "open-state";
    fs::create_directories(open);
    fs::permissions(open, fs::perms::all);
    const auto w = player({"verify", v2.string(), "--trust", kTrust, "--state-dir", open.string()});
    EXPECT_EQ(w.exitCode, 1);
    EXPECT_THAT(w.err, HasSubstr(open.string() + ": the state folder must be owned by root or by you and writable by "
                                                 "no one else"));
    EXPECT_EQ(lineCount(w.err), 1) << w.err;
    fs::create_symlink(state, dir.path() / "state-link");
    const auto l =
        player({"verify", v2.string(), "--trust", kTrust, "--state-dir", (dir.path() / "state-link").string()});
    EXPECT_EQ(l.exitCode, 1);
    EXPECT_THAT(l.err, HasSubstr("the state folder must not be a symbolic link"));
}

TEST(PackageTrust, ATrustKeyThroughALinkOrInAWorldWritableFolderIsRefused) {
    ScratchDir dir;
    const fs::path c = writeSlab(dir, "slab.vcase");
    const fs::path open = dir.path() / "shared";
    fs::create_directories(open);
    fs::permissions(open, fs::perms::all);
    fs::copy_file(kTrust, open / "publisher.pub.pem");
    fs::permissions(open / "publisher.pub.pem",
                    fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
    const auto w = player({"verify", c.string(), "--trust", (open / "publisher.pub.pem").string()});
    EXPECT_EQ(w.exitCode, 1);
    EXPECT_THAT(w.err, HasSubstr((open / "publisher.pub.pem").string() + ": a trusted publisher key lies in " +
                                 open.string() + ", a folder writable by others than root and you"));
    EXPECT_EQ(lineCount(w.err), 1) << w.err;
    fs::create_symlink(kTrust, dir.path() / "linked.pub.pem");
    const auto l = player({"verify", c.string(), "--trust", (dir.path() / "linked.pub.pem").string()});
    EXPECT_EQ(l.exitCode, 1);
    EXPECT_THAT(l.err, HasSubstr((dir.path() / "linked.pub.pem").string() +
                                 ": a trusted publisher key must not be a symbolic link"));
    EXPECT_EQ(player({"verify", c.string(), "--trust", kTrust}).exitCode, 0) << "the key itself is fine";
}

TEST(PackageTrust, TheStudioSignsWithAKeyKeptOutsideTheProject) {
    ScratchDir dir;
    const fs::path key = dir.path() / "keys" / "hospital.pem";
    auto k = studio({"keygen", "-o", key.string()});
    ASSERT_EQ(k.exitCode, 0) << k.err;
    EXPECT_THAT(k.out, HasSubstr("publisher key ed25519:"));
    EXPECT_EQ(fs::status(key).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
    ASSERT_TRUE(fs::exists(dir.path() / "keys" / "hospital.pub.pem"));
    auto again = studio({"keygen", "-o", key.string()});
    EXPECT_EQ(again.exitCode, 1);
    EXPECT_THAT(again.err, HasSubstr(key.string() + ": already exists (a publisher key is never replaced"));

    const fs::path project = dir.path() / "slab";
    fs::copy(fs::path(VISCERA_SOURCE_DIR) / "projects/tissue-slab", project, fs::copy_options::recursive);
    const fs::path out = dir.path() / "slab.vcase";
    auto e = studio({"export", project.string(), "-o", out.string(), "--sign-key", key.string(), "--signer",
                     "St Elsewhere Simulation Centre", "--expires", "2099-12-31"});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    EXPECT_THAT(e.out, HasSubstr("package: signed by 'St Elsewhere Simulation Centre' (ed25519:"));
    EXPECT_EQ(vcase::CasePackage::open(out)->manifest().expires, "2099-12-31T23:59:59Z");
    const std::string pub = (dir.path() / "keys" / "hospital.pub.pem").string();
    const auto v = player({"verify", out.string(), "--trust", pub});
    EXPECT_EQ(v.exitCode, 0) << v.err;
    EXPECT_THAT(v.out, HasSubstr("package signed by hospital (ed25519:"));

    // Refused before any meshing: a key inside the project, an expiry in the past, a key open to others.
    fs::copy_file(key, project / "publisher.pem");
    const auto inside =
        studio({"export", project.string(), "-o", out.string(), "--sign-key", (project / "publisher.pem").string()});
    EXPECT_EQ(inside.exitCode, 1);
    EXPECT_THAT(inside.err, HasSubstr("the publisher key must be kept outside the project folder"));
    EXPECT_THAT(inside.err, Not(HasSubstr("stage 1/")));
    const auto past =
        studio({"export", project.string(), "-o", out.string(), "--sign-key", key.string(), "--expires", "2020-01-01"});
    EXPECT_EQ(past.exitCode, 1);
    EXPECT_THAT(past.err, HasSubstr("--expires '2020-01-01': is not in the future"));
    fs::permissions(key, fs::perms::others_read, fs::perm_options::add);
    const auto open = studio({"export", project.string(), "-o", out.string(), "--sign-key", key.string()});
    EXPECT_EQ(open.exitCode, 1);
    EXPECT_THAT(open.err, HasSubstr(key.string() + ": the publisher key is open to other users (mode 604"));
}
