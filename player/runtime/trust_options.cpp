#include "runtime/trust_options.hpp"

#include <chrono>
#include <stdexcept>

namespace viscera::player {

bool TrustOptions::consume(const std::vector<std::string>& args, size_t& i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
        if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
        return args[++i];
    };
    if (a == "--trust")
        keyFiles.push_back(value());
    else if (a == "--allow-unsigned")
        allowUnsigned = true;
    else if (a == "--state-dir")
        stateDir = value();
    else
        return false;
    return true;
}

vcase::TrustPolicy TrustOptions::policy(vcase::StateUse use) const {
    vcase::TrustPolicy p;
    for (const std::filesystem::path& folder : vcase::systemTrustFolders())
        p.trusted.addFolder(folder);
    for (const std::string& f : keyFiles)
        p.trusted.addKeyFile(f);
    p.allowUnsigned = allowUnsigned;
    p.stateFolder = vcase::stateFolder(stateDir ? std::optional<std::filesystem::path>(*stateDir) : std::nullopt, use);
    p.now =
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    return p;
}

} // namespace viscera::player
