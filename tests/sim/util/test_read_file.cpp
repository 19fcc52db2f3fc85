#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

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

TEST(ReadFile, StreamWithoutASizeIsCappedToo) {
    // /dev/zero has no size and no end: the cap alone stops the read.
    EXPECT_THAT(
        readError("/dev/zero", 100000),
        AllOf(HasSubstr("/dev/zero: file is larger than the limit of 100000 bytes"), ::testing::Not(HasSubstr("\n"))));
}
