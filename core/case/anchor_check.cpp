#include "case/anchor_check.hpp"

#include "sim/util/error.hpp"

#include <string>
#include <sys/stat.h>
#include <system_error>
#include <unistd.h>

namespace viscera::vcase {
namespace {

namespace fs = std::filesystem;

std::string modeText(mode_t mode) {
    std::string out;
    for (int shift : {6, 3, 0})
        out += char('0' + ((mode >> shift) & 7));
    return out;
}

bool ownerIsSafe(const struct stat& st) {
    return st.st_uid == 0 || st.st_uid == ::geteuid();
}

/// Writable by someone other than its owner (root's sticky folders excepted).
bool othersMayWrite(const struct stat& st) {
    if (!(st.st_mode & (S_IWGRP | S_IWOTH))) return false;
    return !(S_ISDIR(st.st_mode) && (st.st_mode & S_ISVTX) && st.st_uid == 0);
}

[[noreturn]] void refuse(const fs::path& named, std::string_view what, const std::string& rule) {
    throw InputError(named.string() + ": " + std::string(what) + " " + rule);
}

/// The entry itself: owner and mode (a symbolic link was refused before).
void checkEntry(const fs::path& named, std::string_view what, const struct stat& st) {
    if (!ownerIsSafe(st) || othersMayWrite(st))
        refuse(named, what,
               "must be owned by root or by you and writable by no one else (owner uid " + std::to_string(st.st_uid) +
                   ", mode " + modeText(st.st_mode) + ")");
}

/// Every folder from `start` up to `/`: a folder that fails names itself in the message.
void checkFolders(const fs::path& named, std::string_view what, fs::path start, bool followLinks) {
    for (fs::path dir = start;; dir = dir.parent_path()) {
        struct stat st {};
        const int rc = followLinks ? ::stat(dir.c_str(), &st) : ::lstat(dir.c_str(), &st);
        if (rc == 0 && !S_ISLNK(st.st_mode) && (!ownerIsSafe(st) || othersMayWrite(st)))
            refuse(named, what,
                   "lies in " + dir.string() + ", a folder writable by others than root and you (owner uid " +
                       std::to_string(st.st_uid) + ", mode " + modeText(st.st_mode) +
                       "); keep it where only root or you can change it");
        if (dir == dir.parent_path() || dir.empty()) break;
    }
}

} // namespace

void requireSafeAnchor(const fs::path& path, std::string_view what) {
    std::error_code ec;
    const fs::path named = fs::absolute(path, ec).lexically_normal();
    if (ec) refuse(path, what, "cannot be located (" + ec.message() + ")");
    struct stat st {};
    if (::lstat(named.c_str(), &st) != 0) {                   // missing: the caller says so, skips it or makes it,
        checkFolders(path, what, named.parent_path(), false); // but never under a folder others may write
        return;
    }
    if (S_ISLNK(st.st_mode)) {
        const fs::path target = fs::read_symlink(named, ec);
        refuse(path, what,
               "must not be a symbolic link" + (ec ? std::string() : " (it points to " + target.string() + ")") +
                   "; copy the file there instead");
    }
    checkEntry(path, what, st);
    // The folders as named (a link among them is judged by the folder holding it), then the
    // folders it resolves to (where the bytes really are).
    checkFolders(path, what, named.parent_path(), false);
    const fs::path resolved = fs::canonical(named.parent_path(), ec);
    if (!ec) checkFolders(path, what, resolved, true);
}

} // namespace viscera::vcase
