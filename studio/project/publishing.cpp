#include "project/publishing.hpp"

#include "case/manifest.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cstdlib>

namespace viscera::studio {
namespace fs = std::filesystem;

fs::path defaultPublisherKeyPath() {
    if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg == '/')
        return fs::path(xdg) / "viscera/publisher-key.pem";
    const char* home = std::getenv("HOME");
    return fs::path(home && *home == '/' ? home : "/root") / ".config/viscera/publisher-key.pem";
}

std::optional<fs::path> defaultPublisherKey() {
    const fs::path file = defaultPublisherKeyPath();
    std::error_code ec;
    if (!fs::exists(file, ec)) return std::nullopt;
    return file;
}

std::string defaultSignerName(const std::optional<fs::path>& namedKey) {
    return namedKey ? namedKey->stem().string() : std::string("publisher");
}

std::string unsignedCaseWarning(const fs::path& missingKey) {
    return "the case is not signed: no publisher key at " + missingKey.string() +
           " (make one with 'viscera-studio keygen'); players refuse it without --allow-unsigned";
}

fs::path publicKeyPathFor(const fs::path& privateFile) {
    fs::path p = privateFile;
    if (p.extension() == ".pem") p.replace_extension();
    p += ".pub.pem";
    return p;
}

NewPublisherKey makePublisherKey(const fs::path& privateFile) {
    NewPublisherKey out{privateFile, publicKeyPathFor(privateFile), {}};
    std::error_code ec;
    for (const fs::path& f : {out.privateFile, out.publicFile})
        if (fs::exists(fs::symlink_status(f, ec)))
            throw InputError(f.string() + ": already exists (a publisher key is never replaced: the cases it signed "
                                          "could no longer be updated; choose another path)");
    const fs::path folder = out.privateFile.parent_path();
    if (!folder.empty() && !fs::exists(folder, ec)) {
        fs::create_directories(folder, ec);
        if (!ec) fs::permissions(folder, fs::perms::owner_all, ec);
    }
    requireWritableFile(out.privateFile, "the publisher key");
    const vcase::SigningKey key = vcase::SigningKey::generate();
    writeFileAtomic(out.privateFile, key.privatePem(), 0600);
    writeFileAtomic(out.publicFile, key.publicPem(), 0644);
    out.keyId = vcase::keyId(key.publicKey());
    return out;
}

vcase::SigningKey loadPublisherKey(const fs::path& keyFile, const fs::path& projectDir) {
    std::error_code ec;
    const fs::path key = fs::weakly_canonical(keyFile, ec);
    const fs::path dir = fs::weakly_canonical(projectDir, ec);
    if (!ec && !dir.empty()) {
        const auto [d, k] = std::mismatch(dir.begin(), dir.end(), key.begin(), key.end());
        if (d == dir.end())
            throw InputError(keyFile.string() + ": the publisher key must be kept outside the project folder '" +
                             projectDir.string() + "' (it would travel with the project)");
    }
    return vcase::SigningKey::load(keyFile);
}

std::string parseExpiry(std::string_view text, int64_t now) {
    std::string full(text);
    if (full.size() == 10) full += "T23:59:59Z";
    const std::optional<int64_t> at = vcase::parseUtcTime(full);
    if (!at)
        throw InputError("--expires '" + std::string(text) +
                         "': must be a UTC date YYYY-MM-DD or time YYYY-MM-DDTHH:MM:SSZ");
    if (*at <= now)
        throw InputError("--expires '" + std::string(text) + "': is not in the future (now " +
                         vcase::formatUtcTime(now) + ")");
    return full;
}

} // namespace viscera::studio
