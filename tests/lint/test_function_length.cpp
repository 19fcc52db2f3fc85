// The function-length lint (tests/lint/function_length.cpp) on planted repositories: content that
// stopped the old CMake checker (an unbalanced '[' in a string) must not hide a long function after
// it, and files of short functions pass.
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

using namespace viscera;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

namespace {

// A scratch folder laid out like a repository: <root>/studio/<files>.
struct PlantedRepo {
    test::Scratch scratch{"viscera-function-length"};
    PlantedRepo() { fs::create_directories(scratch.dir / "studio"); }
    void write(const std::string& relative, const std::string& text) const {
        std::ofstream(scratch.dir / relative, std::ios::binary) << text;
    }
    test::ProcessResult lint() const { return test::runProcess(VISCERA_FUNCTION_LENGTH_EXE, {scratch.dir.string()}); }
};

// A function `name` of exactly `lines` lines (signature and closing brace included).
std::string function(const std::string& name, int lines) {
    std::string text = "int " + name + "(int x) {\n";
    for (int i = 0; i < lines - 3; ++i)
        text += "    x += " + std::to_string(i) + ";\n";
    return text + "    return x;\n}\n";
}

// What stopped the CMake checker: a string with an unbalanced '['.
const std::string kBracketFunction = "const char* bracket() {\n"
                                     "    return \"[\";\n"
                                     "}\n";

} // namespace

TEST(FunctionLength, ALongFunctionAfterAnUnbalancedBracketIsNamed) {
    PlantedRepo repo;
    repo.write("studio/x.cpp", "#include <string>\n\n" + kBracketFunction + "\n" + function("tooLong", 121));
    const auto r = repo.lint();
    EXPECT_EQ(r.exitCode, 1) << r.out << r.err;
    // 2 + 3 + 1 lines before it put the long function on line 7.
    EXPECT_THAT(r.out, HasSubstr("studio/x.cpp:7: 121 lines: int tooLong(int x) {\n"));
    EXPECT_THAT(r.out, Not(HasSubstr("bracket")));
    EXPECT_THAT(r.out, HasSubstr("read 1 files, 127 lines under studio/; 1 function(s) over 120 lines"));
}

TEST(FunctionLength, EveryFileIsReadToItsEnd) {
    PlantedRepo repo;
    fs::create_directories(repo.scratch.dir / "studio" / "sub");
    repo.write("studio/a.cpp", kBracketFunction + "/* [ [[ ; \\ ${x} \" */\n" + function("longInA", 130));
    repo.write("studio/sub/b.cpp", kBracketFunction + function("longInB", 200));
    repo.write("studio/notes.txt", function("notCpp", 300)); // only .cpp files are studio functions
    const auto r = repo.lint();
    EXPECT_EQ(r.exitCode, 1) << r.out << r.err;
    EXPECT_THAT(r.out, HasSubstr("studio/a.cpp:5: 130 lines: int longInA(int x) {\n"));
    EXPECT_THAT(r.out, HasSubstr("studio/sub/b.cpp:4: 200 lines: int longInB(int x) {\n"));
    EXPECT_THAT(r.out, Not(HasSubstr("notCpp")));
    EXPECT_THAT(r.out, HasSubstr("read 2 files, 337 lines under studio/; 2 function(s) over 120 lines"));
}

TEST(FunctionLength, ShortFunctionsPass) {
    PlantedRepo repo;
    repo.write("studio/x.cpp", "#include <string>\n\n" + kBracketFunction + "\n" + function("justRight", 120) + "\n" +
                                   function("small", 5));
    const auto r = repo.lint();
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_THAT(r.out, HasSubstr("read 1 files, 132 lines under studio/; 0 function(s) over 120 lines\n"));
}

TEST(FunctionLength, ARepositoryWithoutStudioIsAnError) {
    test::Scratch empty{"viscera-function-length"};
    const auto r = test::runProcess(VISCERA_FUNCTION_LENGTH_EXE, {empty.dir.string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_THAT(r.err, HasSubstr("has no studio/ folder"));
}
