#include "sim/util/atomic_file.hpp"

#include "sim/util/error.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace viscera {
namespace {

std::string errnoText() { return std::strerror(errno); }

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

} // namespace

void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes) {
    namespace fs = std::filesystem;
    fs::path dir = path.parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string tmpl = (dir / ("." + path.filename().string() + ".tmpXXXXXX")).string();
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

std::string readFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(path.string() + ": read failed");
    return ss.str();
}

} // namespace viscera
