#include "sim/material/uniaxial_data.hpp"

#include "sim/material/material_response.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <system_error>

namespace viscera::sim {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
        s.remove_suffix(1);
    return s;
}

/// Fields of a line (see the header: ',' / ';' separated, else whitespace separated).
void splitFields(std::string_view line, std::vector<std::string_view>& fields) {
    fields.clear();
    if (line.find_first_of(",;") != std::string_view::npos) {
        std::size_t start = 0;
        for (;;) {
            const std::size_t end = line.find_first_of(",;", start);
            fields.push_back(trim(line.substr(start, end == std::string_view::npos ? end : end - start)));
            if (end == std::string_view::npos) break;
            start = end + 1;
        }
        return;
    }
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
            ++i;
        if (i >= line.size()) break;
        std::size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t')
            ++j;
        fields.push_back(line.substr(i, j - i));
        i = j;
    }
}

/// The number a whole field spells (NaN and infinities included), or nothing.
std::optional<double> parseNumber(std::string_view field) {
    if (field.size() > 1 && field.front() == '+' && field[1] != '-') field.remove_prefix(1);
    double value = 0;
    const auto res = std::from_chars(field.data(), field.data() + field.size(), value);
    if (res.ec != std::errc() || res.ptr != field.data() + field.size()) return std::nullopt;
    return value;
}

} // namespace

UniaxialData parseUniaxialData(std::string_view text, const std::string& origin, StrainMeasure measure) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    const bool strain = measure == StrainMeasure::EngineeringStrain;
    const char* abscissa = strain ? "engineering strain" : "stretch";
    UniaxialData data;
    std::vector<std::string_view> fields;
    bool seenFirst = false;
    int lineNo = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::string_view content = trim(line);
        if (content.empty() || content.front() == '#') continue;
        splitFields(content, fields);
        const std::string at = origin + ": line " + std::to_string(lineNo);
        if (!seenFirst) {
            seenFirst = true;
            bool anyNumber = false;
            for (std::string_view f : fields)
                anyNumber = anyNumber || parseNumber(f).has_value();
            if (!anyNumber) continue; // the header
        }
        if (fields.size() != 2)
            throw InputError(at + ": has " + std::to_string(fields.size()) +
                             (fields.size() == 1 ? " column" : " columns") + ", expected 2 (" + abscissa +
                             ", nominal stress)");
        double v[2];
        for (int c = 0; c < 2; ++c) {
            const std::string col = at + ", column " + std::to_string(c + 1) + ": ";
            const std::string_view f = fields[static_cast<std::size_t>(c)];
            if (f.empty()) throw InputError(col + "the field is empty");
            const std::optional<double> n = parseNumber(f);
            if (!n) throw InputError(col + "'" + std::string(f) + "' is not a number");
            if (!std::isfinite(*n)) throw InputError(col + "'" + std::string(f) + "' is not a finite number");
            v[c] = *n;
        }
        const double stretch = strain ? 1.0 + v[0] : v[0];
        const std::string col1 = at + ", column 1: ";
        if (!(stretch > 0))
            throw InputError(col1 + (strain ? "engineering strain " + formatNumber(v[0], 12) +
                                                  " must be greater than -1 (stretch 1 + strain must be positive)"
                                            : "stretch " + formatNumber(v[0], 12) + " must be positive"));
        if (!data.stretch.empty() && !(stretch > data.stretch.back())) {
            const double previous = strain ? data.stretch.back() - 1.0 : data.stretch.back();
            throw InputError(col1 + abscissa + " " + formatNumber(v[0], 12) + " does not increase over line " +
                             std::to_string(data.line.back()) + " (" + abscissa + " " + formatNumber(previous, 12) +
                             ")");
        }
        data.stretch.push_back(stretch);
        data.nominalStress.push_back(v[1]);
        data.line.push_back(lineNo);
    }
    if (data.size() < UniaxialDataLimits::minRows)
        throw InputError(origin + ": has " + std::to_string(data.size()) +
                         (data.size() == 1 ? " data row" : " data rows") + ", at least " +
                         std::to_string(UniaxialDataLimits::minRows) + " are needed");
    return data;
}

UniaxialData readUniaxialData(const std::filesystem::path& path, StrainMeasure measure) {
    return parseUniaxialData(readFile(path, UniaxialDataLimits::maxBytes, "UniaxialDataLimits::maxBytes"),
                             path.filename().string(), measure);
}

UniaxialData combineTests(const std::vector<std::pair<LoadCase, UniaxialData>>& tests) {
    UniaxialData all;
    for (const auto& [c, d] : tests) {
        all.stretch.insert(all.stretch.end(), d.stretch.begin(), d.stretch.end());
        all.nominalStress.insert(all.nominalStress.end(), d.nominalStress.begin(), d.nominalStress.end());
        all.line.insert(all.line.end(), d.line.begin(), d.line.end());
        all.loadCase.insert(all.loadCase.end(), d.size(), c);
    }
    return all;
}

} // namespace viscera::sim
