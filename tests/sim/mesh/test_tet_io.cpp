#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <sys/resource.h>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {
std::string errorOf(const std::string& text) {
    try {
        parseVtet(text, "organ.vtet");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "no error";
}
const char* kHeader = "vtet 1\nvertices 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
} // namespace

TEST(TetIo, RoundTripIsExact) {
    auto m = makeBoxTetMesh({Vec3(0.1, -0.2, 0.3), Vec3(0.1 / 3, 0.07, 0.011), {3, 2, 2}});
    auto back = parseVtet(formatVtet(*m), "mem");
    ASSERT_EQ(back->tetCount(), m->tetCount());
    EXPECT_EQ(back->tets(), m->tets());
    EXPECT_EQ(back->positions(), m->positions());
}

TEST(TetIo, WriteIsAtomicAndReadable) {
    auto dir = std::filesystem::temp_directory_path() / "viscera_test_tet_io";
    std::filesystem::create_directories(dir);
    auto path = dir / "slab.vtet";
    auto m = makeBoxTetMesh({});
    writeVtet(path, *m);
    writeVtet(path, *m); // overwrite in place
    auto back = readVtet(path);
    EXPECT_EQ(back->tets(), m->tets());
    for (auto& e : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().rfind(".slab", 0), std::string::npos)
            << "temporary file left behind: " << e.path();
    std::filesystem::remove_all(dir);
}

TEST(TetIo, ErrorsNameFileLineAndRule) {
    EXPECT_THAT(errorOf(""), HasSubstr("organ.vtet: unexpected end of file (expected header"));
    EXPECT_THAT(errorOf("mesh 1\n"), HasSubstr("organ.vtet: line 1: header must be 'vtet <version>'"));
    EXPECT_THAT(errorOf("vtet 7\n"), HasSubstr("unsupported vtet version 7"));
    EXPECT_THAT(errorOf("vtet 1\nvertices 1\n0 nan 0\ntets 0\n"),
                HasSubstr("line 3: vertex 0 has a non-finite coordinate"));
    EXPECT_THAT(errorOf("vtet 1\nvertices 1\n0 x 0\n"), HasSubstr("line 3: coordinate 'x' is not a valid number"));
    EXPECT_THAT(errorOf(std::string(kHeader) + "tets 1\n0 1 2 4\n"),
                HasSubstr("line 8: tet 0 references vertex 4 (mesh has 4 vertices)"));
    EXPECT_THAT(errorOf(std::string(kHeader) + "tets 2\n0 1 2 3\n"),
                HasSubstr("unexpected end of file (expected tet 1)"));
    EXPECT_THAT(errorOf(std::string(kHeader) + "tets 1\n0 1 2 3\n9 9 9 9\n"),
                HasSubstr("unexpected content after the last tet"));
    EXPECT_THAT(errorOf(std::string(kHeader) + "tets 0\n"), HasSubstr("mesh has no tets"));
    EXPECT_THAT(errorOf(std::string(kHeader) + "tets 1\n0 1 1 3\n"), HasSubstr("tet 0 repeats vertex 1"));
    EXPECT_THAT(errorOf("vtet 1\nvertices -3\n"), HasSubstr("vertices count -3 is out of range"));
    EXPECT_EQ(errorOf(std::string(kHeader) + "# comment\n\ntets 1\n0 1 2 3\n"), "no error");
}

// Found by fuzz_vtet (out-of-memory): a header claiming 94,967,295 vertices over a few bytes made
// the reader reserve 2.3 GB before reading a line. Under an address-space limit of 1 GiB above
// what the process uses now, such a file (and one at the 2^28 maximum) is refused cleanly.
TEST(TetIo, AHugeCountInTheHeaderCostsNoMoreMemoryThanTheFile) {
    rlimit old{};
    ASSERT_EQ(getrlimit(RLIMIT_AS, &old), 0);
    long pages = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
        std::fclose(f);
    }
    ASSERT_GT(pages, 0);
    rlimit lim = old;
    lim.rlim_cur = rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE)) + (rlim_t(1) << 30);
    if (old.rlim_max != RLIM_INFINITY && lim.rlim_cur > old.rlim_max) lim.rlim_cur = old.rlim_max;
    ASSERT_EQ(setrlimit(RLIMIT_AS, &lim), 0);
    std::string what;
    for (const char* text : {"vtet 1\nvertices 94967295\n0 0 0\n1 0 0\n", "vtet 1\nvertices 268435456\n0 0 0\n",
                             "vtet 1\nvertices 1\n0 0 0\ntets 268435456\n0 0 0 0\n"}) {
        try {
            (void)parseVtet(text, "huge.vtet");
            what += "(accepted) ";
        } catch (const viscera::InputError&) {
            what += "refused ";
        } catch (const std::bad_alloc&) {
            what += "bad_alloc ";
        }
    }
    setrlimit(RLIMIT_AS, &old);
    EXPECT_EQ(what, "refused refused refused ");
}
