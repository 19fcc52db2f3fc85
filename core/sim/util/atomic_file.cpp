#include "sim/util/atomic_file.hpp"

#include "sim/util/error.hpp"

#include <cerrno>
#include <chrono>
#include <csignal>
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

const char* fileKind(mode_t mode) {
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    return "not a file";
}

/// The part of a destination's file name its temporaries carry: at most 200 bytes, so that
/// ".<part>.<pid>.tmpXXXXXX" stays within the 255 bytes of a file name.
std::string temporaryStem(const std::string& name) {
    return name.substr(0, 200);
}

/// Removes ".<name>.<pid>.tmpXXXXXX" files of `dir` whose writer process no longer runs and that
/// are over an hour old (a pid of another machine or container sharing the folder may look dead).
void sweepStaleTemporaries(const std::filesystem::path& dir, const std::string& name) {
    namespace fs = std::filesystem;
    std::string head = ".";
    head += temporaryStem(name);
    head += '.';
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string file = it->path().filename().string();
        if (file.size() <= head.size() || file.compare(0, head.size(), head) != 0) continue;
        const size_t tmp = file.find(".tmp", head.size());
        if (tmp == std::string::npos || tmp + 10 != file.size()) continue; // ".tmp" + mkstemp's 6
        const std::string pid = file.substr(head.size(), tmp - head.size());
        if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid.size() > 9) continue;
        if (::kill(static_cast<pid_t>(std::stol(pid)), 0) != 0 && errno == ESRCH) {
            std::error_code rm;
            const auto written = fs::last_write_time(it->path(), rm);
            if (!rm && fs::file_time_type::clock::now() - written > std::chrono::hours(1)) fs::remove(it->path(), rm);
        }
    }
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

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes, unsigned mode) {
    namespace fs = std::filesystem;
    fs::path dir = path.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    fs::create_directories(dir, ec);
    sweepStaleTemporaries(dir, path.filename().string());
    std::string name = ".";
    name += temporaryStem(path.filename().string());
    name += '.';
    name += std::to_string(::getpid());
    name += ".tmpXXXXXX";
    std::string tmpl = (dir / name).string();
    int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw InputError(path.string() + ": cannot create a temporary file: " + errnoText());
    fs::path tmp = tmpl;
    try {
        writeAll(fd, bytes, tmp);
        if (::fsync(fd) != 0) throw InputError(tmp.string() + ": fsync failed: " + errnoText());
        ::fchmod(fd, static_cast<mode_t>(mode));
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
    auto fail = [&](const std::string& rule) { throw InputError(path.string() + ": " + rule); };
    auto tooLarge = [&](const std::string& size) { // size: "300000000 bytes, " or ""
        fail("file is " + size + "larger than the limit of " + std::to_string(maxBytes) + " bytes" +
             (limitName.empty() ? std::string() : " (" + std::string(limitName) + ")"));
    };
    // Not opened unless a regular file now (opening a device can act, e.g. arm a watchdog), and
    // checked again on the open descriptor (it may have been replaced in between); O_NONBLOCK:
    // a FIFO put there meanwhile opens at once and is refused below.
    struct stat before {};
    if (::stat(path.c_str(), &before) == 0 && !S_ISREG(before.st_mode) && !S_ISDIR(before.st_mode))
        fail(std::string("is not a regular file (") + fileKind(before.st_mode) + ")");
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT) fail("cannot open for reading (file not found)");
        if (errno == EISDIR) fail("cannot open for reading (is a directory, not a file)");
        fail("cannot open for reading (" + errnoText() + ")");
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(::fdopen(fd, "rb"), &std::fclose);
    if (!f) {
        ::close(fd);
        fail("cannot open for reading (" + errnoText() + ")");
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) fail("cannot read the file status (" + errnoText() + ")");
    if (S_ISDIR(st.st_mode)) fail("cannot open for reading (is a directory, not a file)");
    if (!S_ISREG(st.st_mode)) fail(std::string("is not a regular file (") + fileKind(st.st_mode) + ")");
    const auto size = static_cast<std::uintmax_t>(st.st_size);
    if (size > maxBytes) tooLarge(std::to_string(size) + " bytes, ");
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    std::string bytes;
    bytes.reserve(static_cast<size_t>(size));
    char chunk[1 << 16];
    while (true) {
        const size_t got = std::fread(chunk, 1, sizeof chunk, f.get());
        if (bytes.size() + got > maxBytes) tooLarge(""); // grown since the fstat
        bytes.append(chunk, got);
        if (got < sizeof chunk) break;
    }
    if (std::ferror(f.get())) fail("read failed (" + errnoText() + ")");
    return bytes;
}

void requireNotAnInput(const std::filesystem::path& output, std::string_view what,
                       const std::vector<std::filesystem::path>& inputs) {
    namespace fs = std::filesystem;
    auto resolved = [](const fs::path& p) {
        std::error_code ec;
        fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
        return ec ? fs::absolute(p).lexically_normal() : r;
    };
    const fs::path out = resolved(output);
    for (const fs::path& in : inputs) {
        std::error_code ec;
        const bool same =
            fs::exists(output, ec) && fs::exists(in, ec) ? fs::equivalent(output, in, ec) : resolved(in) == out;
        if (same && !ec)
            throw InputError(output.string() + ": cannot write " + std::string(what) + " over the input '" +
                             in.string() + "'");
    }
}

void requirePrivateFile(const std::filesystem::path& path, std::string_view what) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        throw InputError(path.string() + ": cannot open (" + std::strerror(errno) + ")");
    if (st.st_mode & (S_IRWXG | S_IRWXO))
        throw InputError(path.string() + ": " + std::string(what) + " is open to other users (mode " +
                         std::to_string((st.st_mode >> 6) & 7) + std::to_string((st.st_mode >> 3) & 7) +
                         std::to_string(st.st_mode & 7) + "; chmod 600 it)");
}

} // namespace viscera
