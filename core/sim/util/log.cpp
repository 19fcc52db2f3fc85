#include "sim/util/log.hpp"

namespace viscera::log {
namespace {
Sink& sink() {
    static Sink s;
    return s;
}
} // namespace

void setSink(Sink s) {
    sink() = std::move(s);
}

void write(Level level, std::string_view message) {
    if (auto& s = sink()) s(level, message);
}

} // namespace viscera::log
