#pragma once
/// Injectable logger. The libraries never print; applications install a sink.
#include <functional>
#include <string_view>

namespace viscera::log {

enum class Level { Debug, Info, Warn, Error };
using Sink = std::function<void(Level, std::string_view)>;

/// Installs the process-wide sink (nullptr silences). Not thread-safe against concurrent logging;
/// install once at start-up.
void setSink(Sink sink);
void write(Level level, std::string_view message);
inline void info(std::string_view m) {
    write(Level::Info, m);
}
inline void warn(std::string_view m) {
    write(Level::Warn, m);
}
inline void error(std::string_view m) {
    write(Level::Error, m);
}

} // namespace viscera::log
