#include "sim/scene/features.hpp"

#include "sim/util/error.hpp"

#include <algorithm>

namespace viscera::sim {
namespace {
const char* kXpbd = "xpbd";
const char* kGravity = "gravity";
const char* kFascia = "fascia";
const char* kEmbedding = "embedding";
const char* kStrainLimit = "strain_limit";
const char* kAccuracy = "accuracy";
const char* kProbe = "probe";
const char* kFem = "fem";
const char* kNeedle = "needle";
const char* kThread = "thread";
const char* kContact = "contact";
const char* kCollision = "collision";
const char* kDissection = "dissection";
const char* kClip = "clip";

bool has(const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}
} // namespace

const std::vector<std::string>& supportedFeatures() {
    static const std::vector<std::string> f = {kAccuracy,  kClip,        kCollision, kContact, kDissection,
                                               kEmbedding, kFascia,      kFem,       kGravity, kNeedle,
                                               kProbe,     kStrainLimit, kThread,    kXpbd};
    return f;
}

bool supportsAccuracySampling(const SceneDesc& scene) {
    return scene.solverType == "xpbd" && scene.surfaces.empty() && scene.bodies.size() == 1 &&
           !scene.interaction.has_value();
}

std::vector<std::string> requiredFeatures(const SceneDesc& scene) {
    std::vector<std::string> f;
    if (!scene.bodies.empty()) f.push_back(scene.solverType);
    if (scene.xpbd.gravity.squaredNorm() > 0) f.push_back(kGravity);
    if (!scene.surfaces.empty()) f.push_back(kFascia);
    for (const auto& b : scene.bodies) {
        if (!b.embeddedIn.empty() && !has(f, kEmbedding)) f.push_back(kEmbedding);
        if (b.strainLimits && !has(f, kStrainLimit)) f.push_back(kStrainLimit);
    }
    if (scene.accuracy) f.push_back(kAccuracy);
    if (!scene.tools.empty()) f.push_back(kProbe);
    if (scene.interaction) {
        using K = InstrumentDesc::Kind;
        if (scene.interaction->has(K::Grasper) || scene.interaction->has(K::EnergyHook) ||
            scene.interaction->has(K::Scissors) || scene.interaction->has(K::NeedleDriver))
            f.push_back(kCollision);
        if (scene.interaction->has(K::EnergyHook) || scene.interaction->has(K::Scissors)) f.push_back(kDissection);
        if (scene.interaction->has(K::ClipApplier)) f.push_back(kClip);
    }
    if (scene.suture) {
        f.push_back(kNeedle);
        if (scene.suture->thread) f.push_back(kThread);
        if (scene.suture->contact) f.push_back(kContact);
    }
    std::sort(f.begin(), f.end());
    return f;
}

void checkSupportedFeatures(const std::vector<std::string>& features, const std::string& origin) {
    std::string list;
    for (const auto& s : supportedFeatures())
        list += (list.empty() ? "" : ", ") + s;
    for (const std::string& f : features)
        if (!has(supportedFeatures(), f))
            throw InputError(origin + ": features: '" + f + "' is not supported by this player (supported: " + list +
                             ")");
}

std::vector<std::string> checkDeclaredFeatures(const SceneDesc& scene, const std::vector<std::string>& features,
                                               const std::string& origin) {
    std::vector<std::string> needed = requiredFeatures(scene);
    for (const std::string& f : needed)
        if (!has(features, f)) {
            if (f == scene.solverType)
                throw InputError(origin + ": features: the scene uses solver '" + f +
                                 "' but the manifest does not declare it");
            if (f == kGravity)
                throw InputError(origin +
                                 ": features: the scene sets gravity but the manifest does not declare 'gravity'");
            throw InputError(origin + ": features: the scene uses '" + f + "' but the manifest does not declare it");
        }
    return needed;
}

} // namespace viscera::sim
