#pragma once
/// Line-oriented tokenizer for the project's small text formats (.vtet, .vtri, .vweights,
/// .vsamples): skips
/// blank lines and '#' comments, knows its line number, and fails with
/// "<origin>: line <n>: <rule>" (viscera::InputError).
#include "sim/util/error.hpp"

#include <charconv>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace viscera::sim::detail {

/// Line-oriented tokenizer that skips blank lines and '#' comments and knows its line number.
class LineReader {
public:
    LineReader(std::string_view text, const std::string& origin) : m_text(text), m_origin(origin) {}

    /// Next significant line split into tokens; false at end of input.
    bool next(std::vector<std::string_view>& tokens) {
        while (m_pos < m_text.size()) {
            size_t end = m_text.find('\n', m_pos);
            if (end == std::string_view::npos) end = m_text.size();
            std::string_view line = m_text.substr(m_pos, end - m_pos);
            m_pos = end + 1;
            ++m_line;
            if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
            tokens.clear();
            size_t i = 0;
            while (i < line.size()) {
                while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
                    ++i;
                if (i >= line.size() || line[i] == '#') break;
                size_t j = i;
                while (j < line.size() && line[j] != ' ' && line[j] != '\t')
                    ++j;
                tokens.push_back(line.substr(i, j - i));
                i = j;
            }
            if (!tokens.empty()) return true;
        }
        return false;
    }

    [[noreturn]] void fail(const std::string& rule) const {
        throw InputError(m_origin + ": line " + std::to_string(m_line) + ": " + rule);
    }
    [[noreturn]] void failEof(const std::string& expected) const {
        throw InputError(m_origin + ": unexpected end of file (expected " + expected + ")");
    }

    template <class T> T number(std::string_view tok, const std::string& what) const {
        T value{};
        auto res = std::from_chars(tok.data(), tok.data() + tok.size(), value);
        if (res.ec != std::errc() || res.ptr != tok.data() + tok.size())
            fail(what + " '" + std::string(tok) + "' is not a valid number");
        return value;
    }

private:
    std::string_view m_text;
    const std::string& m_origin;
    size_t m_pos = 0;
    size_t m_line = 0;
};

/// The per-node formats (.vweights, .vsamples):
///
///   <magic> 1
///   nodes <N>
///   <value>            N lines, one per node in node order
///
/// Reads the header (version 1 only, 1 ≤ N ≤ 2^28, N equal to `expectedNodes` when given), then
/// calls `each(token, i, what)` for node i's value token (`what` is "<valueName> of node <i>",
/// for the caller's messages) and refuses anything after the last node.
template <class Each>
void readNodeValues(LineReader& in, std::string_view magic, std::optional<size_t> expectedNodes,
                    const std::string& valueName, Each&& each) {
    std::vector<std::string_view> tok;
    const std::string header = std::string(magic) + " 1";
    if (!in.next(tok)) in.failEof("header '" + header + "'");
    if (tok.size() != 2 || tok[0] != magic) in.fail("header must be '" + std::string(magic) + " <version>'");
    if (in.number<int>(tok[1], "version") != 1)
        in.fail("unsupported " + std::string(magic) + " version " + std::string(tok[1]) + " (supported: 1)");
    if (!in.next(tok)) in.failEof("'nodes <count>'");
    if (tok.size() != 2 || tok[0] != "nodes") in.fail("expected 'nodes <count>'");
    const int64_t n = in.number<int64_t>(tok[1], "node count");
    if (n < 1 || n > (int64_t{1} << 28)) in.fail("node count " + std::to_string(n) + " is out of range [1, 2^28]");
    if (expectedNodes && static_cast<size_t>(n) != *expectedNodes)
        in.fail("file has " + std::to_string(n) + " nodes, the mesh has " + std::to_string(*expectedNodes));
    for (int64_t i = 0; i < n; ++i) {
        const std::string what = valueName + " of node " + std::to_string(i);
        if (!in.next(tok)) in.failEof(what + " (file declares " + std::to_string(n) + " nodes)");
        if (tok.size() != 1) in.fail(what + ": expected one value per line, found " + std::to_string(tok.size()));
        each(tok[0], static_cast<size_t>(i), what);
    }
    if (in.next(tok))
        in.fail("unexpected content after the last " + valueName + " (file declares " + std::to_string(n) + " nodes)");
}

} // namespace viscera::sim::detail
