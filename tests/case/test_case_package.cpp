// Verification of .vcase packages: every rule, on archives crafted with libzip in a scratch folder.
#include "case/case_package.hpp"
#include "case/sha256.hpp"
#include "sim/util/error.hpp"
#include "zip_craft.hpp"

#include <zip.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace viscera::vcase {
namespace {

using test::craftPackage;
using test::craftZip;
using test::manifestFor;
using test::RawEntry;
using ::testing::HasSubstr;

class VcasePackage : public ::testing::Test {
protected:
    test::ScratchDir dir;

    /// The one-line InputError message of opening `bytes` as case.vcase, or a test failure.
    std::string rejection(const std::string& bytes, const Limits& limits = {}) {
        return rejectionOf(dir.write("case.vcase", bytes), limits);
    }
    std::string rejectionOf(const std::filesystem::path& path, const Limits& limits = {}) {
        try {
            CasePackage::open(path, limits);
        } catch (const InputError& e) {
            std::string message = e.what();
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
            return message;
        }
        ADD_FAILURE() << path << " was accepted";
        return "";
    }
    /// "<package path>: " — every message starts with it.
    std::string pkg() const { return (dir.path() / "case.vcase").string() + ": "; }

    static std::vector<RawEntry> goodFiles() {
        return {{"meshes/a.vtet", test::unitTetVtet()}, {"scene.json", R"({"objects":[]})"}};
    }
};

TEST_F(VcasePackage, CraftedValidPackageOpens) {
    const auto files = goodFiles();
    const Manifest m = manifestFor(files);
    auto path = dir.write("case.vcase", craftPackage(m, files));
    auto package = CasePackage::open(path);
    EXPECT_EQ(package->manifest(), m);
    EXPECT_EQ(package->name(), path.string());
    EXPECT_EQ(package->read("meshes/a.vtet"), test::unitTetVtet());
    EXPECT_EQ(verify(path), m);
}

// ---- (a) the file ---------------------------------------------------------------------------

TEST_F(VcasePackage, MissingFileIsRejected) {
    EXPECT_THAT(rejectionOf(dir.path() / "case.vcase"), HasSubstr(pkg() + "cannot open package (file does not exist)"));
    EXPECT_THAT(rejectionOf(dir.path()), HasSubstr("cannot open package (not a regular file)"));
}

TEST_F(VcasePackage, PackageSizeLimit) {
    const auto files = goodFiles();
    std::string bytes = craftPackage(manifestFor(files), files);
    EXPECT_EQ(rejection(bytes, Limits{.maxPackageBytes = 100}),
              pkg() + "package is " + std::to_string(bytes.size()) + " bytes, larger than the limit of 100 bytes");
}

// ---- (b) the container ----------------------------------------------------------------------

TEST_F(VcasePackage, TruncatedZipIsRejected) {
    const auto files = goodFiles();
    const std::string bytes = craftPackage(manifestFor(files), files);
    for (size_t keep : {bytes.size() / 2, bytes.size() - 1, size_t(10), size_t(0)})
        EXPECT_THAT(rejection(bytes.substr(0, keep)),
                    HasSubstr(pkg() + "not a valid zip archive (truncated or corrupt)"))
            << keep;
    EXPECT_THAT(rejection(std::string(4096, 'x')), HasSubstr(pkg() + "not a valid zip archive (truncated or corrupt)"));
}

TEST_F(VcasePackage, TooManyEntriesDefaultLimit) {
    std::vector<RawEntry> files;
    for (int i = 0; i < 4096; ++i)
        files.push_back({std::to_string(i) + ".txt", "", false});
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files)),
              pkg() + "package has 4097 entries, more than the limit of 4096");
}

TEST_F(VcasePackage, TooManyEntriesCustomLimit) {
    const auto files = goodFiles();
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files), Limits{.maxEntries = 2}),
              pkg() + "package has 3 entries, more than the limit of 2");
}

// ---- (c) entry names and types -----------------------------------------------------------------

TEST_F(VcasePackage, DotDotEntryIsRejected) {
    for (const char* name : {"../x", "meshes/../../x", "a/.."}) {
        std::vector<RawEntry> files{{name, "evil"}};
        EXPECT_EQ(rejection(craftPackage(manifestFor({}), files)),
                  pkg() + name + ": entry name escapes the package ('..' component)");
    }
}

TEST_F(VcasePackage, AbsoluteEntryIsRejected) {
    std::vector<RawEntry> files{{"/etc/passwd", "root"}};
    EXPECT_EQ(rejection(craftPackage(manifestFor({}), files)), pkg() + "/etc/passwd: absolute entry path");
    files = {{"C:/Windows/x.dll", "x"}};
    EXPECT_EQ(rejection(craftPackage(manifestFor({}), files)),
              pkg() + "C:/Windows/x.dll: absolute entry path (drive letter)");
    files = {{"meshes\\a.vtet", "x"}};
    EXPECT_EQ(rejection(craftPackage(manifestFor({}), files)),
              pkg() + "meshes\\a.vtet: entry name contains a backslash (paths use '/')");
}

TEST_F(VcasePackage, ControlCharactersInNamesAreEscaped) {
    std::vector<RawEntry> files{{"a\nb", "x"}};
    EXPECT_THAT(rejection(craftPackage(manifestFor({}), files)),
                HasSubstr(pkg() + "a\\x0ab: entry name contains the character \\x0a"));
}

TEST_F(VcasePackage, SymlinkEntryIsRejected) {
    std::vector<RawEntry> files{{"meshes/link.vtet", "/etc/passwd", false, 0120777}};
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files)),
              pkg() + "meshes/link.vtet: symbolic link entries are not allowed");
}

TEST_F(VcasePackage, NonRegularEntryIsRejected) {
    std::vector<RawEntry> files{{"fifo", "", false, 0010644}};
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files)),
              pkg() + "fifo: entry is not a regular file (Unix file type 010000)");
}

TEST_F(VcasePackage, DuplicateEntryIsRejected) {
    // libzip refuses to write a repeated name, so write two names and rename one in place.
    std::vector<RawEntry> files{{"a.txt", "alpha", false}, {"b.txt", "bravo", false}};
    std::string bytes = craftPackage(manifestFor({files[0]}), files);
    ASSERT_EQ(test::patchBytes(bytes, "b.txt", "a.txt"), 2u); // local header + central directory
    EXPECT_EQ(rejection(bytes), pkg() + "a.txt: duplicate entry");
}

TEST_F(VcasePackage, NamesDifferingOnlyInCaseAreRejected) {
    std::vector<RawEntry> files{{"Scene.json", "{}"}, {"scene.json", "{}"}};
    EXPECT_THAT(rejection(craftPackage(manifestFor(files), files)),
                HasSubstr(pkg() + "scene.json: entry name collides with 'Scene.json'"));
}

TEST_F(VcasePackage, EntryUnderAFileIsRejected) {
    std::vector<RawEntry> files{{"a", "x"}, {"a/b", "y"}};
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files)), pkg() + "a/b: entry lies under the file entry 'a'");
}

TEST_F(VcasePackage, DirectoryEntriesOnlyAsParentsOfFiles) {
    const auto files = goodFiles();
    std::vector<RawEntry> withDirs{{"meshes/", "", false, 040755}};
    withDirs.insert(withDirs.end(), files.begin(), files.end());
    auto path = dir.write("dirs.vcase", craftPackage(manifestFor(files), withDirs));
    EXPECT_NO_THROW(CasePackage::open(path));

    withDirs.push_back({"empty/", "", false, 040755});
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), withDirs)),
              pkg() + "empty/: directory entry contains no packaged file (only parents of files "
                      "may appear)");
}

// ---- (d) sizes --------------------------------------------------------------------------------

TEST_F(VcasePackage, CompressionRatioBombIsRejected) {
    std::vector<RawEntry> files{{"textures/bomb.raw", std::string(8u << 20, '\0')}};
    std::string message = rejection(craftPackage(manifestFor(files), files));
    EXPECT_THAT(message, HasSubstr(pkg() + "textures/bomb.raw: compression ratio "));
    EXPECT_THAT(message, HasSubstr(":1 exceeds the limit of 200:1 (possible zip bomb)"));
}

TEST_F(VcasePackage, ManySmallEntriesThatExpandTheWholePackageAreRejected) {
    // 300 entries of 512 KiB of zeros: each under the per-entry rule's 1 MiB, 150 MiB together
    // from a package of about 150 KiB. Refused from the central directory, before any inflate.
    std::vector<RawEntry> files;
    for (int i = 0; i < 300; ++i)
        files.push_back({"textures/t" + std::to_string(i) + ".raw", std::string(512u << 10, '\0')});
    const std::string bytes = craftPackage(manifestFor(files), files);
    const std::string message = rejection(bytes);
    EXPECT_THAT(message, HasSubstr(pkg() + "the entries expand to "));
    EXPECT_THAT(message, HasSubstr(" times the package's " + std::to_string(bytes.size()) +
                                   " bytes, more than the limit of 200:1 (possible zip bomb)"));
    // The shipped kind of package passes: text that compresses a few times.
    std::string digits(3u << 20, ' ');
    uint32_t state = 12345;
    for (char& c : digits) {
        state = state * 1664525u + 1013904223u;
        c = "0123456789 .\n-"[(state >> 24) % 15];
    }
    std::vector<RawEntry> text{{"textures/noise.raw", digits}};
    EXPECT_NO_THROW(CasePackage::open(dir.write("text.vcase", craftPackage(manifestFor(text), text))));
}

TEST_F(VcasePackage, EntryAndTotalSizeLimits) {
    std::vector<RawEntry> files{{"a.bin", std::string(2000, 'a')}, {"b.bin", std::string(2000, 'b')}};
    const std::string bytes = craftPackage(manifestFor(files), files);
    EXPECT_EQ(rejection(bytes, Limits{.maxEntryBytes = 1999}),
              pkg() + "a.bin: uncompressed size 2000 bytes exceeds the per-entry limit of 1999 bytes");
    const uint64_t manifestSize = manifestFor(files).toJsonText().size();
    EXPECT_EQ(rejection(bytes, Limits{.maxTotalBytes = manifestSize + 3000}),
              pkg() + "total uncompressed size exceeds the limit of " + std::to_string(manifestSize + 3000) +
                  " bytes (reached at entry 'b.bin')");
}

TEST_F(VcasePackage, UnsupportedCompressionMethodIsRejected) {
    if (!zip_compression_method_supported(ZIP_CM_BZIP2, 1)) GTEST_SKIP() << "this libzip cannot write bzip2";
    std::vector<RawEntry> files{{"a.txt", "hello", true, std::nullopt, ZIP_CM_BZIP2}};
    EXPECT_EQ(rejection(craftPackage(manifestFor(files), files)),
              pkg() + "a.txt: compression method 12 is not supported (use store or deflate)");
}

// ---- (e) manifest -----------------------------------------------------------------------------

TEST_F(VcasePackage, MissingManifestIsRejected) {
    EXPECT_EQ(rejection(craftZip(goodFiles())),
              pkg() + "manifest.json: missing (a package needs manifest.json at its root)");
}

TEST_F(VcasePackage, InvalidJsonManifestIsRejected) {
    std::vector<RawEntry> entries{{"manifest.json", "{\"schemaVersion\": 1,"}};
    EXPECT_THAT(rejection(craftZip(entries)), HasSubstr(pkg() + "manifest.json: invalid JSON ("));
}

TEST_F(VcasePackage, ManifestMissingRequiredFieldIsRejected) {
    nlohmann::json j = manifestFor({}).toJson();
    j.erase("caseId");
    std::vector<RawEntry> entries{{"manifest.json", j.dump()}};
    EXPECT_EQ(rejection(craftZip(entries)), pkg() + "manifest.json: caseId: required field is missing");
}

TEST_F(VcasePackage, ManifestSizeLimit) {
    const auto files = goodFiles();
    const Manifest m = manifestFor(files);
    EXPECT_EQ(rejection(craftPackage(m, files), Limits{.maxManifestBytes = 10}),
              pkg() + "manifest.json: size " + std::to_string(m.toJsonText().size()) +
                  " bytes exceeds the manifest limit of 10 bytes");
}

// ---- (f) listed files -------------------------------------------------------------------------

TEST_F(VcasePackage, HashMismatchIsRejected) {
    auto files = goodFiles();
    Manifest m = manifestFor(files);
    const std::string listed = m.files[0].sha256;
    files[0].bytes[files[0].bytes.size() - 2] = '2'; // same size, different content
    const std::string actual = sha256Hex(files[0].bytes);
    EXPECT_EQ(rejection(craftPackage(m, files)),
              pkg() + "meshes/a.vtet: sha256 mismatch (manifest says " + listed + ", file has " + actual + ")");
}

TEST_F(VcasePackage, SizeMismatchIsRejected) {
    const auto files = goodFiles();
    Manifest m = manifestFor(files);
    m.files[1].size += 1;
    EXPECT_EQ(rejection(craftPackage(m, files)), pkg() + "scene.json: size mismatch (manifest says " +
                                                     std::to_string(m.files[1].size) + " bytes, entry has " +
                                                     std::to_string(files[1].bytes.size()) + " bytes)");
}

TEST_F(VcasePackage, ListedFileMissingIsRejected) {
    const auto files = goodFiles();
    Manifest m = manifestFor(files);
    m.files.push_back({"meshes/gone.vtet", 3, sha256Hex("abc")});
    EXPECT_EQ(rejection(craftPackage(m, files)),
              pkg() + "meshes/gone.vtet: listed in manifest.json but missing from the package");
}

TEST_F(VcasePackage, UnlistedFileIsRejected) {
    auto files = goodFiles();
    const Manifest m = manifestFor(files);
    files.push_back({"extra.txt", "not in the manifest"});
    EXPECT_EQ(rejection(craftPackage(m, files)), pkg() + "extra.txt: file is not listed in manifest.json");
}

TEST_F(VcasePackage, CorruptEntryDataIsRejected) {
    std::vector<RawEntry> files{{"data.bin", "0123456789-PAYLOAD-0123456789", false}};
    std::string bytes = craftPackage(manifestFor(files), files);
    ASSERT_EQ(test::patchBytes(bytes, "-PAYLOAD-", "-PAYLOAX-"), 1u); // CRC-32 no longer matches
    EXPECT_THAT(rejection(bytes), HasSubstr(pkg() + "data.bin: cannot decompress entry (corrupt data: "));
}

// ---- (g) compatibility ------------------------------------------------------------------------

TEST_F(VcasePackage, SchemaVersionFromTheFutureIsRejected) {
    const auto files = goodFiles();
    Manifest m = manifestFor(files);
    m.schemaVersion = 99;
    EXPECT_EQ(rejection(craftPackage(m, files)),
              pkg() + "manifest.json: schemaVersion 99 is newer than this player supports (1)");
    m.schemaVersion = 0;
    EXPECT_EQ(rejection(craftPackage(m, files)), pkg() + "manifest.json: schemaVersion 0 is not valid (must be >= 1)");
}

TEST_F(VcasePackage, MinPlayerVersionTooNewIsRejected) {
    const auto files = goodFiles();
    Manifest m = manifestFor(files);
    m.minPlayerVersion = "99.0.0";
    EXPECT_EQ(rejection(craftPackage(m, files)),
              pkg() + "manifest.json: minPlayerVersion 99.0.0 is newer than this player (" + VISCERA_VERSION + ")");
}

// ---- (h) meshes -------------------------------------------------------------------------------

TEST_F(VcasePackage, UnparsableVtetIsRejected) {
    auto files = goodFiles();
    files.push_back({"meshes/bad.vtet", "vtet 1\nvertices 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                        "tets 1\n0 1 2 9\n"});
    std::string message = rejection(craftPackage(manifestFor(files), files));
    EXPECT_THAT(message, HasSubstr(pkg().substr(0, pkg().size() - 2) + ":meshes/bad.vtet"));
    files.back().bytes = "not a mesh";
    EXPECT_THAT(rejection(craftPackage(manifestFor(files), files)),
                HasSubstr(pkg().substr(0, pkg().size() - 2) + ":meshes/bad.vtet"));
}

// ---- order of the checks ----------------------------------------------------------------------

TEST_F(VcasePackage, ChecksRunInTheDocumentedOrder) {
    auto files = goodFiles();
    Manifest m = manifestFor(files);
    m.schemaVersion = 99;                         // (g): the manifest's alone, so before (f)
    files.push_back({"meshes/bad.vtet", "junk"}); // (f) unlisted, and (h)
    files[1].bytes[0] = '[';                      // (f) hash of scene.json
    EXPECT_THAT(rejection(craftPackage(m, files)), HasSubstr("manifest.json: schemaVersion 99 is newer"));
    m.schemaVersion = 1;
    EXPECT_THAT(rejection(craftPackage(m, files)), HasSubstr("scene.json: sha256 mismatch"));
    m.files[1].sha256 = sha256Hex(files[1].bytes);
    EXPECT_THAT(rejection(craftPackage(m, files)), HasSubstr("meshes/bad.vtet: file is not listed in manifest.json"));
    files.push_back({"../x", "evil"}); // (c) beats everything after it
    EXPECT_THAT(rejection(craftZip(files)), HasSubstr("../x: entry name escapes the package"));
    EXPECT_THAT(rejection(craftPackage(m, files), Limits{.maxEntries = 3}),
                HasSubstr("entries, more than the limit of 3"));
}

TEST_F(VcasePackage, ReadOfUnlistedPathThrows) {
    const auto files = goodFiles();
    auto path = dir.write("case.vcase", craftPackage(manifestFor(files), files));
    auto package = CasePackage::open(path);
    EXPECT_TRUE(package->contains("scene.json"));
    EXPECT_FALSE(package->contains("manifest.json"));
    for (const char* name : {"nope.txt", "manifest.json", "../x"}) {
        try {
            package->read(name);
            ADD_FAILURE() << name << " was readable";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()), pkg() + name + ": not listed in manifest.json");
        }
    }
}

TEST_F(VcasePackage, FromBytesUsesTheGivenName) {
    const auto files = goodFiles();
    const std::string bytes = craftPackage(manifestFor(files), files);
    auto package = CasePackage::fromBytes(bytes, "download.vcase");
    EXPECT_EQ(package->name(), "download.vcase");
    EXPECT_EQ(package->read("scene.json"), files[1].bytes);
    try {
        CasePackage::fromBytes(bytes.substr(0, 50), "download.vcase");
        ADD_FAILURE() << "truncated package accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("download.vcase: not a valid zip archive"));
    }
}

} // namespace
} // namespace viscera::vcase
