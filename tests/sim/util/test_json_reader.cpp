#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <cmath>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace viscera::sim {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

const std::string kOrigin = "scene.json";

/// The message of `read` on the document `text`, or "accepted".
template <class F> std::string errorOf(const std::string& text, F read) {
    try {
        const json doc = parseJsonText(text, kOrigin);
        read(JsonField(doc, "", kOrigin));
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

TEST(JsonReader, RulesAreDescribedAsTheyCheck) {
    EXPECT_EQ(NumberRule::any().describe(), "must be a finite number");
    EXPECT_EQ(NumberRule::positive().describe(), "must be positive");
    EXPECT_EQ(NumberRule::nonNegative().describe(), "must not be negative");
    EXPECT_EQ(NumberRule::aboveUpTo(0, 0.1).describe(), "must be in (0, 0.1]");
    EXPECT_EQ(NumberRule::fromBelow(0, 0.5).describe(), "must be in [0, 0.5)");
    EXPECT_EQ(NumberRule::closed(40, 400).describe(), "must be in [40, 400]");
    EXPECT_TRUE(NumberRule::fromBelow(0, 0.5).admits(0));
    EXPECT_FALSE(NumberRule::fromBelow(0, 0.5).admits(0.5));
    EXPECT_FALSE(NumberRule::positive().admits(0));
    EXPECT_FALSE(NumberRule::any().admits(std::nan("")));
    EXPECT_FALSE(NumberRule::any().admits(INFINITY));
}

TEST(JsonReader, MessagesNameTheOriginThePathAndTheRule) {
    const std::string doc = R"({"bodies": [{"material": {"poisson_ratio": 0.7, "density": "heavy"}}]})";
    auto material = [](const JsonField& root) { return root["bodies"].items()[0]["material"]; };
    EXPECT_EQ(
        errorOf(doc, [&](const JsonField& r) { material(r)["poisson_ratio"].number(NumberRule::fromBelow(0, 0.5)); }),
        "scene.json: bodies[0].material.poisson_ratio: must be in [0, 0.5)");
    EXPECT_EQ(errorOf(doc, [&](const JsonField& r) { material(r)["density"].number(); }),
              "scene.json: bodies[0].material.density: must be a number (found string)");
    EXPECT_EQ(errorOf(doc, [&](const JsonField& r) { material(r)["model"]; }),
              "scene.json: bodies[0].material.model: required field is missing");
    EXPECT_EQ(errorOf(doc, [&](const JsonField& r) { material(r).object({"poisson_ratio"}); }),
              "scene.json: bodies[0].material.density: unknown field");
    EXPECT_EQ(errorOf(doc, [&](const JsonField& r) { r["bodies"].items(2); }),
              "scene.json: bodies: must have at least 2 elements");
    EXPECT_EQ(errorOf("[1]", [&](const JsonField& r) { r.anyObject(); }),
              "scene.json: (root): must be an object (found array)");
}

TEST(JsonReader, IntegersVectorsIndicesChoicesAndPaths) {
    EXPECT_EQ(errorOf(R"({"n": 2.5})", [](const JsonField& r) { r["n"].integer(1, 10); }),
              "scene.json: n: must be an integer (found number)");
    EXPECT_EQ(errorOf(R"({"n": 0})", [](const JsonField& r) { r["n"].integer(1, 1000); }),
              "scene.json: n: must be an integer in [1, 1000]");
    EXPECT_EQ(errorOf(R"({"n": 5000000000})", [](const JsonField& r) { r["n"].integer(); }),
              "scene.json: n: integer out of range");
    EXPECT_EQ(errorOf(R"({"n": 18446744073709551615})", [](const JsonField& r) { r["n"].integer(0, 5); }),
              "scene.json: n: must be an integer in [0, 5]");
    EXPECT_EQ(errorOf(R"({"v": [1, 2]})", [](const JsonField& r) { r["v"].vec3(); }),
              "scene.json: v: must be an array of 3 numbers");
    EXPECT_EQ(errorOf(R"({"v": [1, 2, -3]})", [](const JsonField& r) { r["v"].vec3(NumberRule::positive()); }),
              "scene.json: v[2]: must be positive");
    EXPECT_EQ(errorOf(R"({"i": [0, -1]})", [](const JsonField& r) { r["i"].indices(); }),
              "scene.json: i[1]: must not be negative");
    EXPECT_EQ(errorOf(R"({"k": "cube"})",
                      [](const JsonField& r) {
                          r["k"].choice({"box", "tube"}, "a generator");
                      }),
              "scene.json: k: 'cube' is not a generator (box, tube)");
    EXPECT_EQ(errorOf(R"({"f": "../etc/passwd"})", [](const JsonField& r) { r["f"].entryPath(); }),
              "scene.json: f: '../etc/passwd': entry name escapes the package ('..' component)");
    EXPECT_EQ(errorOf(R"({"f": "/etc/passwd"})", [](const JsonField& r) { r["f"].entryPath(); }),
              "scene.json: f: '/etc/passwd': absolute entry path");
    EXPECT_EQ(errorOf(R"({"b": 1})", [](const JsonField& r) { r["b"].boolean(); }),
              "scene.json: b: must be true or false (found number)");
    double got = 0;
    EXPECT_EQ(errorOf(R"({"x": 2})", [&](const JsonField& r) { got = r.number("x", 1.0) + r.number("y", 10.0); }),
              "accepted");
    EXPECT_EQ(got, 12.0);
}

TEST(JsonReader, DisplayTextIsBoundedPrintableUtf8) {
    auto title = [](const std::string& t) {
        return errorOf(json({{"title", t}}).dump(), [](const JsonField& f) { f["title"].displayText(40); });
    };
    EXPECT_EQ(title("Mesorectal dissection \u2014 fascia"), "accepted"); // UTF-8 (an em dash) is text
    EXPECT_EQ(title("two\nlines"), "scene.json: title: must be printable text: control character U+000A at byte 3");
    EXPECT_EQ(title("\x1b[2Kstatus ok"),
              "scene.json: title: must be printable text: control character U+001B at byte 0");
    EXPECT_EQ(title("tab\there"), "scene.json: title: must be printable text: control character U+0009 at byte 3");
    EXPECT_EQ(title("c1 \xc2\x9b"), "scene.json: title: must be printable text: control character U+009B at byte 3");
    EXPECT_EQ(title(std::string(41, 'x')), "scene.json: title: must be at most 40 bytes of text (it is 41)");
    EXPECT_EQ(title("ok \u202e"), "scene.json: title: must be printable text: control character U+202E at byte 3");
    EXPECT_EQ(title("ok \u2028"), "scene.json: title: must be printable text: control character U+2028 at byte 3");
    // Bytes that are not UTF-8 (an overlong '/', an encoded UTF-16 surrogate) never reach a title.
    for (const std::string text : {"{\"title\": \"over\xc0\xaflong\"}", "{\"title\": \"a\xed\xa0\x80\"}"})
        EXPECT_NE(errorOf(text, [](const JsonField& f) { f["title"].displayText(40); }), "accepted") << text;
}

TEST(JsonReader, NonFiniteNumbersAndBrokenDocumentsAreRefused) {
    // 1e999 overflows the parser: refused as a document, never read as infinity.
    EXPECT_THAT(errorOf(R"({"x": 1e999})", [](const JsonField& r) { r["x"].number(); }),
                HasSubstr("scene.json: invalid JSON ([json.exception.out_of_range.406] number overflow"));
    // An infinity made in code (not from text) is refused by the reader itself.
    const json inf = {{"x", INFINITY}};
    EXPECT_THROW(JsonField(inf, "", kOrigin)["x"].number(), InputError);
    EXPECT_THAT(errorOf(R"({"x": NaN})", [](const JsonField&) {}), HasSubstr("scene.json: invalid JSON ("));
    EXPECT_THAT(errorOf(R"({"x": 1,)", [](const JsonField&) {}), HasSubstr("scene.json: invalid JSON ("));
    EXPECT_EQ(errorOf(R"({"x": 1, "y": {"z": 1, "z": 2}})", [](const JsonField&) {}),
              "scene.json: invalid JSON (duplicate object key \"z\")");
}

} // namespace
} // namespace viscera::sim
