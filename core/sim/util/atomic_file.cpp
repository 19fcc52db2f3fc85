#include "sim/util/atomic_file.hpp"

#include "sim/util/error.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <sys/stat.h>
#include <unistd.h>

namespace viscera {
namespace {

std::string errnoText() {
    return std::strerror(errno);
}

void writeAll(int fd, std::string_view bytes, const std::filesystem::path& tmp) {
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            throw InputError(tmp.string() + ": write failed: " + errnoText());
        }
        done += static_cast<size_t>(n);
    }
}

/// Creates and removes a temporary file in `dir`; the errno text when it cannot.
std::string probeFolder(const std::filesystem::path& dir) {
    std::string tmpl = (dir / ".viscera-write-probe-XXXXXX").string();
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) return errnoText();
    ::close(fd);
    ::unlink(tmpl.c_str());
    return {};
}

} // namespace

void requireWritableFile(const std::filesystem::path& path, std::string_view what) {
    namespace fs = std::filesystem;
    const std::string head = path.string() + ": cannot write " + std::string(what) + " (";
    std::error_code ec;
    if (path.empty() || path.filename().empty()) throw InputError(head + "the path names no file)");
    if (fs::is_directory(path, ec)) throw InputError(head + "it is a folder)");
    fs::path dir = path.parent_path();
    if (dir.empty()) dir = ".";
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw InputError(head + "'" + dir.string() + "' is a file, not a folder)");
    fs::create_directories(dir, ec);
    if (ec) throw InputError(head + "cannot create the folder '" + dir.string() + "': " + ec.message() + ")");
    if (const std::string why = probeFolder(dir); !why.empty())
        throw InputError(head + "the folder '" + dir.string() + "' takes no new file: " + why + ")");
}

void requireWritableFolder(const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw InputError(dir.string() + ": the output folder is a file, not a folder");
    fs::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot create the output folder (" + ec.message() + ")");
    if (const std::string why = probeFolder(dir); !why.empty())
        throw InputError(dir.string() + ": the output folder is not writable (" + why + ")");
}

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes) {
    namespace fs = std::filesystem;
    fs::path dir = path.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string name = ".";
    name += path.filename().string();
    name += ".tmpXXXXXX";
    std::string tmpl = (dir / name).string();
    int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw InputError(path.string() + ": cannot create a temporary file: " + errnoText());
    fs::path tmp = tmpl;
    try {
        writeAll(fd, bytes, tmp);
        if (::fsync(fd) != 0) throw InputError(tmp.string() + ": fsync failed: " + errnoText());
        ::fchmod(fd, 0644);
    } catch (...) {
        ::close(fd);
        ::unlink(tmpl.c_str());
        throw;
    }
    ::close(fd);
    if (::rename(tmpl.c_str(), path.c_str()) != 0) {
        std::string why = errnoText();
        ::unlink(tmpl.c_str());
        throw InputError(path.string() + ": rename from temporary file failed: " + why);
    }
    int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

std::string readFile(const std::filesystem::path& path, std::uintmax_t maxBytes, std::string_view limitName) {
    namespace fs = std::filesystem;
    auto fail = [&](const std::string& rule) { throw InputError(path.string() + ": " + rule); };
    auto tooLarge = [&](const std::string& size) { // size: "300000000 bytes, " or ""
        fail("file is " + size + "larger than the limit of " + std::to_string(maxBytes) + " bytes" +
             (limitName.empty() ? std::string() : " (" + std::string(limitName) + ")"));
    };
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (status.type() == fs::file_type::not_found) fail("cannot open for reading (file not found)");
    if (ec) fail("cannot open for reading (" + ec.message() + ")");
    if (fs::is_directory(status)) fail("cannot open for reading (is a directory, not a file)");
    std::uintmax_t size = 0; // known for a regular file; a FIFO or device is read to its end
    if (fs::is_regular_file(status)) {
        size = fs::file_size(path, ec);
        if (ec) fail("cannot read the file size (" + ec.message() + ")");
        if (size > maxBytes) tooLarge(std::to_string(size) + " bytes, ");
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) fail("cannot open for reading (" + errnoText() + ")");
    std::string bytes;
    bytes.reserve(static_cast<size_t>(size));
    char chunk[1 << 16];
    while (true) {
        const size_t got = std::fread(chunk, 1, sizeof chunk, f.get());
        if (bytes.size() + got > maxBytes) tooLarge("");
        bytes.append(chunk, got);
        if (got < sizeof chunk) break;
    }
    if (std::ferror(f.get())) fail("read failed (" + errnoText() + ")");
    return bytes;
}

} // namespace viscera
