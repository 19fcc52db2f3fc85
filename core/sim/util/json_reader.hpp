#pragma once
/// The one strict JSON field reader of Viscera: every JSON section (scene, suture, interaction,
/// render settings, material curves, manifest, project) is read through JsonField, so that one
/// field is parsed and validated in one place and every error has the same form:
///
///   "<origin>: <JSON path>: <rule>"   e.g. "scene.json: bodies[1].material.poisson_ratio: must be
///                                          in [0, 0.5)"
///
/// A JsonField is a non-owning view of one value of a parsed document plus its JSON path; it
/// throws viscera::InputError on the first broken rule. Objects are checked for unknown fields
/// (object()), numbers for finiteness and a NumberRule, integers for a range, file references
/// for the entry-name rule of sim/util/entry_name.hpp. parseJsonText() rejects invalid JSON and
/// repeated keys (nlohmann::json would keep the last one silently).
///
/// Header for .cpp files only: nlohmann::json stays out of the public headers of the libraries.
#include "sim/mesh/tri_mesh.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

/// The admissible values of a number field; describe() is the rule of the message.
struct NumberRule {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false, hiOpen = false;

    static NumberRule any() { return {}; }
    static NumberRule positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
    static NumberRule nonNegative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
    static NumberRule closed(double lo, double hi) { return {lo, hi, false, false}; }
    /// (lo, hi]
    static NumberRule aboveUpTo(double lo, double hi) { return {lo, hi, true, false}; }
    /// [lo, hi)
    static NumberRule fromBelow(double lo, double hi) { return {lo, hi, false, true}; }

    bool admits(double v) const;
    std::string describe() const; ///< "must be positive", "must be in (0, 0.1]", ...
};

class JsonField {
public:
    /// `path` is the JSON path of `value` ("" for a document root, "suture" for a section).
    JsonField(const nlohmann::json& value, std::string path, const std::string& origin);

    const nlohmann::json& value() const { return *m_value; }
    const std::string& path() const { return m_path; }
    const std::string& origin() const { return *m_origin; }
    /// Throws InputError("<origin>: <path>: <rule>").
    [[noreturn]] void fail(std::string_view rule) const;
    /// The same for a sub-path ("key" → "<path>.key").
    [[noreturn]] void failAt(std::string_view key, std::string_view rule) const;

    // ---- structure ------------------------------------------------------------------------------
    /// Must be an object whose keys are all in `keys` ("<path>.<key>: unknown field").
    const JsonField& object(std::initializer_list<std::string_view> keys) const;
    /// Must be an object (any keys).
    const JsonField& anyObject() const;
    bool has(std::string_view key) const;
    /// A required member ("<path>.<key>: required field is missing").
    JsonField operator[](std::string_view key) const;
    std::optional<JsonField> find(std::string_view key) const;
    /// Must be an array with a size in [minSize, maxSize]; its elements "<path>[i]".
    std::vector<JsonField> items(size_t minSize = 0, size_t maxSize = SIZE_MAX) const;
    /// The members of an object, in document order.
    std::vector<std::pair<std::string, JsonField>> members() const;

    // ---- values ---------------------------------------------------------------------------------
    double number(const NumberRule& rule = NumberRule::any()) const;
    int integer(int64_t lo = INT32_MIN, int64_t hi = INT32_MAX) const;
    bool boolean() const;
    std::string string() const;
    std::string nonEmptyString() const;
    /// Text shown to people (a title, instructions): valid UTF-8 of at most `maxBytes` bytes
    /// without control characters (no newline, tab or escape code) or line-breaking and
    /// bidirectional format characters (U+2028, U+2029, U+200E/F, U+202A–E, U+2066–9): it cannot
    /// break, recolour or reorder the line it is printed on. "must be at most 200 bytes of text (it is 5000)", "must be
    /// printable text: control character U+001B at byte 12", "must be valid UTF-8 (byte 3)".
    std::string displayText(size_t maxBytes) const;
    /// One of `options`: "'x' is not one of (a, b, c)", or with `what` = "a generator":
    /// "'x' is not a generator (a, b, c)".
    std::string choice(std::initializer_list<std::string_view> options, std::string_view what = {}) const;
    /// A relative path inside a case or project (sim::entryNameProblem).
    std::string entryPath() const;
    Vec3 vec3(const NumberRule& rule = NumberRule::any()) const;
    /// Non-negative int32 indices.
    std::vector<int32_t> indices() const;

    // ---- optional members with a default ------------------------------------------------------
    double number(std::string_view key, double fallback, const NumberRule& rule = NumberRule::any()) const;
    int integer(std::string_view key, int fallback, int64_t lo, int64_t hi) const;
    bool boolean(std::string_view key, bool fallback) const;

private:
    [[noreturn]] void typeError(const char* expected) const;
    std::string sub(std::string_view key) const;

    const nlohmann::json* m_value;
    std::string m_path;
    const std::string* m_origin;
};

/// Parses a whole document. Throws InputError("<origin>: invalid JSON (...)") on a syntax error
/// and on a repeated object key.
nlohmann::json parseJsonText(std::string_view text, const std::string& origin);

} // namespace viscera::sim
