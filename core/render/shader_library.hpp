#pragma once
/// GLSL sources from shaders/*.glsl, embedded at build time (generated source in the build folder).
#include <string_view>
#include <vector>

namespace viscera::render {

/// Text of shaders/<name> (e.g. "lighting_fs.glsl"); empty when there is no such shader.
std::string_view shaderSource(std::string_view name);
/// Names of every embedded shader, sorted.
std::vector<std::string_view> shaderNames();

} // namespace viscera::render
