#pragma once
/// Loading a verified case into a World and running a session on it.
#include "case/case_package.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace viscera::player {

struct LoadedCase {
    std::unique_ptr<vcase::CasePackage> package;
    sim::SceneDesc scene;
    std::unique_ptr<sim::World> world;
};

/// Verifies the package, parses its scene and assembles a World with only the subsystems the
/// manifest declares. Throws viscera::InputError naming the file, the field and the rule.
LoadedCase loadCase(const std::filesystem::path& casePath);

struct RunOptions {
    int frames = 300;
    /// Called after every frame with (frames done, frames total); may be empty.
    std::function<void(int, int)> progress;
};

struct SessionResult {
    std::string caseId, caseVersion, title;
    std::vector<std::string> activeSubsystems;
    std::vector<sim::FrameRecord> frames;
    std::vector<sim::AccuracyRecord> accuracy;
    sim::Invariants invariants;
    double simTime = 0;           ///< s
    double wallTime = 0;          ///< s
    double maxNodeDisplacement = 0; ///< m, from the rest configuration, at the end
    size_t nodes = 0, tets = 0;
    std::vector<std::string> errors;
    bool ok() const { return errors.empty() && invariants.allFinite; }
};

/// Steps the world `frames` times, recording per-frame figures and invariants. Never throws.
SessionResult runSession(LoadedCase& loaded, const RunOptions& options);

} // namespace viscera::player
