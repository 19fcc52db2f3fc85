// .vweights: exact round trip, atomic write, strict reader messages (file, line, rule).
#include "sim/skeleton/node_weights_io.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::string errorOf(const std::string& text, std::optional<size_t> expected = std::nullopt) {
    try {
        parseNodeWeights(text, "vessel.vweights", expected);
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(NodeWeightsIo, RoundTripIsBitExact) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> logw(-300, 300);
    std::vector<double> w = {1.0, 0.1, 1.0 / 3.0, 1e-3, 1e6, 5e-324, 1.7976931348623157e308, std::nextafter(1.0, 2.0)};
    for (int i = 0; i < 1000; ++i)
        w.push_back(std::pow(10.0, logw(rng)));
    const std::string text = formatNodeWeights(w);
    EXPECT_EQ(text.rfind("vweights 1\nnodes 1008\n", 0), 0u);
    EXPECT_EQ(parseNodeWeights(text, "mem"), w);
    EXPECT_EQ(parseNodeWeights(text, "mem", w.size()), w);
    // Comments, blank lines, CRLF and trailing comments are accepted.
    EXPECT_EQ(parseNodeWeights("# painted\r\nvweights 1\r\n\r\nnodes 2\r\n2.5 # fat\r\n  0.5\r\n", "mem"),
              (std::vector<double>{2.5, 0.5}));
}

TEST(NodeWeightsIo, WriteIsAtomicAndReadable) {
    const auto dir = std::filesystem::temp_directory_path() / "viscera_test_node_weights";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto path = dir / "vessel.vweights";
    writeNodeWeights(path, {1.0, 2.0, 3.0});
    writeNodeWeights(path, {4.0, 0.25}); // overwrite in place
    EXPECT_EQ(readNodeWeights(path), (std::vector<double>{4.0, 0.25}));
    size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1u) << "no temporary file left behind";
    try {
        readNodeWeights(path, 3);
        FAIL() << "no error";
    } catch (const viscera::InputError& e) {
        EXPECT_STREQ(e.what(), "vessel.vweights: line 2: file has 2 nodes, the mesh has 3");
    }
    EXPECT_THROW(readNodeWeights(dir / "missing.vweights"), viscera::InputError);
    std::filesystem::remove_all(dir);
}

TEST(NodeWeightsIo, MalformedFilesAreRejectedNamingLineAndRule) {
    EXPECT_EQ(errorOf(""), "vessel.vweights: unexpected end of file (expected header 'vweights 1')");
    EXPECT_EQ(errorOf("vtet 1\n"), "vessel.vweights: line 1: header must be 'vweights <version>'");
    EXPECT_EQ(errorOf("vweights 2\nnodes 1\n1\n"),
              "vessel.vweights: line 1: unsupported vweights version 2 (supported: 1)");
    EXPECT_EQ(errorOf("vweights x\n"), "vessel.vweights: line 1: version 'x' is not a valid number");
    EXPECT_EQ(errorOf("vweights 1\n"), "vessel.vweights: unexpected end of file (expected 'nodes <count>')");
    EXPECT_EQ(errorOf("vweights 1\nvertices 2\n"), "vessel.vweights: line 2: expected 'nodes <count>'");
    EXPECT_EQ(errorOf("vweights 1\nnodes 0\n"), "vessel.vweights: line 2: node count 0 is out of range [1, 2^28]");
    EXPECT_EQ(errorOf("vweights 1\nnodes -3\n"), "vessel.vweights: line 2: node count -3 is out of range [1, 2^28]");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1\n", 3), "vessel.vweights: line 2: file has 2 nodes, the mesh has 3");
    EXPECT_EQ(errorOf("vweights 1\nnodes 3\n1\n2\n"),
              "vessel.vweights: unexpected end of file (expected weight of node 2 (file declares 3 nodes))");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1\n# c\n-2\n"),
              "vessel.vweights: line 5: weight of node 1 is -2 (must be finite and > 0)");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n0\n1\n"),
              "vessel.vweights: line 3: weight of node 0 is 0 (must be finite and > 0)");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\nnan\n1\n"),
              "vessel.vweights: line 3: weight of node 0 is nan (must be finite and > 0)");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1\ninf\n"),
              "vessel.vweights: line 4: weight of node 1 is inf (must be finite and > 0)");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1e999\n1\n"),
              "vessel.vweights: line 3: weight of node 0 '1e999' is not a valid number");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1.5x\n1\n"),
              "vessel.vweights: line 3: weight of node 0 '1.5x' is not a valid number");
    EXPECT_EQ(errorOf("vweights 1\nnodes 2\n1 2\n1\n"),
              "vessel.vweights: line 3: weight of node 0: expected one value per line, found 2");
    EXPECT_EQ(errorOf("vweights 1\nnodes 1\n1\n2\n"),
              "vessel.vweights: line 4: unexpected content after the last weight (file declares 1 nodes)");
}

TEST(NodeWeightsIo, WriterRefusesInvalidWeights) {
    EXPECT_THROW(formatNodeWeights({}), std::invalid_argument);
    try {
        formatNodeWeights({1.0, 2.0, 3.0, NAN});
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::formatNodeWeights(): weight of node 3 is nan (must be finite and > 0)"));
    }
    EXPECT_THROW(formatNodeWeights({1.0, -1.0}), std::invalid_argument);
    EXPECT_THROW(formatNodeWeights({0.0}), std::invalid_argument);
    const auto dir = std::filesystem::temp_directory_path() / "viscera_test_node_weights_bad";
    std::filesystem::create_directories(dir);
    EXPECT_THROW(writeNodeWeights(dir / "w.vweights", {INFINITY}), std::invalid_argument);
    EXPECT_FALSE(std::filesystem::exists(dir / "w.vweights"));
    std::filesystem::remove_all(dir);
}
