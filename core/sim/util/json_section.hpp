#pragma once
/// Strict reading of one JSON section of a scene (suture, interaction, ...): every error is
/// "<origin>: <section>.<field>: <rule>". Header-only; nlohmann::json stays private to viscera::sim
/// (only .cpp files of the library include this header).
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

namespace viscera::sim::detail {

struct SectionReader {
    const std::string& origin;
    const char* section; ///< e.g. "suture"

    [[noreturn]] void fail(const std::string& field, const std::string& rule) const {
        throw InputError(origin + ": " + section + "." + field + ": " + rule);
    }
    /// obj must be an object whose keys are all in `keys`.
    void only(const nlohmann::json& obj, std::initializer_list<const char*> keys, const std::string& path) const {
        if (!obj.is_object()) fail(path.empty() ? "(section)" : path, "must be an object");
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool known = false;
            for (const char* k : keys) known |= it.key() == k;
            if (!known) fail(path.empty() ? it.key() : path + "." + it.key(), "unknown field");
        }
    }
    static std::string fmt(double v) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", v);
        return b;
    }
};

} // namespace viscera::sim::detail
