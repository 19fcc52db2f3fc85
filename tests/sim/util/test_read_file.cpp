#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace viscera;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace {

std::string readError(const std::filesystem::path& path, std::uintmax_t maxBytes = kReadFileMaxBytes,
                      std::string_view limitName = {}) {
    try {
        readFile(path, maxBytes, limitName);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(ReadFile, ReadsTheWholeFileUpToTheCap) {
    test::Scratch scratch("viscera-read-file");
    const std::string bytes("a\0b\nc", 5);
    writeFileAtomic(scratch / "five.bin", bytes);
    EXPECT_EQ(readFile(scratch / "five.bin"), bytes);
    EXPECT_EQ(readFile(scratch / "five.bin", 5), bytes); // the cap is inclusive
    writeFileAtomic(scratch / "empty.bin", "");
    EXPECT_EQ(readFile(scratch / "empty.bin", 0), "");
}

TEST(ReadFile, RejectsAFileOverTheCapNamingFileAndLimit) {
    test::Scratch scratch("viscera-read-file");
    const std::string path = scratch / "six.bin";
    writeFileAtomic(path, "123456");
    EXPECT_EQ(readError(path, 5), path + ": file is 6 bytes, larger than the limit of 5 bytes");
    EXPECT_EQ(readError(path, 5, "Options::maxBytes"),
              path + ": file is 6 bytes, larger than the limit of 5 bytes (Options::maxBytes)");
}

TEST(ReadFile, DefaultCapIs256MiB) {
    EXPECT_EQ(kReadFileMaxBytes, 256u * 1024u * 1024u);
}

TEST(ReadFile, MissingOrDirectoryIsOneLineNamingThePath) {
    test::Scratch scratch("viscera-read-file");
    const std::string missing = scratch / "absent.txt";
    EXPECT_EQ(readError(missing), missing + ": cannot open for reading (file not found)");
    EXPECT_EQ(readError(scratch.dir), scratch.dir.string() + ": cannot open for reading (is a directory, not a file)");
}

TEST(ReadFile, OnlyRegularFilesAreOpenedAndAFifoDoesNotBlock) {
    // A device has no end (/dev/zero) and a FIFO without a writer blocks an open: neither is a file
    // a user gives as input, and neither is read.
    EXPECT_EQ(readError("/dev/zero", 100000), "/dev/zero: is not a regular file (a character device)");
    test::Scratch scratch("viscera-read-file");
    const std::string fifo = scratch / "track.csv";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_EQ(readError(fifo), fifo + ": is not a regular file (a FIFO)"); // returns at once, no writer needed
    // Through a link the same.
    const std::string link = scratch / "link.csv";
    ASSERT_EQ(::symlink(fifo.c_str(), link.c_str()), 0);
    EXPECT_EQ(readError(link), link + ": is not a regular file (a FIFO)");
}

TEST(WriteFileAtomic, SweepsTheTemporariesOfAWriterThatNoLongerRuns) {
    test::Scratch scratch("viscera-write-file");
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    ASSERT_EQ(::waitpid(child, nullptr, 0), child); // a pid that no longer runs
    const std::filesystem::path d = scratch.dir;
    const auto dead = d / (".r.json." + std::to_string(child) + ".tmpAbC123");
    const auto live = d / (".r.json." + std::to_string(::getpid()) + ".tmpXyZ789");
    const auto other = d / (".other.json." + std::to_string(child) + ".tmpAbC123");
    const auto young = d / (".r.json." + std::to_string(child) + ".tmpNeW456"); // a minute old: kept
    for (const auto& f : {dead, live, other, young})
        writeFileAtomic(f, "partial");
    const auto now = std::filesystem::file_time_type::clock::now();
    for (const auto& f : {dead, live, other})
        std::filesystem::last_write_time(f, now - std::chrono::hours(2));
    std::filesystem::last_write_time(young, now - std::chrono::minutes(1));
    writeFileAtomic(scratch / "r.json", "{}\n");
    EXPECT_FALSE(std::filesystem::exists(dead)) << "killed writer's temporary swept";
    EXPECT_TRUE(std::filesystem::exists(live)) << "a running writer's temporary is left alone";
    EXPECT_TRUE(std::filesystem::exists(other)) << "another destination's temporary is left alone";
    EXPECT_TRUE(std::filesystem::exists(young)) << "under an hour old: perhaps a writer of another machine";
    EXPECT_EQ(readFile(scratch / "r.json"), "{}\n");
    for (const auto& e : std::filesystem::directory_iterator(scratch.dir)) // no temporary of this write left
        EXPECT_EQ(e.path().filename().string().find(".r.json." + std::to_string(::getpid()) + ".tmp") == 0,
                  e.path() == live)
            << e.path();
}

TEST(RequireNotAnInput, RefusesTheSameFileByAnyNameAndAcceptsAnother) {
    test::Scratch scratch("viscera-not-input");
    const std::filesystem::path d = scratch.dir, input = d / "case.vcase";
    writeFileAtomic(input, "zip");
    std::filesystem::create_directory(d / "sub");
    std::filesystem::create_directory_symlink(d, d / "sub" / "up");
    std::filesystem::create_symlink(input, d / "alias.vcase");
    std::filesystem::create_hard_link(input, d / "hard.vcase");
    auto error = [&](const std::filesystem::path& out) -> std::string {
        try {
            requireNotAnInput(out, "the report", {d / "other.csv", input});
        } catch (const InputError& e) {
            return e.what();
        }
        return "no error";
    };
    for (const auto& same :
         {input, d / "sub" / ".." / "case.vcase", d / "sub" / "up" / "case.vcase", d / "alias.vcase", d / "hard.vcase"})
        EXPECT_EQ(error(same), same.string() + ": cannot write the report over the input '" + input.string() + "'");
    EXPECT_EQ(error(d / "report.json"), "no error");
    EXPECT_EQ(error(d / "sub" / "up" / "report.json"), "no error");
    // Neither exists yet: compared by their resolved paths.
    EXPECT_THAT(error(d / "sub" / "up" / "other.csv"), HasSubstr("over the input '"));
}
