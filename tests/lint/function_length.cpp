// Small rooms (README "Layout", issue 39): no function of the studio runs past 120 lines.
//
// A function is a definition that starts at column 0 on a line with '(' that is not a declaration
// (ends with ';'), a preprocessor line, a comment, a namespace, type, using or template line, and
// ends at the next line that is exactly '}'; its length counts both lines. A function still open at
// the end of its file ends there.
//
// Every studio/**/*.cpp file is read byte for byte, one line per '\n' (a '\r' before it and a last
// line without one are part of the count), so no file content can end the reading early (issue 57:
// the CMake script this replaces stopped at an unbalanced '[' in a string).
//
// Usage: viscera_function_length <repo> [--limit N]
// Prints `<file>:<line>: <N> lines: <signature>` for every function over the limit, then how many
// files and lines it read; exit status 1 when any function is over the limit, 2 on a usage or read
// error.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct LongFunction {
    std::string file;
    std::size_t line = 0, length = 0;
    std::string signature;
};

struct Tally {
    std::size_t files = 0, lines = 0;
    std::vector<LongFunction> found;
};

bool startsWithAny(std::string_view line) {
    static constexpr std::string_view kNotFunctions[] = {"namespace", "#",       "//",    "struct", "class",
                                                         "enum",      "extern",  "union", "}",      "static_assert",
                                                         "using",     "template"};
    return std::any_of(std::begin(kNotFunctions), std::end(kNotFunctions),
                       [&](std::string_view p) { return line.substr(0, p.size()) == p; });
}

bool endsWithSemicolon(std::string_view line) {
    const auto last = line.find_last_not_of(" \t\r");
    return last != std::string_view::npos && line[last] == ';';
}

bool startsFunction(std::string_view line) {
    if (line.empty() || line[0] == ' ' || line[0] == '\t' || line[0] == '\r') return false;
    return line.find('(') != std::string_view::npos && !endsWithSemicolon(line) && !startsWithAny(line);
}

bool endsFunction(std::string_view line) {
    return line == "}" || line == "}\r";
}

std::string shown(std::string_view line) {
    const auto last = line.find_last_not_of(" \t\r");
    return std::string(line.substr(0, last == std::string_view::npos ? 0 : last + 1));
}

// Splits `text` at every '\n'; a last line without one counts too.
std::vector<std::string_view> splitLines(std::string_view text) {
    std::vector<std::string_view> lines;
    std::size_t from = 0;
    while (from < text.size()) {
        const auto nl = text.find('\n', from);
        const auto to = nl == std::string_view::npos ? text.size() : nl;
        lines.push_back(text.substr(from, to - from));
        from = to + 1;
    }
    return lines;
}

void checkFile(const std::string& name, std::string_view text, std::size_t limit, Tally& tally) {
    const auto lines = splitLines(text);
    std::size_t start = 0; // 1-based line of the open function; 0: none
    auto close = [&](std::size_t end) {
        const auto length = end - start + 1;
        if (length > limit) tally.found.push_back({name, start, length, shown(lines[start - 1])});
        start = 0;
    };
    for (std::size_t i = 0; i < lines.size(); ++i) {
        if (start == 0) {
            if (startsFunction(lines[i])) start = i + 1;
        } else if (endsFunction(lines[i])) {
            close(i + 1);
        }
    }
    if (start != 0) close(lines.size());
    tally.files += 1;
    tally.lines += lines.size();
}

bool readFile(const fs::path& path, std::string& text) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return !in.bad();
}

std::vector<fs::path> studioSources(const fs::path& repo) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(repo / "studio"))
        if (entry.is_regular_file() && entry.path().extension() == ".cpp") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

int usage() {
    std::fprintf(stderr, "usage: viscera_function_length <repo> [--limit N]\n");
    return 2;
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2 && argc != 4) return usage();
    std::size_t limit = 120;
    if (argc == 4) {
        if (std::string_view(argv[2]) != "--limit") return usage();
        try {
            limit = std::stoul(argv[3]);
        } catch (const std::exception&) {
            return usage();
        }
    }
    const fs::path repo = argv[1];
    if (!fs::is_directory(repo / "studio")) {
        std::fprintf(stderr, "function length: %s has no studio/ folder\n", (repo / "studio").c_str());
        return 2;
    }
    Tally tally;
    std::string text;
    for (const auto& path : studioSources(repo)) {
        const auto name = path.lexically_relative(repo).generic_string();
        if (!readFile(path, text)) {
            std::fprintf(stderr, "function length: cannot read %s\n", name.c_str());
            return 2;
        }
        checkFile(name, text, limit, tally);
    }
    for (const auto& f : tally.found)
        std::printf("%s:%zu: %zu lines: %s\n", f.file.c_str(), f.line, f.length, f.signature.c_str());
    std::printf("function length: read %zu files, %zu lines under studio/; %zu function(s) over %zu lines%s\n",
                tally.files, tally.lines, tally.found.size(), limit,
                tally.found.empty() ? "" : " (split them along their seams)");
    return tally.found.empty() ? 0 : 1;
}
