// Writing .vcase packages: round trip, determinism, name rules, verification before writing.
#include "case/case_package.hpp"
#include "case/case_writer.hpp"
#include "case/sha256.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "zip_craft.hpp"

#include <zip.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <ctime>

namespace viscera::vcase {
namespace {

using ::testing::HasSubstr;

Manifest header() {
    Manifest m;
    m.caseId = "liver-resection-01";
    m.caseVersion = "1.0.0";
    m.minPlayerVersion = "0.1.0";
    m.title = "Liver resection";
    m.features = {"xpbd", "gravity", "fem"};
    m.device = {{"haptics", {{"devices", 1}}}};
    return m;
}

std::string allByteValues() {
    std::string bytes;
    for (int round = 0; round < 64; ++round)
        for (int b = 0; b < 256; ++b)
            bytes.push_back(static_cast<char>((b * 7 + round) & 0xff));
    return bytes;
}

/// The InputError message thrown by `f`, or a test failure.
template <class F> std::string messageOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        return message;
    }
    ADD_FAILURE() << "no InputError thrown";
    return "";
}

/// Entry names of a package in archive order, read with libzip.
std::vector<std::string> entryOrder(const std::string& bytes) {
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* src = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
    zip_t* za = zip_open_from_source(src, ZIP_RDONLY, &error);
    std::vector<std::string> names;
    if (!za) {
        zip_source_free(src);
        ADD_FAILURE() << "cannot reopen the package";
        return names;
    }
    for (zip_int64_t i = 0; i < zip_get_num_entries(za, 0); ++i)
        names.push_back(zip_get_name(za, i, 0));
    zip_discard(za);
    zip_error_fini(&error);
    return names;
}

TEST(VcaseWriter, RoundTripPreservesBytesAndManifest) {
    test::ScratchDir dir;
    const std::string binary = allByteValues();
    CaseWriter writer(header());
    writer.addFile("scene.json", R"({"objects":["liver"]})");
    writer.addFile("meshes/liver.vtet", test::unitTetVtet());
    writer.addFile("textures/noise.bin", binary);
    writer.addFile("empty.txt", "");
    const auto path = dir.path() / "liver.vcase";
    const Manifest written = writer.write(path);

    EXPECT_EQ(written, writer.manifest());
    ASSERT_EQ(written.files.size(), 4u);
    EXPECT_EQ(written.files[0].path, "empty.txt"); // sorted by path
    EXPECT_EQ(written.files[3].path, "textures/noise.bin");
    EXPECT_EQ(written.files[3].size, binary.size());
    EXPECT_EQ(written.files[3].sha256, sha256Hex(binary));

    auto package = CasePackage::open(path);
    EXPECT_EQ(package->manifest(), written);
    Manifest expected = header();
    expected.files = written.files;
    EXPECT_EQ(package->manifest(), expected);
    EXPECT_EQ(package->read("scene.json"), R"({"objects":["liver"]})");
    EXPECT_EQ(package->read("meshes/liver.vtet"), test::unitTetVtet());
    EXPECT_EQ(package->read("textures/noise.bin"), binary);
    EXPECT_EQ(package->read("empty.txt"), "");
    EXPECT_EQ(verify(path), written);
}

TEST(VcaseWriter, ManifestComesFirstThenFilesSorted) {
    CaseWriter writer(header());
    writer.addFile("z.txt", "z");
    writer.addFile("a/b.txt", "b");
    writer.addFile("a.txt", "a");
    EXPECT_EQ(entryOrder(writer.build()), (std::vector<std::string>{"manifest.json", "a.txt", "a/b.txt", "z.txt"}));
}

TEST(VcaseWriter, OutputIsDeterministic) {
    test::ScratchDir dir;
    auto make = [](bool reversed) {
        CaseWriter writer(header());
        std::vector<std::pair<std::string, std::string>> files = {
            {"meshes/liver.vtet", test::unitTetVtet()}, {"scene.json", "{}"}, {"textures/noise.bin", allByteValues()}};
        if (reversed) std::reverse(files.begin(), files.end());
        for (auto& [path, bytes] : files)
            writer.addFile(path, bytes);
        return writer;
    };
    const std::string first = make(false).build();
    // A different insertion order, time zone and wall-clock second change nothing.
    const char* oldTz = std::getenv("TZ");
    const std::string savedTz = oldTz ? oldTz : "";
    ::setenv("TZ", "Pacific/Kiritimati", 1);
    ::tzset();
    const std::string second = make(true).build();
    if (oldTz)
        ::setenv("TZ", savedTz.c_str(), 1);
    else
        ::unsetenv("TZ");
    ::tzset();
    EXPECT_TRUE(first == second) << "two builds differ";

    make(false).write(dir.path() / "one.vcase");
    make(true).write(dir.path() / "two.vcase");
    EXPECT_TRUE(readFile(dir.path() / "one.vcase") == readFile(dir.path() / "two.vcase"));
    EXPECT_TRUE(readFile(dir.path() / "one.vcase") == first);
}

TEST(VcaseWriter, RejectsBadEntryNamesAtAddTime) {
    CaseWriter writer(header());
    const std::string prefix = "vcase::CaseWriter::addFile(): ";
    EXPECT_EQ(messageOf([&] { writer.addFile("../x", "x"); }),
              prefix + "../x: entry name escapes the package ('..' component)");
    EXPECT_EQ(messageOf([&] { writer.addFile("/etc/passwd", "x"); }), prefix + "/etc/passwd: absolute entry path");
    EXPECT_EQ(messageOf([&] { writer.addFile("D:/x", "x"); }), prefix + "D:/x: absolute entry path (drive letter)");
    EXPECT_EQ(messageOf([&] { writer.addFile("a\\b", "x"); }),
              prefix + "a\\b: entry name contains a backslash (paths use '/')");
    EXPECT_EQ(messageOf([&] { writer.addFile("meshes/", "x"); }),
              prefix + "meshes/: entry name has an empty component ('//' or a trailing '/')");
    EXPECT_EQ(messageOf([&] { writer.addFile("manifest.json", "{}"); }),
              prefix + "manifest.json: reserved name (the writer generates manifest.json)");
    writer.addFile("Scene.json", "{}");
    EXPECT_EQ(messageOf([&] { writer.addFile("Scene.json", "{}"); }), prefix + "Scene.json: already added");
    EXPECT_EQ(messageOf([&] { writer.addFile("scene.json", "{}"); }),
              prefix + "scene.json: collides with 'Scene.json' (names differ only in letter case)");
    EXPECT_EQ(writer.fileCount(), 1u);
}

TEST(VcaseWriter, RejectsAnInvalidHeader) {
    Manifest bad = header();
    bad.caseId = "Liver Case";
    EXPECT_THAT(messageOf([&] { CaseWriter w(bad); }), HasSubstr("vcase::CaseWriter: caseId: 'Liver Case' must match"));
    bad = header();
    bad.files.push_back({"a.txt", 1, sha256Hex("a")});
    EXPECT_THAT(messageOf([&] { CaseWriter w(bad); }), HasSubstr("vcase::CaseWriter: files: must be empty"));
    bad = header();
    bad.units["length"] = "mm";
    EXPECT_THAT(messageOf([&] { CaseWriter w(bad); }), HasSubstr("units.length: 'mm' is not supported"));
}

TEST(VcaseWriter, NeverWritesAPackageThePlayerWouldReject) {
    test::ScratchDir dir;
    const auto path = dir.path() / "future.vcase";
    Manifest future = header();
    future.minPlayerVersion = "99.0.0";
    CaseWriter tooNew(future);
    EXPECT_THAT(messageOf([&] { tooNew.write(path); }),
                HasSubstr(path.string() + ": manifest.json: minPlayerVersion 99.0.0 is newer"));
    EXPECT_FALSE(std::filesystem::exists(path));

    CaseWriter badMesh(header());
    badMesh.addFile("meshes/bad.vtet", "vtet 1\nvertices 1\n0 0 0\ntets 1\n0 0 0 0\n");
    EXPECT_THAT(messageOf([&] { badMesh.write(path); }), HasSubstr(path.string() + ":meshes/bad.vtet"));
    EXPECT_FALSE(std::filesystem::exists(path));

    CaseWriter many(header());
    for (int i = 0; i < 3; ++i)
        many.addFile(std::to_string(i) + ".txt", "x");
    EXPECT_EQ(messageOf([&] { many.build(Limits{.maxEntries = 3}); }),
              "vcase::CaseWriter::build(): package has 4 entries, more than the limit of 3");
}

TEST(VcaseWriter, WriteReplacesAnExistingPackage) {
    test::ScratchDir dir;
    const auto path = dir.write("case.vcase", "old contents");
    CaseWriter writer(header());
    writer.addFile("scene.json", "{}");
    writer.write(path);
    EXPECT_EQ(CasePackage::open(path)->read("scene.json"), "{}");
}

} // namespace
} // namespace viscera::vcase
