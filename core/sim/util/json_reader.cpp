#include "sim/util/json_reader.hpp"

#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <cmath>
#include <cstdio>
#include <set>

namespace viscera::sim {

using nlohmann::json;

bool NumberRule::admits(double v) const {
    if (!std::isfinite(v)) return false;
    if (loOpen ? !(v > lo) : !(v >= lo)) return false;
    if (hiOpen ? !(v < hi) : !(v <= hi)) return false;
    return true;
}

std::string NumberRule::describe() const {
    const bool noLo = std::isinf(lo), noHi = std::isinf(hi);
    if (noLo && noHi) return "must be a finite number";
    if (noHi && lo == 0) return loOpen ? "must be positive" : "must not be negative";
    if (noHi) return std::string("must be ") + (loOpen ? "greater than " : "at least ") + formatNumber(lo);
    if (noLo) return std::string("must be ") + (hiOpen ? "less than " : "at most ") + formatNumber(hi);
    return "must be in " + std::string(loOpen ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) +
           (hiOpen ? ")" : "]");
}

JsonField::JsonField(const json& value, std::string path, const std::string& origin)
    : m_value(&value), m_path(std::move(path)), m_origin(&origin) {}

void JsonField::fail(std::string_view rule) const {
    throw InputError(*m_origin + ": " + (m_path.empty() ? std::string("(root)") : m_path) + ": " + std::string(rule));
}

void JsonField::failAt(std::string_view key, std::string_view rule) const {
    throw InputError(*m_origin + ": " + sub(key) + ": " + std::string(rule));
}

std::string JsonField::sub(std::string_view key) const {
    return m_path.empty() ? std::string(key) : m_path + "." + std::string(key);
}

void JsonField::typeError(const char* expected) const {
    fail(std::string("must be ") + expected + " (found " + m_value->type_name() + ")");
}

const JsonField& JsonField::anyObject() const {
    if (!m_value->is_object()) typeError("an object");
    return *this;
}

const JsonField& JsonField::object(std::initializer_list<std::string_view> keys) const {
    anyObject();
    for (auto it = m_value->begin(); it != m_value->end(); ++it) {
        bool known = false;
        for (std::string_view k : keys)
            known |= it.key() == k;
        if (!known) failAt(displayName(it.key()), "unknown field");
    }
    return *this;
}

bool JsonField::has(std::string_view key) const {
    return m_value->is_object() && m_value->contains(key);
}

JsonField JsonField::operator[](std::string_view key) const {
    anyObject();
    auto it = m_value->find(key);
    if (it == m_value->end()) failAt(key, "required field is missing");
    return JsonField(*it, sub(key), *m_origin);
}

std::optional<JsonField> JsonField::find(std::string_view key) const {
    anyObject();
    auto it = m_value->find(key);
    if (it == m_value->end()) return std::nullopt;
    return JsonField(*it, sub(key), *m_origin);
}

std::vector<JsonField> JsonField::items(size_t minSize, size_t maxSize) const {
    if (!m_value->is_array()) typeError("an array");
    const size_t n = m_value->size();
    if (n < minSize || n > maxSize) {
        if (minSize == maxSize) fail("must have " + std::to_string(minSize) + " elements");
        if (maxSize == SIZE_MAX)
            fail(minSize == 1 ? "must not be empty" : "must have at least " + std::to_string(minSize) + " elements");
        fail("must have " + std::to_string(minSize) + " to " + std::to_string(maxSize) + " elements");
    }
    std::vector<JsonField> out;
    out.reserve(n);
    for (size_t i = 0; i < n; ++i)
        out.emplace_back((*m_value)[i], m_path + "[" + std::to_string(i) + "]", *m_origin);
    return out;
}

std::vector<std::pair<std::string, JsonField>> JsonField::members() const {
    anyObject();
    std::vector<std::pair<std::string, JsonField>> out;
    for (auto it = m_value->begin(); it != m_value->end(); ++it)
        out.emplace_back(it.key(), JsonField(it.value(), sub(displayName(it.key())), *m_origin));
    return out;
}

double JsonField::number(const NumberRule& rule) const {
    if (!m_value->is_number()) typeError("a number");
    const double d = m_value->get<double>();
    if (!std::isfinite(d)) fail("must be a finite number");
    if (!rule.admits(d)) fail(rule.describe());
    return d;
}

int JsonField::integer(int64_t lo, int64_t hi) const {
    if (!m_value->is_number_integer()) typeError("an integer");
    const bool huge = m_value->is_number_unsigned() && m_value->get<uint64_t>() > uint64_t(INT64_MAX);
    const int64_t v = huge ? INT64_MAX : m_value->get<int64_t>();
    if (v < lo || v > hi) {
        if (lo == INT32_MIN && hi == INT32_MAX) fail("integer out of range");
        if (hi == INT32_MAX) fail(lo == 0 ? "must not be negative" : "must be at least " + std::to_string(lo));
        fail("must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return static_cast<int>(v);
}

bool JsonField::boolean() const {
    if (!m_value->is_boolean()) typeError("true or false");
    return m_value->get<bool>();
}

std::string JsonField::string() const {
    if (!m_value->is_string()) typeError("a string");
    return m_value->get<std::string>();
}

std::string JsonField::displayText(size_t maxBytes) const {
    std::string s = string();
    if (s.size() > maxBytes)
        fail("must be at most " + std::to_string(maxBytes) + " bytes of text (it is " + std::to_string(s.size()) + ")");
    for (size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        const int len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        if (len == 0 || i + len > s.size()) fail("must be valid UTF-8 (byte " + std::to_string(i) + ")");
        uint32_t cp = len == 1 ? c : c & (0x7F >> len);
        for (int k = 1; k < len; ++k) {
            const auto t = static_cast<unsigned char>(s[i + k]);
            if ((t >> 6) != 0x2) fail("must be valid UTF-8 (byte " + std::to_string(i + k) + ")");
            cp = (cp << 6) | (t & 0x3F);
        }
        const bool overlong = (len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000);
        if (overlong || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
            fail("must be valid UTF-8 (byte " + std::to_string(i) + ")");
        // Control characters, and the format characters that break a line (U+2028, U+2029) or
        // reorder it (bidirectional marks, embeddings, overrides and isolates).
        const bool format =
            cp == 0x200E || cp == 0x200F || (cp >= 0x2028 && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
        if (cp < 0x20 || cp == 0x7F || (cp >= 0x80 && cp < 0xA0) || format) {
            char code[16];
            std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(cp));
            fail(std::string("must be printable text: control character ") + code + " at byte " + std::to_string(i));
        }
        i += static_cast<size_t>(len);
    }
    return s;
}

std::string JsonField::nonEmptyString() const {
    std::string s = string();
    if (s.empty()) fail("must be a non-empty string");
    return s;
}

std::string JsonField::choice(std::initializer_list<std::string_view> options, std::string_view what) const {
    std::string list;
    for (std::string_view o : options)
        list += (list.empty() ? "" : ", ") + std::string(o);
    const std::string s = string();
    for (std::string_view o : options)
        if (s == o) return s;
    std::string rule = "'";
    rule += displayName(s);
    rule += "' is not ";
    rule += what.empty() ? std::string_view("one of") : what;
    fail(rule + " (" + list + ")");
}

std::string JsonField::entryPath() const {
    std::string s = string();
    if (auto problem = entryNameProblem(s)) fail("'" + displayName(s) + "': " + *problem);
    return s;
}

Vec3 JsonField::vec3(const NumberRule& rule) const {
    if (!m_value->is_array() || m_value->size() != 3) fail("must be an array of 3 numbers");
    const std::vector<JsonField> e = items();
    return {e[0].number(rule), e[1].number(rule), e[2].number(rule)};
}

std::vector<int32_t> JsonField::indices() const {
    std::vector<int32_t> out;
    for (const JsonField& e : items())
        out.push_back(e.integer(0, INT32_MAX));
    return out;
}

double JsonField::number(std::string_view key, double fallback, const NumberRule& rule) const {
    auto f = find(key);
    return f ? f->number(rule) : fallback;
}

int JsonField::integer(std::string_view key, int fallback, int64_t lo, int64_t hi) const {
    auto f = find(key);
    return f ? f->integer(lo, hi) : fallback;
}

bool JsonField::boolean(std::string_view key, bool fallback) const {
    auto f = find(key);
    return f ? f->boolean() : fallback;
}

json parseJsonText(std::string_view text, const std::string& origin) {
    // nlohmann::json keeps the last of repeated keys; a file must not be read differently by
    // different parsers, so a repeated key is an error.
    std::vector<std::set<std::string>> open;
    std::optional<std::string> repeated;
    json::parser_callback_t track = [&](int, json::parse_event_t event, json& parsed) {
        switch (event) {
        case json::parse_event_t::object_start:
            open.emplace_back();
            break;
        case json::parse_event_t::object_end:
            open.pop_back();
            break;
        case json::parse_event_t::key:
            if (!open.back().insert(parsed.get<std::string>()).second && !repeated)
                repeated = parsed.get<std::string>();
            break;
        default:
            break;
        }
        return true;
    };
    json doc;
    try {
        doc = json::parse(text.begin(), text.end(), track);
    } catch (const json::exception& e) { // parse_error, and out_of_range for a number like 1e999
        throw InputError(origin + ": invalid JSON (" + e.what() + ")");
    }
    if (repeated) throw InputError(origin + ": invalid JSON (duplicate object key \"" + displayName(*repeated) + "\")");
    return doc;
}

} // namespace viscera::sim
