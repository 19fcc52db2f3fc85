#include "sim/material/uniaxial_data.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::string messageOf(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const viscera::InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("(not an InputError) ") + e.what();
    }
    return "(no exception)";
}

/// A folder of its own per test case (tests may run in parallel).
class UniaxialDataFile : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = std::filesystem::temp_directory_path() /
                ("viscera_test_uniaxial_data_" +
                 std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::remove_all(m_dir);
        std::filesystem::create_directories(m_dir);
    }
    void TearDown() override { std::filesystem::remove_all(m_dir); }

    std::filesystem::path write(const std::string& name, const std::string& text) {
        const auto path = m_dir / name;
        std::ofstream(path, std::ios::binary) << text;
        return path;
    }
    std::string errorOf(const std::string& text, StrainMeasure measure = StrainMeasure::Stretch) {
        const auto path = write("data.csv", text);
        return messageOf([&] { readUniaxialData(path, measure); });
    }

    std::filesystem::path m_dir;
};

} // namespace

TEST_F(UniaxialDataFile, ReadsEverySeparatorHeaderCommentsAndBlankLines) {
    const std::string rows[] = {
        "stretch,nominal stress [Pa]\n0.9,-100\n1.0,0\n1.1,120\n",
        "# machine export\r\n\r\nstretch;stress\r\n0.9;-100\r\n1.0 ; 0\r\n# mid comment\r\n1.1;120\r\n",
        "0.9\t-100\n1.0\t0\n\n1.1\t120",
        "  0.9   -1e2\n1 0\n+1.1 +1.2e+2\n",
        "\xEF\xBB\xBF\"stretch\" \"stress\"\n0.9 -100\n1.0 0\n1.1 120\n",
    };
    for (const std::string& text : rows) {
        const UniaxialData d = readUniaxialData(write("ok.txt", text), StrainMeasure::Stretch);
        ASSERT_EQ(d.size(), 3u) << text;
        EXPECT_EQ(d.stretch, (std::vector<double>{0.9, 1.0, 1.1})) << text;
        EXPECT_EQ(d.nominalStress, (std::vector<double>{-100, 0, 120})) << text;
    }
    const UniaxialData d =
        readUniaxialData(write("c.csv", "# c\nstretch,stress\n0.9,-1\n\n1,0\n1.1,1\n"), StrainMeasure::Stretch);
    EXPECT_EQ(d.line, (std::vector<int>{3, 5, 6}));
}

TEST_F(UniaxialDataFile, EngineeringStrainBecomesStretch) {
    const UniaxialData d = readUniaxialData(write("strain.csv", "strain,stress\n-0.2,-500\n0,0\n0.25,400\n"),
                                            StrainMeasure::EngineeringStrain);
    EXPECT_EQ(d.stretch, (std::vector<double>{0.8, 1.0, 1.25}));
    EXPECT_EQ(d.nominalStress, (std::vector<double>{-500, 0, 400}));
}

TEST_F(UniaxialDataFile, EveryRuleNamesFileLineAndColumn) {
    EXPECT_EQ(errorOf("stretch,stress\n0.9,-1\n1.0,0\n1.1,1\n1.2,2\n1.3,3\n1.4,abc\n"),
              "data.csv: line 7, column 2: 'abc' is not a number");
    EXPECT_EQ(errorOf("0.9,-1\n1.0\n1.1,1\n"), "data.csv: line 2: has 1 column, expected 2 (stretch, nominal stress)");
    EXPECT_EQ(errorOf("0.9 -1\n1.0 0 7\n1.1 1\n"),
              "data.csv: line 2: has 3 columns, expected 2 (stretch, nominal stress)");
    EXPECT_EQ(errorOf("0.9,-1,\n1.0,0\n1.1,1\n"),
              "data.csv: line 1: has 3 columns, expected 2 (stretch, nominal stress)");
    EXPECT_EQ(errorOf("0.9,-1\n1,5;200\n1.1,1\n"),
              "data.csv: line 2: has 3 columns, expected 2 (stretch, nominal stress)");
    EXPECT_EQ(errorOf("0.9,-1\n,0\n1.1,1\n"), "data.csv: line 2, column 1: the field is empty");
    EXPECT_EQ(errorOf("0.9,-1\n1.0,nan\n1.1,1\n"), "data.csv: line 2, column 2: 'nan' is not a finite number");
    EXPECT_EQ(errorOf("0.9,-1\ninf,0\n1.1,1\n"), "data.csv: line 2, column 1: 'inf' is not a finite number");
    EXPECT_EQ(errorOf("-0.1,-1\n1.0,0\n1.1,1\n"), "data.csv: line 1, column 1: stretch -0.1 must be positive");
    EXPECT_EQ(errorOf("0,-1\n1.0,0\n1.1,1\n"), "data.csv: line 1, column 1: stretch 0 must be positive");
    EXPECT_EQ(errorOf("-1.5,-1\n0,0\n0.1,1\n", StrainMeasure::EngineeringStrain),
              "data.csv: line 1, column 1: engineering strain -1.5 must be greater than -1 (stretch 1 + strain must "
              "be positive)");
    EXPECT_EQ(errorOf("0.9,-1\n1.2,0\n\n1.1,1\n"),
              "data.csv: line 4, column 1: stretch 1.1 does not increase over line 2 (stretch 1.2)");
    EXPECT_EQ(errorOf("0.9,-1\n1.2,0\n1.2,1\n"),
              "data.csv: line 3, column 1: stretch 1.2 does not increase over line 2 (stretch 1.2)");
    EXPECT_EQ(errorOf("0.1,-1\n0.05,0\n", StrainMeasure::EngineeringStrain),
              "data.csv: line 2, column 1: engineering strain 0.05 does not increase over line 1 (engineering "
              "strain 0.1)");
    EXPECT_EQ(errorOf("stretch,stress\n0.9,-1\n1.0,0\n"), "data.csv: has 2 data rows, at least 3 are needed");
    EXPECT_EQ(errorOf("# nothing\n\n"), "data.csv: has 0 data rows, at least 3 are needed");
    EXPECT_EQ(errorOf(""), "data.csv: has 0 data rows, at least 3 are needed");
    // One header at most: a second text line is a bad row.
    EXPECT_EQ(errorOf("stretch,stress\nunits,Pa\n0.9,-1\n"), "data.csv: line 2, column 1: 'units' is not a number");
    // A first line with a number in it is data, not a header.
    EXPECT_EQ(errorOf("stretch,5\n0.9,-1\n1.0,0\n1.1,1\n"), "data.csv: line 1, column 1: 'stretch' is not a number");
    // A trailing comment on a data line is not a comment.
    EXPECT_EQ(errorOf("0.9,-1 # low\n1.0,0\n1.1,1\n"), "data.csv: line 1, column 2: '-1 # low' is not a number");
}

TEST_F(UniaxialDataFile, FileProblemsComeFromTheSharedReader) {
    const auto missing = m_dir / "missing.csv";
    EXPECT_THAT(messageOf([&] { readUniaxialData(missing, StrainMeasure::Stretch); }),
                HasSubstr("missing.csv: cannot open for reading"));
    const auto big = m_dir / "big.csv";
    {
        std::ofstream out(big, std::ios::binary);
        const std::string line = "1.0000000000,0.0000000000000\n";
        for (std::uintmax_t n = 0; n <= UniaxialDataLimits::maxBytes / line.size(); ++n)
            out << line;
    }
    EXPECT_THAT(messageOf([&] { readUniaxialData(big, StrainMeasure::Stretch); }),
                HasSubstr("larger than the limit of 8388608 bytes (UniaxialDataLimits::maxBytes)"));
}

TEST(UniaxialData, ParseNamesTheOrigin) {
    EXPECT_EQ(messageOf([] { parseUniaxialData("1,1\n", "pasted", StrainMeasure::Stretch); }),
              "pasted: has 1 data row, at least 3 are needed");
    const UniaxialData d = parseUniaxialData("1 0\n2 1\n3 2", "pasted", StrainMeasure::Stretch);
    EXPECT_EQ(d.size(), 3u);
}
