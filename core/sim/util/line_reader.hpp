#pragma once
/// Line-oriented tokenizer for the project's small text formats (.vtet, .vtri, .vweights): skips
/// blank lines and '#' comments, knows its line number, and fails with
/// "<origin>: line <n>: <rule>" (viscera::InputError).
#include "sim/util/error.hpp"

#include <charconv>
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

} // namespace viscera::sim::detail
