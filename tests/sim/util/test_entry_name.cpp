#include "sim/util/entry_name.hpp"

#include <gtest/gtest.h>

namespace viscera::sim {
namespace {

std::string problem(std::string_view name) {
    return entryNameProblem(name).value_or("ok");
}

TEST(VcaseEntryName, AcceptsPortableRelativePaths) {
    for (const char* name : {"scene.json", "meshes/liver.vtet", "a/b/c-d_e.0", "..a", "a..b/c"})
        EXPECT_EQ(problem(name), "ok") << name;
}

TEST(VcaseEntryName, NamesTheRuleEachBadNameBreaks) {
    EXPECT_EQ(problem(""), "empty entry name");
    EXPECT_EQ(problem("/etc/passwd"), "absolute entry path");
    EXPECT_EQ(problem("C:/x"), "absolute entry path (drive letter)");
    EXPECT_EQ(problem("c:x"), "absolute entry path (drive letter)");
    EXPECT_EQ(problem("a\\b"), "entry name contains a backslash (paths use '/')");
    EXPECT_EQ(problem("../x"), "entry name escapes the package ('..' component)");
    EXPECT_EQ(problem("a/../../x"), "entry name escapes the package ('..' component)");
    EXPECT_EQ(problem("a/.."), "entry name escapes the package ('..' component)");
    EXPECT_EQ(problem("a//b"), "entry name has an empty component ('//' or a trailing '/')");
    EXPECT_EQ(problem("a/"), "entry name has an empty component ('//' or a trailing '/')");
    EXPECT_EQ(problem("./a"), "entry name has a '.' component");
    EXPECT_NE(problem("a b").find("character \\x20"), std::string::npos);
    EXPECT_NE(problem("ab:c").find("character \\x3a"), std::string::npos);
    EXPECT_NE(problem("caf\xc3\xa9").find("character \\xc3"), std::string::npos);
    EXPECT_NE(problem(std::string(256, 'a')).find("longer than the limit of 255"), std::string::npos);
    EXPECT_EQ(problem(std::string(255, 'a')), "ok");
}

TEST(VcaseEntryName, DisplayNameKeepsMessagesOnOneLine) {
    EXPECT_EQ(displayName("a\nb\x01"), "a\\x0ab\\x01");
    EXPECT_EQ(displayName("meshes/a.vtet"), "meshes/a.vtet");
    EXPECT_EQ(displayName(std::string(300, 'x')), std::string(255, 'x') + "...");
}

} // namespace
} // namespace viscera::sim
