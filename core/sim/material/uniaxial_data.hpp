#pragma once
/// Uniaxial tension/compression test data (stretch, nominal stress), read from the two-column
/// text or CSV files that test machines and spreadsheets export, for fitting Valanis–Landel
/// curves to it (curve_fit.hpp) [A §4.3.3].
///
/// Format, line by line ('\n' or "\r\n"; a UTF-8 byte-order mark is skipped):
///   - blank lines and lines whose first non-blank character is '#' are ignored;
///   - the first other line is a header when none of its fields is a number (any text, e.g.
///     "stretch,stress [Pa]"); at most one header;
///   - every other line is a row of exactly 2 fields: a line holding ',' or ';' is split at each
///     of them (fields trimmed of spaces and tabs; an empty field is an error), any other line
///     at runs of spaces and tabs. Decimal commas are not supported ("1,5;200" has 3 fields);
///   - column 1: stretch λ, or engineering strain ε (λ = 1 + ε), dimensionless; column 2:
///     nominal (first Piola–Kirchhoff) stress, Pa. Numbers as std::from_chars reads them
///     (decimal or exponent form, an optional leading '+'); NaN and infinities are refused;
///   - λ > 0 (ε > −1), λ strictly increasing from row to row, at least UniaxialDataLimits::minRows rows.
/// Errors are viscera::InputError, one line naming the file, the line, the column where there
/// is one, and the rule:
///   "data.csv: line 7, column 2: 'abc' is not a number"
///   "data.csv: line 4: has 1 column, expected 2 (stretch, nominal stress)"
///   "data.csv: line 9, column 1: stretch 1.1 does not increase over line 8 (stretch 1.2)"
///   "data.csv: has 2 data rows, at least 3 are needed"
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

enum class StrainMeasure {
    Stretch,           ///< column 1 is λ = l/L
    EngineeringStrain, ///< column 1 is ε = (l − L)/L, λ = 1 + ε
};

/// Homogeneous tests (material_response.hpp): what a data row's stretch and stress mean.
enum class LoadCase;

struct UniaxialData {
    std::vector<double> stretch;       ///< λ (#rows), strictly increasing within each test, > 0
    std::vector<double> nominalStress; ///< P11 (#rows), Pa
    std::vector<int> line;             ///< source line of each row (1-based), for messages
    /// The test of each row (#rows); empty: every row is uniaxial. Rows of one test are
    /// consecutive (combineTests()).
    std::vector<LoadCase> loadCase;
    std::size_t size() const { return stretch.size(); }
};

/// The rows of several tests in one data set (e.g. a uniaxial and an equibiaxial test of the same
/// material, fitted together), each row marked with its test.
UniaxialData combineTests(const std::vector<std::pair<LoadCase, UniaxialData>>& tests);

struct UniaxialDataLimits {
    static constexpr std::uintmax_t maxBytes = std::uintmax_t{8} << 20; ///< file size cap (8 MiB)
    static constexpr std::size_t minRows = 3;
};

/// Parses `text`; `origin` names it in messages (readUniaxialData() passes the file name).
UniaxialData parseUniaxialData(std::string_view text, const std::string& origin, StrainMeasure measure);

/// Reads a file of at most UniaxialDataLimits::maxBytes (readFile()'s messages for a missing,
/// unreadable or too large file) and parses it, naming it by its file name.
UniaxialData readUniaxialData(const std::filesystem::path& path, StrainMeasure measure);

} // namespace viscera::sim
