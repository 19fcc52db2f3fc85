#pragma once
/// What a frame is rendered with: output size, camera, rectangular area light and its sampling
/// [A §6.3.2], subsurface scattering switch [A §6.3.1], post effects [A §6.3.3] and stereo [B ch. 4].
/// Plain data; validate() checks the preconditions renderers rely on.
#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace viscera::render {

/// Pinhole camera, world frame, metres.
struct Camera {
    Eigen::Vector3f position{0.0f, -0.16f, 0.12f};
    Eigen::Vector3f target{0.0f, 0.0f, 0.0f};
    Eigen::Vector3f up{0.0f, 0.0f, 1.0f};
    float fovYDeg = 55.0f;    ///< vertical field of view of one eye, degrees
    float nearPlane = 0.005f; ///< m
    float farPlane = 1.0f;    ///< m
};

/// Uniformly emitting one-sided rectangle (the laparoscope light). Radiance is derived from
/// `intensity` so that resizing the light keeps its power: L = intensity / (width · height).
struct AreaLight {
    Eigen::Vector3f center{0.0f, -0.08f, 0.08f};        ///< m, world (ignored when followCamera)
    Eigen::Vector3f direction{0.0f, 0.7071f, -0.7071f}; ///< emitting normal (ignored when followCamera)
    Eigen::Vector3f up{0.0f, 0.0f, 1.0f};               ///< orients the rectangle's height axis
    float width = 0.02f, height = 0.01f;                ///< m
    Eigen::Vector3f colour{1.0f, 0.96f, 0.9f};
    float intensity = 0.03f; ///< W/sr-like units; irradiance at distance d on axis ≈ intensity / d²
    /// Coaxial scope light: centred at the camera plus `cameraOffset` (camera right, up, forward),
    /// facing the view direction.
    bool followCamera = true;
    Eigen::Vector3f cameraOffset{0.0f, 0.0f, 0.0f};
};

/// How many light samples a pixel takes [A eq. 6.15–6.16].
enum class SampleMode : uint8_t {
    Uniform,  ///< `uniformSamples` everywhere (1 = a point light)
    Distance, ///< m(d) from `bands`, d = distance from the shaded point to the light centre
    Painted,  ///< the per-vertex sample map (1×/4×/8×); unpainted vertices take `uniformSamples`
    Reference ///< `referenceSamples` everywhere, no reflection cone: the ground truth
};

/// m(d) = samples for h_{k+1} < d ≤ h_k = maxDistance [A eq. 6.16]; bands sorted by maxDistance.
struct DistanceBand {
    float maxDistance = std::numeric_limits<float>::infinity(); ///< m
    int samples = 1;
};

struct SamplingSettings {
    SampleMode mode = SampleMode::Distance;
    int uniformSamples = 1;
    std::vector<DistanceBand> bands{{0.05f, 8}, {0.09f, 4}, {std::numeric_limits<float>::infinity(), 1}};
    int referenceSamples = 256;
    /// Specular only from the samples inside the reflection cone [A eq. 6.21]; the cone holds the
    /// directions where the GGX lobe is above `coneCutoff` of its peak.
    bool specularCone = true;
    float coneCutoff = 0.01f;
};

struct ChromaticAberration {
    bool enabled = false;
    float strength = 0.006f; ///< red/blue offset at the image corner, fraction of the image size
};
struct ToneMapping {
    bool enabled = false;
    float exposure = 1.4f;
    enum class Operator : uint8_t { Aces, Reinhard } op = Operator::Aces;
};
/// Piecewise-linear curve on display values in [0, 1] (2–8 points, x increasing), applied to all
/// channels, then per-channel gain (colour theme).
struct ColourCurve {
    bool enabled = false;
    std::vector<Eigen::Vector2f> points{{0.0f, 0.0f}, {0.25f, 0.18f}, {0.75f, 0.85f}, {1.0f, 1.0f}};
    Eigen::Vector3f gain{1.04f, 0.96f, 0.92f};
};
struct DepthOfField {
    bool enabled = false;
    float focusDistance = 0.15f; ///< m along the view axis
    float focusRange = 0.02f;    ///< m in focus either side
    float blurPerMetre = 200.0f; ///< circle-of-confusion radius (px) per metre out of focus
    float maxRadiusPx = 5.0f;
};
struct Noise {
    bool enabled = false;
    float amount = 0.04f; ///< amplitude in display units
    uint32_t seed = 1;
    bool animate = false; ///< reseed every frame (off: deterministic frames, goldens)
};
struct Sharpen {
    bool enabled = false;
    float amount = 0.8f; ///< unsharp-mask weight
};
/// Radial gradient mask of the scope's view: 1 inside `inner`, `colour` beyond `outer` (radii as a
/// fraction of the half diagonal).
struct RadialMask {
    bool enabled = false;
    float inner = 0.6f, outer = 1.0f;
    Eigen::Vector3f colour{0.0f, 0.0f, 0.0f};
};

/// Post effects [A §6.3.3], applied in this order; each one disabled runs no pass.
struct PostSettings {
    DepthOfField depthOfField;
    ChromaticAberration chromaticAberration;
    ToneMapping toneMapping;
    ColourCurve colourCurve;
    Sharpen sharpen;
    Noise noise;
    RadialMask radialMask;
    bool anyEnabled() const;
    void disableAll();
};

enum class StereoMode : uint8_t { Off, SideBySide, Anaglyph };
/// Parallel cameras with off-axis frustums [B ch. 4]: both eyes look along the mono view direction,
/// shifted by ±eyeSeparation/2, frustums sheared so that parallax is zero at `convergenceDistance`.
struct StereoSettings {
    StereoMode mode = StereoMode::Off;
    float eyeSeparation = 0.005f;      ///< m (stereo laparoscope baseline)
    float convergenceDistance = 0.12f; ///< m
};

struct RenderSettings {
    int width = 640, height = 480; ///< output pixels (side by side: both eyes together)
    Camera camera;
    AreaLight light;
    SamplingSettings sampling;
    bool subsurface = true;                             ///< SSS term [A eq. 6.10]; off: diffuse takes its weight
    Eigen::Vector3f ambient{0.02f, 0.012f, 0.01f};      ///< constant fill, linear
    Eigen::Vector3f background{0.012f, 0.004f, 0.003f}; ///< linear
    PostSettings post;
    StereoSettings stereo;
    /// Wait for the GPU after every pass to time it (FrameStats::passes). Off: one wait per frame.
    bool timePasses = true;

    /// Throws std::invalid_argument("render::RenderSettings: <field>: <rule>") on a violated rule.
    void validate() const;
};

} // namespace viscera::render
