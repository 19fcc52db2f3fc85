#pragma once
/// The player's package trust options, shared by verify, run and soak:
///   --trust KEY.pem      trust this publisher's Ed25519 public key (repeatable), besides the
///                        system folders (vcase::systemTrustFolders)
///   --allow-unsigned     run a case no trusted publisher signed (said in the summary and report)
///   --state-dir DIR      keep the versions run here instead of the default state folder
///                        (vcase::defaultStateFolder); rollback is refused either way
#include "case/trust.hpp"

#include <optional>
#include <string>
#include <vector>

/// The help lines of the options above, pasted into the subcommands' --help texts.
#define VISCERA_PLAYER_TRUST_HELP                                                                                      \
    "  --trust KEY.pem       trust this publisher key (Ed25519 PEM public key; repeatable) besides\n"                  \
    "                        /etc/viscera/trusted-publishers and <prefix>/share/viscera/trusted-publishers\n"          \
    "  --allow-unsigned      accept a case no trusted publisher signed (said in the summary and report)\n"             \
    "  --state-dir DIR       where the case versions run are kept (an older version is always refused;\n"              \
    "                        default /var/lib/viscera/state where it exists, else $XDG_STATE_HOME/viscera\n"           \
    "                        or ~/.local/state/viscera, created 0700)\n"

namespace viscera::player {

struct TrustOptions {
    std::vector<std::string> keyFiles;
    bool allowUnsigned = false;
    std::optional<std::string> stateDir;

    /// When args[i] is one of the options above, takes it (and its value: i moves past it) and
    /// returns true. Throws std::invalid_argument for a missing value.
    bool consume(const std::vector<std::string>& args, size_t& i);
    /// The policy: the system folders' keys, then --trust's; the state folder (`run` records in
    /// it and makes it, `verify` and `soak` only read it: vcase::StateUse); the clock now.
    /// Throws viscera::InputError naming a key file that is not an Ed25519 PEM public key.
    vcase::TrustPolicy policy(vcase::StateUse use) const;
};

} // namespace viscera::player
