#include "case/manifest.hpp"

#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace viscera::vcase {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

constexpr const char* kOrigin = "case.vcase: manifest.json";

Manifest sample() {
    Manifest m;
    m.caseId = "liver-resection_01.a";
    m.caseVersion = "1.2.0-rc.1";
    m.minPlayerVersion = "0.1.0";
    m.title = "Liver resection";
    m.features = {"xpbd", "gravity", "fem", "needle"};
    m.units["temperature"] = "K";
    m.device = {{"haptics", {{"channels", 2}}}};
    m.files = {{"meshes/liver.vtet", 1234, std::string(64, 'a')}, {"scene.json", 0, std::string(64, '0')}};
    return m;
}

/// The InputError message of parsing `j`, or "" when it parses.
std::string errorOf(const json& j) {
    try {
        Manifest::fromJson(j, kOrigin);
    } catch (const InputError& e) {
        std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        return message;
    }
    return "";
}

TEST(VcaseManifest, JsonRoundTripIsExact) {
    const Manifest m = sample();
    EXPECT_EQ(Manifest::fromJson(m.toJson(), kOrigin), m);
    EXPECT_EQ(Manifest::parse(m.toJsonText(), kOrigin), m);
    Manifest untitled = m;
    untitled.title.reset();
    EXPECT_FALSE(untitled.toJson().contains("title"));
    EXPECT_EQ(Manifest::parse(untitled.toJsonText(), kOrigin), untitled);
}

TEST(VcaseManifest, TextFormIsDeterministic) {
    EXPECT_EQ(sample().toJsonText(), sample().toJsonText());
    EXPECT_EQ(sample().toJsonText().back(), '\n');
}

TEST(VcaseManifest, FindFile) {
    const Manifest m = sample();
    ASSERT_NE(m.findFile("scene.json"), nullptr);
    EXPECT_EQ(m.findFile("scene.json")->size, 0u);
    EXPECT_EQ(m.findFile("nope"), nullptr);
}

TEST(VcaseManifest, MissingRequiredFieldsAreNamed) {
    for (const char* field :
         {"schemaVersion", "caseId", "caseVersion", "minPlayerVersion", "features", "units", "device", "files"}) {
        json j = sample().toJson();
        j.erase(field);
        EXPECT_EQ(errorOf(j), std::string(kOrigin) + ": " + field + ": required field is missing");
    }
    json j = sample().toJson();
    j["files"][1].erase("sha256");
    EXPECT_EQ(errorOf(j), std::string(kOrigin) + ": files[1].sha256: required field is missing");
    j = sample().toJson();
    j["units"].erase("mass");
    EXPECT_EQ(errorOf(j), std::string(kOrigin) + ": units.mass: required field is missing");
}

TEST(VcaseManifest, WrongTypesAreNamed) {
    struct Case {
        const char* pointer;
        json value;
        const char* expected;
    } cases[] = {
        {"/schemaVersion", "1", "schemaVersion: must be an integer (found string)"},
        {"/schemaVersion", 1.0, "schemaVersion: must be an integer (found number)"},
        {"/caseId", 5, "caseId: must be a string (found number)"},
        {"/title", nullptr, "title: must be a string (found null)"},
        {"/features", "xpbd", "features: must be an array (found string)"},
        {"/features/0", true, "features[0]: must be a string (found boolean)"},
        {"/units", json::array(), "units: must be an object (found array)"},
        {"/units/length", 1, "units.length: must be a string (found number)"},
        {"/device", json::array(), "device: must be an object (found array)"},
        {"/files", json::object(), "files: must be an array (found object)"},
        {"/files/0", "meshes/liver.vtet", "files[0]: must be an object (found string)"},
        {"/files/0/size", -1, "files[0].size: must be a non-negative integer (found a negative integer)"},
        {"/files/0/size", 12.5, "files[0].size: must be a non-negative integer (found number)"},
        {"/files/0/size", "12", "files[0].size: must be a non-negative integer (found string)"},
    };
    for (const Case& c : cases) {
        json j = sample().toJson();
        j[json::json_pointer(c.pointer)] = c.value;
        EXPECT_EQ(errorOf(j), std::string(kOrigin) + ": " + c.expected) << c.pointer;
    }
    EXPECT_EQ(errorOf(json::array()), std::string(kOrigin) + ": must be a JSON object (found array)");
}

TEST(VcaseManifest, FieldRulesAreNamed) {
    struct Case {
        const char* pointer;
        json value;
        std::string expected;
    } cases[] = {
        {"/caseId", "Liver", "caseId: 'Liver' must match [a-z0-9][a-z0-9._-]*"},
        {"/caseId", "..", "caseId: '..' must match"},
        {"/caseId", "a/b", "caseId: 'a/b' must match"},
        {"/caseId", "", "caseId: '' must match"},
        {"/caseId", std::string(65, 'a'),
         "caseId: '" + std::string(65, 'a') + "' must match [a-z0-9][a-z0-9._-]* (at most 64 characters)"},
        {"/caseVersion", "1.0", "caseVersion: '1.0' is not a semantic version"},
        {"/minPlayerVersion", "latest", "minPlayerVersion: 'latest' is not a semantic version"},
        {"/features/1", "xpbd", "features[1]: duplicate feature 'xpbd'"},
        {"/features/1", "Gravity", "features[1]: 'Gravity' must match [a-z0-9][a-z0-9_-]*"},
        {"/units/length", "mm", "units.length: 'mm' is not supported (the player uses SI: 'm')"},
        {"/files/0/path", "../x", "files[0].path: entry name escapes the package ('..' component)"},
        {"/files/0/path", "/etc/passwd", "files[0].path: absolute entry path"},
        {"/files/0/path", "manifest.json", "files[0].path: manifest.json must not list itself"},
        {"/files/1/path", "meshes/liver.vtet", "files[1].path: 'meshes/liver.vtet' is listed more than once"},
        {"/files/0/sha256", std::string(64, 'A'), "files[0].sha256: must be 64 lowercase hex characters"},
        {"/files/0/sha256", "abc", "files[0].sha256: must be 64 lowercase hex characters"},
        {"/titel", "typo", "titel: unknown field"},
        {"/files/0/mode", 420, "files[0].mode: unknown field"},
        {"/schemaVersion", 1ull << 40, "schemaVersion: integer out of range"},
    };
    for (const Case& c : cases) {
        json j = sample().toJson();
        j[json::json_pointer(c.pointer)] = c.value;
        EXPECT_THAT(errorOf(j), HasSubstr(std::string(kOrigin) + ": " + c.expected)) << c.pointer;
    }
}

TEST(VcaseManifest, ParseRejectsInvalidJsonAndDuplicateKeys) {
    try {
        Manifest::parse("{ \"schemaVersion\": 1,", kOrigin);
        FAIL() << "truncated JSON accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr(std::string(kOrigin) + ": invalid JSON ("));
    }
    std::string text = sample().toJsonText();
    text.insert(text.find('{') + 1, "\"caseId\": \"other\",");
    try {
        Manifest::parse(text, kOrigin);
        FAIL() << "duplicate key accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr(std::string(kOrigin) + ": invalid JSON (duplicate object key \"caseId\")"));
    }
    // The same key in different objects is fine (every files[] entry has "path").
    EXPECT_NO_THROW(Manifest::parse(sample().toJsonText(), kOrigin));
}

TEST(VcaseManifest, PlayerCompatibility) {
    Manifest m = sample();
    EXPECT_NO_THROW(checkPlayerCompatibility(m, kOrigin));
    m.schemaVersion = 99;
    try {
        checkPlayerCompatibility(m, kOrigin);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "case.vcase: manifest.json: schemaVersion 99 is newer than this "
                               "player supports (1)");
    }
    m.schemaVersion = 0;
    EXPECT_THROW(checkPlayerCompatibility(m, kOrigin), InputError);
    m = sample();
    m.minPlayerVersion = "0.1.1-alpha";
    try {
        checkPlayerCompatibility(m, kOrigin);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "case.vcase: manifest.json: minPlayerVersion 0.1.1-alpha is newer "
                               "than this player (" VISCERA_VERSION ")");
    }
    m.minPlayerVersion = "0.1.0-rc.1"; // a pre-release of this version is older
    EXPECT_NO_THROW(checkPlayerCompatibility(m, kOrigin));
}

} // namespace
} // namespace viscera::vcase
