#pragma once
// The haptic sample case used by the player e2e tests and bench_haptics: a 6 × 4 × 2 cm tissue
// block resting on a fixed base (z = 0), 20 kPa, under gravity, with one 5 mm sphere probe
// hovering 3 mm above the centre of its top face.
#include "sim/scene/scene.hpp"

#include <filesystem>
#include <string>

namespace viscera::test {

/// The scene of the sample (meshes/tissue.vtet is made by writeHapticCase).
sim::SceneDesc hapticScene(int tools = 1);
/// Writes the .vcase; tools = 1 (right hand) or 2 (left and right probes); signed with the PEM
/// private key `signingKey` when one is given.
void writeHapticCase(const std::filesystem::path& out, int tools = 1, const std::filesystem::path& signingKey = {});

} // namespace viscera::test
