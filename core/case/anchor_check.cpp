#include "case/anchor_check.hpp"

#include "sim/util/error.hpp"

#include <deque>
#include <grp.h>
#include <pwd.h>
#include <string>
#include <sys/stat.h>
#include <system_error>
#include <unistd.h>
#include <vector>

namespace viscera::vcase {
namespace {

namespace fs = std::filesystem;

/// Links followed while resolving one path, as the kernel's limit (ELOOP).
constexpr int kMaxLinks = 40;

std::string modeText(mode_t mode) {
    std::string out;
    for (int shift : {6, 3, 0})
        out += char('0' + ((mode >> shift) & 7));
    return out;
}

/// The user's private group (Debian's default: a group of the user's name, the user's primary
/// group, with no other member): its write bit gives no one else access.
bool isPrivateGroup(gid_t gid) {
    if (gid != ::getegid()) return false;
    const struct passwd* pw = ::getpwuid(::geteuid());
    const struct group* gr = ::getgrgid(gid);
    if (!pw || !gr || std::string(pw->pw_name) != gr->gr_name) return false;
    return !gr->gr_mem || !gr->gr_mem[0];
}

/// Owned by root or the user, and writable by no one else. `stickyRootOk`: a root-owned folder
/// with the sticky bit (/tmp) passes too, as a folder *above* an anchor: there only an entry's
/// owner can rename or remove it, and every entry below is checked in turn.
bool safe(const struct stat& st, bool stickyRootOk) {
    if (st.st_uid != 0 && st.st_uid != ::geteuid()) return false;
    if (st.st_mode & S_IWOTH) return stickyRootOk && S_ISDIR(st.st_mode) && (st.st_mode & S_ISVTX) && st.st_uid == 0;
    if (st.st_mode & S_IWGRP) return isPrivateGroup(st.st_gid);
    return true;
}

[[noreturn]] void refuse(const fs::path& named, std::string_view what, const std::string& rule) {
    throw InputError(named.string() + ": " + std::string(what) + " " + rule);
}

std::string facts(const struct stat& st) {
    return "owner uid " + std::to_string(st.st_uid) + ", mode " + modeText(st.st_mode);
}

/// Queues the components of `p` ("" and "." dropped) at the front or the back of `pending`, the
/// components still to resolve.
void queueComponents(std::deque<std::string>& pending, const fs::path& p, bool front) {
    std::vector<std::string> parts;
    for (const fs::path& c : p.relative_path())
        if (!c.empty() && c != ".") parts.push_back(c.string());
    if (front)
        pending.insert(pending.begin(), parts.begin(), parts.end());
    else
        pending.insert(pending.end(), parts.begin(), parts.end());
}

/// Resolves `named` one component at a time, as the kernel does, and checks every folder whose
/// entries it passes through: a link is followed only out of a safe folder, so nobody but root
/// and the user can change where the path leads. Returns the resolved path of the final entry
/// (which may not exist) and, when it exists, its lstat.
struct Walk {
    fs::path resolved;
    bool exists = false;
    struct stat st {};
};

Walk walk(const fs::path& named, std::string_view what) {
    std::error_code ec;
    const fs::path start = fs::absolute(named, ec);
    if (ec) refuse(named, what, "cannot be located (" + ec.message() + ")");
    std::deque<std::string> pending;
    queueComponents(pending, start, false);
    fs::path dir = "/";
    int links = 0;
    for (;;) {
        struct stat ds {};
        if (::stat(dir.c_str(), &ds) == 0 && !safe(ds, true))
            refuse(named, what,
                   "lies in " + dir.string() + ", a folder writable by others than root and you (" + facts(ds) +
                       "); keep it where only root or you can change it");
        if (pending.empty()) return {dir, true, ds}; // named "/" itself
        const std::string c = pending.front();
        pending.pop_front();
        if (c == "..") {
            dir = dir.parent_path();
            continue;
        }
        const fs::path next = dir / c;
        Walk w{next, false, {}};
        if (::lstat(next.c_str(), &w.st) != 0) return w; // missing: what is above it was checked
        w.exists = true;
        if (S_ISLNK(w.st.st_mode)) {
            const fs::path target = fs::read_symlink(next, ec);
            if (pending.empty())
                refuse(named, what,
                       "must not be a symbolic link" +
                           (ec ? std::string() : " (it points to " + target.string() + ")") +
                           "; put the file itself there");
            if (ec || ++links > kMaxLinks) refuse(named, what, "cannot be resolved (too many links)");
            queueComponents(pending, target, true);
            if (target.is_absolute()) dir = "/";
            continue;
        }
        if (pending.empty()) return w;
        if (!S_ISDIR(w.st.st_mode)) return {next, false, {}}; // a file in the middle: the caller's read says so
        dir = next;
    }
}

} // namespace

std::filesystem::path requireSafeAnchor(const fs::path& path, std::string_view what) {
    const Walk w = walk(path, what);
    if (w.exists && !safe(w.st, false))
        refuse(path, what, "must be owned by root or by you and writable by no one else (" + facts(w.st) + ")");
    return w.resolved;
}

} // namespace viscera::vcase
