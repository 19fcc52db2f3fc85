// scene.json, every section (solver, bodies, surfaces, tools, interaction, suture, render, ...).
#include "sim/scene/scene.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)viscera::sim::parseScene(std::string_view(reinterpret_cast<const char*>(data), size), "scene.json");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
