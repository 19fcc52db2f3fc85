#pragma once
/// Case-manifest features: the names this build understands, the ones a scene needs (what an
/// exporter writes into the manifest), and the checks World::assemble runs on a manifest.
#include "sim/scene/scene.hpp"

#include <string>
#include <vector>

namespace viscera::sim {

/// Feature names of case manifests understood by this build, sorted.
const std::vector<std::string>& supportedFeatures();
/// The features a scene needs (what an exporter writes into the manifest), sorted.
std::vector<std::string> requiredFeatures(const SceneDesc& scene);

/// Whether the scene's accuracy sampling (feature "accuracy": the frame's first substep solved
/// to convergence with Newton as the reference) applies: an XPBD scene of one tet body with no
/// layers (no surfaces, no embedded bodies, no instruments).
bool supportsAccuracySampling(const SceneDesc& scene);

/// Throws viscera::InputError ("<origin>: features: 'x' is not supported by this player
/// (supported: ...)") for the first feature this build does not understand.
void checkSupportedFeatures(const std::vector<std::string>& features, const std::string& origin);
/// Returns requiredFeatures(scene); throws viscera::InputError naming origin for the first one the
/// manifest's `features` does not declare.
std::vector<std::string> checkDeclaredFeatures(const SceneDesc& scene, const std::vector<std::string>& features,
                                               const std::string& origin);

} // namespace viscera::sim
