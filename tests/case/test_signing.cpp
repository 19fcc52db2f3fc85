// Signed packages: Ed25519 over manifest.json, the trust policy (trusted, untrusted, unsigned,
// tampered, expired, rolled back) and the record of the versions run.
#include "case/case_package.hpp"
#include "case/case_writer.hpp"
#include "case/run_state.hpp"
#include "case/sha256.hpp"
#include "case/signing.hpp"
#include "case/trust.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "zip_craft.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

namespace viscera::vcase {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
namespace fs = std::filesystem;

constexpr int64_t kNow = 1'796'000'000; // 2026-11-29

Manifest header(std::string version = "1.2.0") {
    Manifest m;
    m.caseId = "signed-case";
    m.caseVersion = std::move(version);
    m.minPlayerVersion = "0.1.0";
    m.features = {"xpbd"};
    return m;
}

std::vector<test::RawEntry> files() {
    return {{"scene.json", "{\"gravity\": [0, 0, -9.81]}\n"}, {"meshes/a.vtet", test::unitTetVtet()}};
}

/// A package of files() under `m`, signed by `key` when given.
std::string package(const Manifest& m, const SigningKey* key) {
    CaseWriter w(m);
    for (const test::RawEntry& e : files())
        w.addFile(e.name, e.bytes);
    if (key) w.sign(*key, "Test publisher");
    return w.build();
}

using test::messageOf;

struct SignedPackage : ::testing::Test {
    test::ScratchDir dir;
    SigningKey publisher = SigningKey::generate();
    SigningKey stranger = SigningKey::generate();
    TrustPolicy policy;

    void SetUp() override {
        writeFileAtomic(dir.path() / "publisher.pem", publisher.publicPem());
        policy.trusted.addKeyFile(dir.path() / "publisher.pem");
        policy.now = kNow;
    }
    std::unique_ptr<CasePackage> open(const std::string& bytes) { return CasePackage::fromBytes(bytes, "c.vcase"); }
    std::string refusal(const std::string& bytes) {
        return messageOf([&] { checkProvenance(*open(bytes), policy); });
    }
};

TEST(Signing, SignaturesVerifyOnlyForTheirKeyAndMessage) {
    const SigningKey a = SigningKey::generate(), b = SigningKey::generate();
    const std::string msg = signedMessage("{\"caseId\": \"x\"}\n");
    const std::string sig = a.sign(msg);
    ASSERT_EQ(sig.size(), kSignatureBytes);
    EXPECT_EQ(sig, a.sign(msg)) << "Ed25519 is deterministic";
    EXPECT_TRUE(verifySignature(a.publicKey(), msg, sig));
    EXPECT_FALSE(verifySignature(b.publicKey(), msg, sig));
    std::string flipped = msg;
    flipped.back() ^= 1;
    EXPECT_FALSE(verifySignature(a.publicKey(), flipped, sig));
    std::string badSig = sig;
    badSig[10] ^= 0x40;
    EXPECT_FALSE(verifySignature(a.publicKey(), msg, badSig));
    EXPECT_FALSE(verifySignature(a.publicKey().substr(1), msg, sig));
    // The label keeps a signature over a manifest from passing for any other signed text.
    EXPECT_FALSE(verifySignature(a.publicKey(), "{\"caseId\": \"x\"}\n", sig));
    EXPECT_THAT(keyId(a.publicKey()), StartsWith("ed25519:"));
    EXPECT_EQ(keyId(a.publicKey()).size(), 8u + 16u);
}

TEST(Signing, KeysRoundTripThroughPemAndSecretsStayPrivate) {
    test::ScratchDir dir;
    const SigningKey k = SigningKey::generate();
    const fs::path priv = dir.path() / "k.pem", pub = dir.path() / "k.pub.pem";
    writeFileAtomic(priv, k.privatePem(), 0600);
    writeFileAtomic(pub, k.publicPem());
    EXPECT_EQ(SigningKey::load(priv).publicKey(), k.publicKey());
    EXPECT_EQ(parsePublicKeyPem(k.publicPem(), "k.pub.pem"), k.publicKey());
    fs::permissions(priv, fs::perms::group_read, fs::perm_options::add);
    EXPECT_EQ(messageOf([&] { SigningKey::load(priv); }),
              priv.string() + ": the publisher key is open to other users (mode 640; chmod 600 it)");
    // The public key is not a private key, and neither is text.
    writeFileAtomic(dir.path() / "pub-as-private.pem", k.publicPem(), 0600);
    EXPECT_THAT(messageOf([&] { SigningKey::load(dir.path() / "pub-as-private.pem"); }),
                HasSubstr("not an unencrypted PEM private key"));
    EXPECT_THAT(messageOf([&] { parsePublicKeyPem("hello", "x.pem"); }), StartsWith("x.pem: not a PEM public key"));
    EXPECT_THAT(messageOf([&] { SigningKey::load(dir.path() / "missing.pem"); }),
                StartsWith((dir.path() / "missing.pem").string()));
}

TEST(Signing, KeysOfAnotherTypeAreRefusedByName) {
    // Public keys of other types (fixed test data, nothing secret): P-256 and SM2 (whose OpenSSL id
    // has no short name: the message must still be made, not crash).
    const std::string p256 = "-----BEGIN PUBLIC KEY-----\n"
                             "MFkwEwYHKoZIzj0CAQYIKoZIzj0DAQcDQgAEoPoXI7OFZ0XqDjNcHjSBrUQtbBQX\n"
                             "eTiCrJgSDIdxq0N62/UVLWSL/FRVt67KZCBrzbWOhXwlucctbdD6kvMNpw==\n"
                             "-----END PUBLIC KEY-----\n";
    const std::string sm2 = "-----BEGIN PUBLIC KEY-----\n"
                            "MFkwEwYHKoZIzj0CAQYIKoEcz1UBgi0DQgAEDzejYxqw5gHobV6N9biPvGbWWosi\n"
                            "OQuNF+CWzYkzAw7cteQ8HXaAzjB+cFYZ+fBijsG7sqeMztpIwS6XJPIW3Q==\n"
                            "-----END PUBLIC KEY-----\n";
    EXPECT_THAT(messageOf([&] { parsePublicKeyPem(p256, "ec.pem"); }),
                StartsWith("ec.pem: not an Ed25519 public key (found "));
    EXPECT_THAT(messageOf([&] { parsePublicKeyPem(sm2, "sm2.pem"); }),
                StartsWith("sm2.pem: not an Ed25519 public key (found "));
}

TEST(Signing, TrustAnchorsWritableByOthersAreRefused) {
    test::ScratchDir dir;
    const SigningKey k = SigningKey::generate();
    const fs::path folder = dir.path() / "trusted", key = folder / "pub.pem";
    fs::create_directories(folder);
    fs::permissions(folder, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                fs::perms::others_read | fs::perms::others_exec);
    writeFileAtomic(key, k.publicPem());
    TrustStore good;
    good.addFolder(folder);
    EXPECT_EQ(good.keys().size(), 1u);
    // Group-writable by a group others share (nogroup, where this user may hand the file to it;
    // the user's own private group would be harmless), else writable by everyone.
    const bool shared = ::chown(key.c_str(), static_cast<uid_t>(-1), 65534) == 0;
    fs::permissions(key, shared ? fs::perms::group_write : fs::perms::others_write, fs::perm_options::add);
    TrustStore file;
    EXPECT_EQ(messageOf([&] { file.addKeyFile(key); }),
              key.string() +
                  ": a trusted publisher key must be owned by root or by you and writable by no one else "
                  "(owner uid " +
                  std::to_string(::geteuid()) + ", mode " + (shared ? "664" : "646") + ")");
    fs::permissions(key, fs::perms::group_write | fs::perms::others_write, fs::perm_options::remove);
    fs::permissions(folder, fs::perms::others_write, fs::perm_options::add);
    TrustStore open;
    EXPECT_THAT(messageOf([&] { open.addFolder(folder); }),
                StartsWith(folder.string() + ": a trust folder must be owned by root or by you"));
}

TEST(Signing, SignatureFileIsParsedStrictly) {
    const SigningKey k = SigningKey::generate();
    const std::string good = signManifest(k, "Pub", "m");
    const PackageSignature s = PackageSignature::parse(good, "s.json");
    EXPECT_EQ(s.signer, "Pub");
    EXPECT_EQ(s.publicKey, k.publicKey());
    auto edited = [&](const std::string& key, const nlohmann::json& value) {
        nlohmann::json j = nlohmann::json::parse(good);
        if (value.is_null())
            j.erase(key);
        else
            j[key] = value;
        return messageOf([&] { PackageSignature::parse(j.dump(), "s.json"); });
    };
    EXPECT_THAT(edited("algorithm", "rsa"),
                HasSubstr("s.json: algorithm: 'rsa' is not a supported signature algorithm"));
    EXPECT_THAT(edited("publicKey", "abcd"), HasSubstr("s.json: publicKey: must be 64 lowercase hex characters"));
    EXPECT_THAT(edited("signature", std::string(128, 'G')), HasSubstr("signature: must be 128 lowercase hex"));
    EXPECT_THAT(edited("signature", nullptr), HasSubstr("s.json: signature: required field is missing"));
    EXPECT_THAT(edited("extra", 1), HasSubstr("extra: unknown field"));
    EXPECT_THAT(edited("signer", "a\x1b[2Jb"), HasSubstr("signer: must be printable text"));
    EXPECT_THAT(edited("schemaVersion", 2), HasSubstr("schemaVersion: 2 is not supported"));
}

TEST(Signing, UtcTimesParseOnlyRealDates) {
    EXPECT_EQ(parseUtcTime("1970-01-01T00:00:00Z"), 0);
    EXPECT_EQ(parseUtcTime("2000-03-01T00:00:00Z"), 951868800);
    EXPECT_EQ(parseUtcTime("2024-02-29T23:59:59Z"), 1709251199);
    for (const char* bad :
         {"2023-02-29T00:00:00Z", "2026-13-01T00:00:00Z", "2026-04-31T00:00:00Z", "2026-01-01T24:00:00Z",
          "2026-01-01 00:00:00Z", "2026-01-01T00:00:00", "1969-12-31T23:59:59Z", "2026-1-01T00:00:00Z", ""})
        EXPECT_FALSE(parseUtcTime(bad)) << bad;
    for (int64_t t : {int64_t(0), int64_t(951868800), int64_t(1709251199), kNow, int64_t(253402300799)})
        EXPECT_EQ(parseUtcTime(formatUtcTime(t)), t) << formatUtcTime(t);
    Manifest m = header();
    m.expires = "2027-02-30T00:00:00Z";
    EXPECT_THAT(messageOf([&] { Manifest::fromJson(m.toJson(), "m"); }),
                HasSubstr("m: expires: '2027-02-30T00:00:00Z' is not a UTC time YYYY-MM-DDTHH:MM:SSZ"));
}

TEST_F(SignedPackage, ATrustedSignatureIsAcceptedAndNamed) {
    const std::string bytes = package(header(), &publisher);
    const auto pkg = open(bytes);
    ASSERT_TRUE(pkg->signature());
    EXPECT_EQ(pkg->sha256(), sha256Hex(bytes));
    EXPECT_EQ(pkg->bytes(), bytes.size());
    EXPECT_EQ(pkg->manifest().findFile(std::string(kSignatureName)), nullptr) << "the signature is never listed";
    const Provenance p = checkProvenance(*pkg, policy);
    EXPECT_EQ(p.signature, "trusted");
    EXPECT_EQ(p.signer, "publisher") << "the trusted key's file name, not the name the package claims";
    EXPECT_EQ(p.keyId, keyId(publisher.publicKey()));
    EXPECT_EQ(p.sha256, sha256Hex(bytes));
    EXPECT_EQ(package(header(), &publisher), bytes) << "signed packages stay deterministic";
}

TEST_F(SignedPackage, UnsignedAndUntrustedRunOnlyWhenAllowed) {
    const std::string unsignedBytes = package(header(), nullptr), foreign = package(header(), &stranger);
    EXPECT_EQ(refusal(unsignedBytes), "c.vcase: not signed (no signature.json); a case runs only when a trusted "
                                      "publisher signed it, or with --allow-unsigned");
    EXPECT_THAT(refusal(foreign), StartsWith("c.vcase: signature.json: signed by " + keyId(stranger.publicKey()) +
                                             " ('Test publisher'), a key this player does not trust (add it with "
                                             "--trust KEY.pem or to /etc/viscera/trusted-publishers"));
    policy.allowUnsigned = true;
    EXPECT_EQ(checkProvenance(*open(unsignedBytes), policy).signature, "unsigned");
    const Provenance p = checkProvenance(*open(foreign), policy);
    EXPECT_EQ(p.signature, "untrusted");
    EXPECT_EQ(p.signer, "Test publisher");
    EXPECT_TRUE(p.allowUnsigned);
}

TEST_F(SignedPackage, ATamperedReHashedPackageIsRefusedEvenWhenUnsignedIsAllowed) {
    const auto original = open(package(header(), &publisher));
    // The outsider's edit: a changed scene, the manifest re-hashed, the old signature kept.
    std::vector<test::RawEntry> edited = files();
    edited[0].bytes = "{\"gravity\": [0, 0, 0]}\n";
    Manifest m = header();
    m.files = test::manifestFor(edited).files;
    std::vector<test::RawEntry> entries = edited;
    entries.emplace_back(std::string(kSignatureName), original->signature()->toJsonText());
    const std::string forged = test::craftPackage(m, entries);
    ASSERT_NO_THROW(open(forged)) << "the package is consistent: only the signature tells";
    policy.allowUnsigned = true;
    EXPECT_EQ(refusal(forged), "c.vcase: signature.json: the signature by " + keyId(publisher.publicKey()) +
                                   " does not match manifest.json (the package was changed after it was signed)");
    // Re-signed by the outsider's own key: verifies, but is not the publisher's.
    policy.allowUnsigned = false;
    CaseWriter w(header());
    for (const test::RawEntry& e : edited)
        w.addFile(e.name, e.bytes);
    w.sign(stranger, "Test publisher");
    EXPECT_THAT(refusal(w.build()), HasSubstr("a key this player does not trust"));
}

TEST_F(SignedPackage, AnExpiredCaseIsRefused) {
    Manifest m = header();
    m.expires = formatUtcTime(kNow - 1);
    EXPECT_EQ(refusal(package(m, &publisher)), "c.vcase: manifest.json: expires: the case expired at " + *m.expires +
                                                   " (now " + formatUtcTime(kNow) + ")");
    m.expires = formatUtcTime(kNow + 3600);
    EXPECT_EQ(checkProvenance(*open(package(m, &publisher)), policy).expires, *m.expires);
}

TEST_F(SignedPackage, AnOlderVersionThanOneRunIsRefusedWhereAStateFolderExists) {
    const fs::path state = dir.path() / "state";
    fs::create_directories(state);
    policy.stateFolder = state;
    EXPECT_NO_THROW(checkProvenance(*open(package(header("1.2.0"), &publisher)), policy)) << "nothing run yet";
    recordVersionRun(state, "signed-case", "1.2.0");
    recordVersionRun(state, "signed-case", "1.1.0"); // never lowers the record
    EXPECT_EQ(highestVersionRun(state, "signed-case"), "1.2.0");
    EXPECT_EQ(refusal(package(header("1.1.9"), &publisher)),
              "c.vcase: manifest.json: caseVersion 1.1.9 is older than 1.2.0, already run for case 'signed-case' "
              "(state folder " +
                  state.string() + ")");
    EXPECT_THAT(refusal(package(header("1.2.0-rc.1"), &publisher)), HasSubstr("is older than 1.2.0"));
    EXPECT_NO_THROW(checkProvenance(*open(package(header("1.2.0"), &publisher)), policy)) << "the same version reruns";
    EXPECT_NO_THROW(checkProvenance(*open(package(header("1.3.0"), &publisher)), policy));
    // A broken record is an error naming it, and is left as it was.
    writeFileAtomic(state / kRunStateName, "{\"schemaVersion\": 1, \"cases\": {\"signed-case\": \"one\"}}");
    EXPECT_THAT(refusal(package(header("1.3.0"), &publisher)),
                HasSubstr((state / kRunStateName).string() + ": cases.signed-case: 'one' is not a semantic version"));
    EXPECT_THAT(messageOf([&] { recordVersionRun(state, "signed-case", "2.0.0"); }),
                HasSubstr("not a semantic version"));
    EXPECT_THAT(readFile(state / kRunStateName), HasSubstr("\"one\""));
}

TEST_F(SignedPackage, ASignatureEntryIsBoundedAndNeverListed) {
    std::vector<test::RawEntry> entries = files();
    entries.emplace_back(std::string(kSignatureName), std::string(5000, ' '));
    const std::string big = test::craftPackage(test::manifestFor(files()), entries);
    EXPECT_EQ(messageOf([&] { open(big); }),
              "c.vcase: signature.json: size 5000 bytes exceeds the signature limit of 4096 bytes");
    std::vector<test::RawEntry> listed = files();
    listed.emplace_back(std::string(kSignatureName), "{}");
    EXPECT_THAT(messageOf([&] { open(test::craftPackage(test::manifestFor(listed), listed)); }),
                HasSubstr("signature.json is the package's signature and is not listed"));
    CaseWriter w(header());
    EXPECT_THAT(messageOf([&] { w.addFile(std::string(kSignatureName), "x"); }), HasSubstr("reserved name"));
}

TEST_F(SignedPackage, TrustFoldersReadEveryKeyAndRefuseABrokenOne) {
    const fs::path folder = dir.path() / "trusted";
    fs::create_directories(folder);
    writeFileAtomic(folder / "hospital.pem", stranger.publicPem());
    writeFileAtomic(folder / "notes.txt", "not a key, not read");
    TrustStore store;
    store.addFolder(folder);
    store.addFolder(dir.path() / "absent"); // a folder that does not exist adds nothing
    ASSERT_EQ(store.keys().size(), 1u);
    EXPECT_EQ(store.keys()[0].name, "hospital");
    EXPECT_NE(store.find(stranger.publicKey()), nullptr);
    EXPECT_EQ(store.find(publisher.publicKey()), nullptr);
    writeFileAtomic(folder / "broken.pem", "-----BEGIN PUBLIC KEY-----\nAAAA\n-----END PUBLIC KEY-----\n");
    TrustStore again;
    EXPECT_EQ(messageOf([&] { again.addFolder(folder); }),
              (folder / "broken.pem").string() + ": not a PEM public key ('-----BEGIN PUBLIC KEY-----')");
}

} // namespace
} // namespace viscera::vcase
