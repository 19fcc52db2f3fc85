// viscera-studio remesh --sample kidney --uv-preview (label gl: the preview renders headless):
// the figures of the three transfers, seam cutting with no triangle over two islands,
// the OBJ with its UVs and the checker preview, four surfaces side by side (the last the seam cut's stretch heat map
// and seams).
#include "render/image.hpp"
#include "sim/util/atomic_file.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

using namespace viscera;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST(StudioCliGl, RemeshTheKidneySampleWithItsUvsAndTheCheckerPreview) {
    test::Scratch s("viscera-studio-cli-gl");
    const auto r = test::runProcess(VISCERA_STUDIO_EXE, {"remesh", "--sample", "kidney", "--voxels", "48", "-o",
                                                         s / "kidney.obj", "--uv-preview", s / "preview.png"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("viscera-studio: remesh: seam cut ("));
    // One `name value` line per figure.
    std::map<std::string, double> fig;
    std::istringstream in(r.out);
    for (std::string line; std::getline(in, line);) {
        std::smatch m;
        if (std::regex_match(line, m, std::regex(R"((uv\.\S+) (-?[0-9][-+.0-9e]*|inf))"))) fig[m[1]] = std::stod(m[2]);
    }
    EXPECT_EQ(fig["uv.source.islands"], 7) << r.out;
    for (const char* method : {"closest", "island", "seam-cut"})
        for (const char* name : {"triangles", "over_two_islands", "flipped", "angle_p50", "angle_p95", "area_p50",
                                 "area_p95", "over_threshold_pct", "uv_error_mean", "uv_error_p95"})
            EXPECT_TRUE(fig.count(std::string("uv.") + method + "." + name)) << method << " " << name << "\n" << r.out;
    for (const char* method : {"closest", "island", "seam-cut"}) // never an infinite figure shown
        for (const char* name : {"angle_max", "area_max", "uv_error_max"})
            EXPECT_TRUE(std::isfinite(fig[std::string("uv.") + method + "." + name])) << method << " " << name;
    EXPECT_GT(fig["uv.closest.over_two_islands"], 0);
    EXPECT_EQ(fig["uv.island.over_two_islands"], fig["uv.closest.over_two_islands"]); // the same uncut mesh
    EXPECT_EQ(fig["uv.seam-cut.over_two_islands"], 0);
    EXPECT_LT(fig["uv.seam-cut.flipped"], fig["uv.closest.flipped"]);
    EXPECT_LT(fig["uv.seam-cut.over_threshold_pct"], fig["uv.closest.over_threshold_pct"]);
    EXPECT_LT(fig["uv.seam-cut.uv_error_mean"], fig["uv.closest.uv_error_mean"]);
    EXPECT_THAT(r.out, HasSubstr("uv.written seam-cut\n"));
    // The OBJ carries per-corner UVs.
    const std::string obj = readFile(s / "kidney.obj");
    EXPECT_THAT(obj, HasSubstr("\nvt "));
    EXPECT_TRUE(std::regex_search(obj, std::regex(R"(\nf \d+/\d+ \d+/\d+ \d+/\d+\n)")));
    // The preview: four surfaces across the image, checker-textured (many distinct colours).
    const render::Image img = render::readPng(s / "preview.png");
    ASSERT_EQ(img.width, 1800);
    ASSERT_EQ(img.height, 700);
    const uint8_t* corner = img.pixel(0, 0);
    std::array<size_t, 4> covered{};
    std::set<int> colours;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const uint8_t* p = img.pixel(x, y);
            if (std::abs(p[0] - corner[0]) + std::abs(p[1] - corner[1]) + std::abs(p[2] - corner[2]) < 12) continue;
            ++covered[size_t(4 * x / img.width)];
            colours.insert((p[0] >> 4) << 8 | (p[1] >> 4) << 4 | (p[2] >> 4));
        }
    for (size_t quarter = 0; quarter < 4; ++quarter) // source, closest point, seam cutting, its stretch and seams
        EXPECT_GT(covered[quarter], size_t(img.width * img.height / 80)) << "quarter " << quarter;
    EXPECT_GT(colours.size(), 40u);
}
