#pragma once
/// The checks every reader of a session report applies to its fields (the session plots, the
/// results database): each failure is one line "<origin>: <field>: <rule>" (viscera::InputError),
/// e.g. "r.json: frames[3].step_ms: must be a number". Header for .cpp files only (nlohmann::json).
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

/// A report's text as JSON; refused with the parser's position: "<origin>: not a JSON session
/// report (parse error at line 3, column 5: ...)".
inline nlohmann::json parseReportText(const std::string& text, const std::string& origin) {
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        // parse_error, and out_of_range for a number like 1e999 ("number overflow parsing '1e999'")
        std::string why = e.what(); // "[json.exception.parse_error.101] parse error at line 3, ..."
        if (auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
        throw InputError(origin + ": not a JSON session report (" + why + ")");
    }
}

struct ReportReader {
    const std::string& origin;
    [[noreturn]] void fail(const std::string& field, const std::string& rule) const {
        throw InputError(origin + ": " + field + ": " + rule);
    }
    const nlohmann::json& member(const nlohmann::json& obj, const std::string& field, const char* key) const {
        if (!obj.is_object()) fail(field, "must be an object");
        auto it = obj.find(key);
        if (it == obj.end()) fail(field.empty() ? key : field + "." + key, "is missing");
        return *it;
    }
    const nlohmann::json* optional(const nlohmann::json& obj, const char* key) const {
        if (!obj.is_object()) return nullptr;
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }
    /// A finite number.
    double number(const nlohmann::json& v, const std::string& field) const {
        if (!v.is_number()) fail(field, "must be a number");
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(field, "must be finite");
        return d;
    }
    /// A number, or null for a figure the session could not compute (NaN: a gap in a plot).
    double numberOrNaN(const nlohmann::json& v, const std::string& field) const {
        return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : number(v, field);
    }
    /// A number, or null (none).
    std::optional<double> numberOrNone(const nlohmann::json& v, const std::string& field) const {
        if (v.is_null()) return std::nullopt;
        return number(v, field);
    }
    int integer(const nlohmann::json& v, const std::string& field) const {
        if (!v.is_number_integer()) fail(field, "must be an integer");
        if (v.is_number_unsigned() ? v.get<uint64_t>() > uint64_t(std::numeric_limits<int>::max())
                                   : (v.get<int64_t>() > std::numeric_limits<int>::max() ||
                                      v.get<int64_t>() < std::numeric_limits<int>::min()))
            fail(field, "is out of range");
        return v.get<int>();
    }
    bool boolean(const nlohmann::json& v, const std::string& field) const {
        if (!v.is_boolean()) fail(field, "must be true or false");
        return v.get<bool>();
    }
    std::string string(const nlohmann::json& v, const std::string& field) const {
        if (!v.is_string()) fail(field, "must be a string");
        return v.get<std::string>();
    }
    const nlohmann::json& array(const nlohmann::json& v, const std::string& field) const {
        if (!v.is_array()) fail(field, "must be an array");
        return v;
    }
    std::vector<double> numbers(const nlohmann::json& v, const std::string& field) const {
        std::vector<double> out;
        for (size_t i = 0; i < array(v, field).size(); ++i)
            out.push_back(numberOrNaN(v[i], field + "[" + std::to_string(i) + "]"));
        return out;
    }
    std::vector<std::string> strings(const nlohmann::json& v, const std::string& field) const {
        std::vector<std::string> out;
        for (size_t i = 0; i < array(v, field).size(); ++i)
            out.push_back(string(v[i], field + "[" + std::to_string(i) + "]"));
        return out;
    }
};

} // namespace viscera::player
