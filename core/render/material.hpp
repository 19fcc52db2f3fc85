#pragma once
/// Multi-layer tissue material [A §6.2.2]: four layers blended by procedural patterns evaluated on
/// the rest-state position (so the pattern moves with the tissue): surface (epithelium colour),
/// granular (granule pattern, also drives the granular specular), connective tissue (fibres along
/// `fibreAxis`) and submucosa (vessel pattern, shown more where the tissue is thin). Shading
/// parameters feed the G-buffer (roughness, metallic, reflection) and the SSS term [A eq. 6.8]:
/// f_sub = C·exp(−σ·T) with C = sssColour, σ = sigma (1/m per channel), T = baked thickness.
#include "render/image.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>

namespace viscera::render {

struct TissueLayer {
    Eigen::Vector3f colour{0.6f, 0.2f, 0.2f}; ///< linear albedo
    float weight = 1.0f;                      ///< blend weight in [0, 1]
    float frequency = 300.0f;                 ///< pattern cells per metre (rest frame)
};

/// Bits of the G-buffer flag channel (RT3.a).
enum MaterialFlags : uint8_t { kFlagNone = 0, kFlagMembrane = 1, kFlagTool = 2 };

/// Material maps of a layer [A §6.2.2, Fig. 6.8–6.9], sampled in the G-buffer pass in place of
/// the procedural layers. Each map may be empty (that channel stays procedural or uniform); the
/// maps given have one size. diffuse: sRGB colour; roughness and metallic: the red channel, linear;
/// normal: tangent-space, RGB = (n + 1)/2. Coordinates: the mesh's UVs when it has them, else a
/// triplanar projection of the rest position with `tilesPerMetre` texture repeats per metre.
struct MaterialMaps {
    Image diffuse, roughness, metallic, normal;
    float tilesPerMetre = 20.0f;
    float normalStrength = 1.0f; ///< scales the map's tangent-plane tilt, [0, 4]
};

struct TissueMaterial {
    std::string name = "tissue";
    TissueLayer surface{{0.55f, 0.16f, 0.13f}, 1.0f, 0.0f};
    TissueLayer granular{{0.42f, 0.09f, 0.08f}, 0.45f, 900.0f};
    TissueLayer connective{{0.75f, 0.45f, 0.40f}, 0.25f, 250.0f};
    TissueLayer submucosa{{0.30f, 0.03f, 0.05f}, 0.35f, 120.0f};
    Eigen::Vector3f fibreAxis{1.0f, 0.0f, 0.0f};
    float roughness = 0.42f;         ///< perceptual, α = roughness²
    float granularRoughness = 0.15f; ///< roughness variation driven by the granular pattern
    float metallic = 0.0f;
    float reflection = 0.25f;                      ///< mucus reflection weight (G-buffer "reflection")
    float f0 = 0.028f;                             ///< normal-incidence Fresnel reflectance (wet tissue ≈ water)
    float sssWeight = 0.45f;                       ///< k_sss [A eq. 6.5]
    Eigen::Vector3f sssColour{1.0f, 0.35f, 0.25f}; ///< C [A eq. 6.8]
    Eigen::Vector3f sigma{60.0f, 180.0f, 220.0f};  ///< absorption σ, 1/m, per channel
    uint8_t flags = kFlagNone;
    std::shared_ptr<const MaterialMaps> maps; ///< null: the procedural layers above
};

/// A material for a body or surface name ("liver", "organ", "vessel", "fascia", "fat", …); a
/// generic soft tissue for names it does not know.
TissueMaterial defaultMaterialFor(const std::string& name);

} // namespace viscera::render
