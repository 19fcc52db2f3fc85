#include "render/material.hpp"

#include <algorithm>
#include <cctype>

namespace viscera::render {

namespace {
bool has(const std::string& name, const char* word) {
    return name.find(word) != std::string::npos;
}
} // namespace

TissueMaterial defaultMaterialFor(const std::string& rawName) {
    std::string name = rawName;
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    TissueMaterial m;
    m.name = rawName;
    if (has(name, "liver") || has(name, "organ")) {
        m.surface.colour = {0.36f, 0.07f, 0.05f};
        m.granular = {{0.26f, 0.04f, 0.03f}, 0.5f, 700.0f};
        m.connective = {{0.52f, 0.20f, 0.15f}, 0.2f, 220.0f};
        m.submucosa = {{0.18f, 0.02f, 0.04f}, 0.3f, 110.0f};
        m.roughness = 0.38f;
        m.sssColour = {1.0f, 0.25f, 0.18f};
        m.sigma = {45.0f, 170.0f, 210.0f};
    } else if (has(name, "vessel") || has(name, "artery") || has(name, "vein")) {
        m.surface.colour = {0.30f, 0.03f, 0.06f};
        m.granular.weight = 0.2f;
        m.submucosa.weight = 0.1f;
        m.roughness = 0.3f;
        m.sssWeight = 0.3f;
    } else if (has(name, "fascia") || has(name, "membrane")) {
        m.surface.colour = {0.78f, 0.62f, 0.58f};
        m.granular = {{0.70f, 0.52f, 0.48f}, 0.2f, 1200.0f};
        m.connective = {{0.92f, 0.86f, 0.82f}, 0.5f, 400.0f};
        m.submucosa = {{0.55f, 0.10f, 0.10f}, 0.3f, 90.0f};
        m.roughness = 0.26f;
        m.granularRoughness = 0.06f;
        m.reflection = 0.5f;
        m.sssWeight = 0.6f;
        m.sssColour = {1.0f, 0.55f, 0.45f};
        m.sigma = {150.0f, 300.0f, 380.0f};
        m.flags = kFlagMembrane;
    } else if (has(name, "rectum") || has(name, "bowel") || has(name, "colon")) {
        m.surface.colour = {0.62f, 0.30f, 0.28f}; // serosa over the muscular wall
        m.granular = {{0.55f, 0.24f, 0.22f}, 0.3f, 600.0f};
        m.connective = {{0.80f, 0.58f, 0.52f}, 0.3f, 160.0f};
        m.submucosa = {{0.40f, 0.06f, 0.08f}, 0.3f, 70.0f};
        m.roughness = 0.3f;
        m.sssColour = {1.0f, 0.4f, 0.3f};
    } else if (has(name, "peritoneum") || has(name, "wall") || has(name, "pelvi")) {
        m.surface.colour = {0.66f, 0.40f, 0.38f}; // a thin lining over muscle
        m.granular = {{0.58f, 0.32f, 0.30f}, 0.3f, 600.0f};
        m.connective = {{0.84f, 0.68f, 0.62f}, 0.3f, 160.0f};
        m.submucosa = {{0.45f, 0.08f, 0.10f}, 0.3f, 70.0f};
        m.roughness = 0.3f;
        m.sssColour = {1.0f, 0.45f, 0.35f};
    } else if (has(name, "fat")) {
        m.surface.colour = {0.80f, 0.62f, 0.22f};
        m.granular = {{0.72f, 0.50f, 0.15f}, 0.6f, 500.0f};
        m.connective = {{0.85f, 0.72f, 0.45f}, 0.3f, 200.0f};
        m.submucosa = {{0.50f, 0.08f, 0.06f}, 0.25f, 80.0f};
        m.roughness = 0.35f;
        m.sssColour = {1.0f, 0.8f, 0.4f};
        m.sigma = {30.0f, 60.0f, 160.0f};
    }
    return m;
}

} // namespace viscera::render
