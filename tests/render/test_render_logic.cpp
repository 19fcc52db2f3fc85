// Renderer logic without GL: pass selection, mesh updates, sample counts [A eq. 6.15–6.16],
// reflection cone [A eq. 6.21], stereo frustums [B ch. 4], settings validation.
#include "render/area_light.hpp"
#include "render/camera.hpp"
#include "render/case_settings.hpp"
#include "render/frame_plan.hpp"
#include "render/renderer.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::render;
using ::testing::HasSubstr;

namespace {

std::vector<PassKind> kinds(const std::vector<PassDesc>& plan) {
    std::vector<PassKind> k;
    for (const PassDesc& p : plan)
        k.push_back(p.kind);
    return k;
}

SceneView sphereView() {
    SceneView v;
    const uint32_t mat = v.addMaterial(defaultMaterialFor("liver"));
    v.addMesh(
        "organ",
        viscera::sim::makeEllipsoidSurface(viscera::sim::Vec3::Zero(), viscera::sim::Vec3(0.05, 0.04, 0.03), 16, 8),
        mat);
    return v;
}

void enableOnly(PostSettings& p, PassKind kind) {
    p.disableAll();
    switch (kind) {
    case PassKind::DepthOfField:
        p.depthOfField.enabled = true;
        break;
    case PassKind::ChromaticAberration:
        p.chromaticAberration.enabled = true;
        break;
    case PassKind::ToneMapping:
        p.toneMapping.enabled = true;
        break;
    case PassKind::ColourCurve:
        p.colourCurve.enabled = true;
        break;
    case PassKind::Sharpen:
        p.sharpen.enabled = true;
        break;
    case PassKind::Noise:
        p.noise.enabled = true;
        break;
    case PassKind::RadialMask:
        p.radialMask.enabled = true;
        break;
    default:
        break;
    }
}

const PassKind kEffects[] = {PassKind::DepthOfField, PassKind::ChromaticAberration,
                             PassKind::ToneMapping,  PassKind::ColourCurve,
                             PassKind::Sharpen,      PassKind::Noise,
                             PassKind::RadialMask};

} // namespace

TEST(FramePlan, AllEffectsOffRunsNoPostPass) {
    RenderSettings s;
    s.post.disableAll();
    const auto plan = planFrame(s);
    EXPECT_EQ(kinds(plan), (std::vector<PassKind>{PassKind::GBuffer, PassKind::Lighting, PassKind::Output}));
    EXPECT_EQ(plan.back().input, Target::Lit);
    EXPECT_EQ(plan.back().output, Target::Final);
}

TEST(FramePlan, EachEffectAloneAddsExactlyItsPass) {
    for (PassKind k : kEffects) {
        RenderSettings s;
        enableOnly(s.post, k);
        EXPECT_EQ(kinds(planFrame(s)),
                  (std::vector<PassKind>{PassKind::GBuffer, PassKind::Lighting, k, PassKind::Output}))
            << passName(k);
    }
}

TEST(FramePlan, ChainOrderAndPingPongNeverOverwriteLit) {
    RenderSettings s;
    s.post.depthOfField.enabled = s.post.chromaticAberration.enabled = s.post.toneMapping.enabled = true;
    s.post.colourCurve.enabled = s.post.sharpen.enabled = s.post.noise.enabled = s.post.radialMask.enabled = true;
    const auto plan = planFrame(s);
    ASSERT_EQ(plan.size(), 10u);
    for (size_t i = 2; i < 9; ++i) {
        EXPECT_EQ(plan[i].kind, kEffects[i - 2]);
        EXPECT_NE(plan[i].output, Target::Lit);
        EXPECT_EQ(plan[i].input, plan[i - 1].output) << "pass " << i;
        EXPECT_NE(plan[i].input, plan[i].output);
    }
    EXPECT_EQ(plan[9].input, plan[8].output);
}

TEST(FramePlan, StereoSideBySideAndAnaglyph) {
    RenderSettings s;
    s.width = 640;
    s.post.disableAll();
    s.stereo.mode = StereoMode::SideBySide;
    auto plan = planFrame(s);
    ASSERT_EQ(plan.size(), 6u);
    EXPECT_EQ(frameLayout(s).eyeWidth, 320);
    EXPECT_EQ(plan[2].kind, PassKind::Output);
    EXPECT_EQ(plan[2].viewport, (Viewport{0, 0, 320, 480}));
    EXPECT_EQ(plan[5].viewport, (Viewport{320, 0, 320, 480}));
    EXPECT_EQ(plan[5].eye, 1);

    s.stereo.mode = StereoMode::Anaglyph;
    plan = planFrame(s);
    ASSERT_EQ(plan.size(), 7u);
    EXPECT_EQ(plan[2].output, Target::EyeLeft);
    EXPECT_EQ(plan[5].output, Target::EyeRight);
    EXPECT_EQ(plan[6].kind, PassKind::StereoCompose);
    EXPECT_EQ(plan[6].output, Target::Final);
}

TEST(Renderer, MockRunsOnlyEnabledPassesAndTimesThem) {
    RenderSettings s;
    s.post.disableAll();
    s.post.toneMapping.enabled = true;
    auto mock = std::make_unique<MockBackend>();
    MockBackend* m = mock.get();
    Renderer r(std::move(mock), s);
    SceneView view = sphereView();
    const FrameStats& st = r.renderFrame(view);
    EXPECT_EQ(kinds(m->passes()),
              (std::vector<PassKind>{PassKind::GBuffer, PassKind::Lighting, PassKind::ToneMapping, PassKind::Output}));
    ASSERT_EQ(st.passes.size(), 4u);
    EXPECT_EQ(st.passes[2].name, "tone_mapping");
    EXPECT_EQ(st.passMs("noise"), 0.0);
    EXPECT_EQ(m->stats().drawCalls, 1u);

    m->clearPasses();
    s.post.toneMapping.enabled = false;
    r.setSettings(s);
    r.renderFrame(view);
    for (const PassDesc& p : m->passes())
        EXPECT_FALSE(isPostEffect(p.kind)) << passName(p.kind);
}

TEST(Renderer, MeshesUpdateInPlaceWithoutReallocation) {
    auto mock = std::make_unique<MockBackend>();
    MockBackend* m = mock.get();
    const RenderSettings defaults;
    Renderer r(std::move(mock), defaults);
    SceneView view = sphereView();
    r.renderFrame(view);
    const uint64_t allocations = m->stats().bufferAllocations;
    ASSERT_GT(allocations, 0u);
    for (int f = 0; f < 5; ++f) {
        for (float& x : view.meshes()[0].positions)
            x *= 1.01f;
        view.recomputeNormals(0);
        r.renderFrame(view);
    }
    EXPECT_EQ(m->stats().bufferAllocations, allocations);
    EXPECT_EQ(m->meshes()[0].updates, 6u); // first upload + 5 frames
    r.renderFrame(view);                   // nothing changed: no update
    EXPECT_EQ(m->meshes()[0].updates, 6u);

    // A mesh that changes its vertex count is refused (warning), not reallocated.
    view.meshes()[0].positions.resize(view.meshes()[0].positions.size() + 3, 0.0f);
    ++view.meshes()[0].revision;
    r.renderFrame(view);
    EXPECT_EQ(m->stats().bufferAllocations, allocations);
    ASSERT_EQ(r.warnings().size(), 1u);
    EXPECT_THAT(r.warnings()[0], HasSubstr("organ"));
}

TEST(AreaLight, SampleCountFromDistanceBands) {
    const std::vector<DistanceBand> bands{{0.05f, 8}, {0.1f, 4}, {INFINITY, 1}};
    EXPECT_EQ(samplesForDistance(bands, 0.0f), 8);
    EXPECT_EQ(samplesForDistance(bands, 0.05f), 8); // h2 < d ≤ h1
    EXPECT_EQ(samplesForDistance(bands, 0.0500001f), 4);
    EXPECT_EQ(samplesForDistance(bands, 0.1f), 4);
    EXPECT_EQ(samplesForDistance(bands, 3.0f), 1);
    const std::vector<DistanceBand> bounded{{0.05f, 8}, {0.1f, 4}};
    EXPECT_EQ(samplesForDistance(bounded, 1.0f), 4); // beyond every band: the last band's count

    SamplingSettings s;
    s.bands = bands;
    s.mode = SampleMode::Uniform;
    EXPECT_EQ(samplesFor(s, 0.0f, 8), 1);
    s.mode = SampleMode::Distance;
    EXPECT_EQ(samplesFor(s, 0.07f, 8), 4);
    s.mode = SampleMode::Painted;
    EXPECT_EQ(samplesFor(s, 0.07f, 8), 8);
    EXPECT_EQ(samplesFor(s, 0.07f, 0), 1); // unpainted: uniform count
    s.mode = SampleMode::Reference;
    EXPECT_EQ(samplesFor(s, 0.07f, 1), 256);
}

TEST(AreaLight, MockLightingGivesNearVerticesMoreSamples) {
    RenderSettings s;
    s.light.followCamera = false;
    s.light.center = {0.08f, 0.0f, 0.0f}; // beside the +x end of the organ
    s.light.direction = {-1.0f, 0.0f, 0.0f};
    s.sampling.bands = {{0.05f, 8}, {0.1f, 4}, {INFINITY, 1}};
    auto mock = std::make_unique<MockBackend>();
    MockBackend* m = mock.get();
    Renderer r(std::move(mock), s);
    SceneView view = sphereView();
    r.renderFrame(view);
    const auto& samples = m->lightingSamples().at(0);
    const auto& pos = view.meshes()[0].positions;
    int near = 0, far = 0;
    for (size_t v = 0; v < samples.size(); ++v) {
        const float d = (Eigen::Map<const Eigen::Vector3f>(&pos[3 * v]) - s.light.center).norm();
        if (d <= 0.05f) {
            EXPECT_EQ(samples[v], 8);
            ++near;
        } else if (d > 0.1f) {
            EXPECT_EQ(samples[v], 1);
            ++far;
        } else {
            EXPECT_EQ(samples[v], 4);
        }
    }
    EXPECT_GT(near, 0);
    EXPECT_GT(far, 0);

    // Painted mode: the sample map decides.
    s.sampling.mode = SampleMode::Painted;
    r.setSettings(s);
    view.paintSampleMap({-0.05f, 0.0f, 0.0f}, 0.02f, 8);
    r.renderFrame(view);
    const auto& painted = m->lightingSamples().at(0);
    for (size_t v = 0; v < painted.size(); ++v)
        EXPECT_EQ(painted[v], view.meshes()[0].sampleMap[v] > 0 ? 8 : 1);
    EXPECT_THROW(view.paintSampleMap({0, 0, 0}, 1.0f, 3), std::invalid_argument);
}

TEST(AreaLight, SamplePatternIsStratified) {
    EXPECT_EQ(samplePoint(0, 1), Eigen::Vector2f(0.5f, 0.5f)); // 1×: a point light at the centre
    for (int m : {4, 8, 256}) {
        std::vector<int> rows(m, 0);
        for (int i = 0; i < m; ++i) {
            const Eigen::Vector2f p = samplePoint(i, m);
            ASSERT_GE(p.y(), 0.0f);
            ASSERT_LT(p.y(), 1.0f);
            EXPECT_NEAR(p.x(), (i + 0.5f) / m, 1e-6f);
            ++rows[std::min(m - 1, int(p.y() * m))];
        }
        for (int c : rows)
            EXPECT_EQ(c, 1) << "m = " << m; // one sample per row: a Latin square
    }
}

TEST(AreaLight, ReflectionConeHoldsTheLobeAboveTheCutoff) {
    const float cutoff = 0.01f;
    float previous = 0.0f;
    for (float rough : {0.1f, 0.2f, 0.3f, 0.4f, 0.5f}) {
        const float angle = reflectionConeHalfAngle(rough, cutoff);
        EXPECT_GT(angle, previous) << rough; // rougher: wider cone
        previous = angle;
        if (angle >= float(M_PI)) continue;
        // GGX D at the cone's half-vector angle equals cutoff · D(0).
        const float a = rough * rough, a2 = a * a, c = std::cos(0.5f * angle);
        const float ratio = a2 * a2 / std::pow(c * c * (a2 - 1.0f) + 1.0f, 2.0f);
        EXPECT_NEAR(ratio, cutoff, 1e-4f) << rough;
    }
    EXPECT_FLOAT_EQ(reflectionConeHalfAngle(0.9f, cutoff), float(M_PI)); // wide lobe: every sample
    EXPECT_LT(reflectionConeHalfAngle(0.1f, cutoff), 0.07f);             // 3.4° for a mirror-like membrane
}

TEST(AreaLight, FollowsTheCamera) {
    AreaLight l;
    l.followCamera = true;
    l.width = 0.02f;
    l.height = 0.01f;
    l.intensity = 0.5f;
    l.cameraOffset = {0.01f, 0.0f, 0.0f};
    Camera c;
    const EyeView e = monoEye(c, 1.5f);
    const LightFrame f = lightFrame(l, e);
    EXPECT_TRUE(f.center.isApprox(e.position + 0.01f * e.right, 1e-5f));
    EXPECT_TRUE(f.normal.isApprox(e.forward, 1e-5f));
    EXPECT_NEAR(f.halfU.norm(), 0.01f, 1e-6f);
    EXPECT_NEAR(f.halfV.norm(), 0.005f, 1e-6f);
    EXPECT_NEAR(f.halfU.dot(f.normal), 0.0f, 1e-6f);
    EXPECT_NEAR(f.area, 2e-4f, 1e-9f);
    EXPECT_NEAR(f.radiance.x() * f.area, l.intensity * l.colour.x(), 1e-5f);
}

TEST(Stereo, ParallelCamerasWithZeroParallaxAtConvergence) {
    Camera c;
    c.position = {0.0f, -0.2f, 0.1f};
    c.target = {0.0f, 0.0f, 0.0f};
    StereoSettings st;
    st.eyeSeparation = 0.006f;
    st.convergenceDistance = 0.15f;
    const float aspect = 4.0f / 3.0f;
    const auto eyes = stereoEyes(c, st, aspect);
    const EyeView mono = monoEye(c, aspect);
    EXPECT_TRUE(eyes[0].forward.isApprox(eyes[1].forward, 1e-6f)); // parallel, not toed in
    EXPECT_TRUE(eyes[0].forward.isApprox(mono.forward, 1e-6f));
    EXPECT_NEAR((eyes[1].position - eyes[0].position).norm(), 0.006f, 1e-6f);
    EXPECT_NEAR((eyes[1].position - eyes[0].position).normalized().dot(mono.right), 1.0f, 1e-5f);
    EXPECT_TRUE((0.5f * (eyes[0].position + eyes[1].position)).isApprox(mono.position, 1e-6f));
    // Off-axis: the projection is sheared (m(0,2) ≠ 0) in opposite directions.
    EXPECT_GT(eyes[0].projection(0, 2), 0.0f);
    EXPECT_NEAR(eyes[0].projection(0, 2), -eyes[1].projection(0, 2), 1e-7f);

    auto ndcX = [](const EyeView& e, const Eigen::Vector3f& p) {
        const Eigen::Vector4f q = e.viewProjection * p.homogeneous();
        return q.x() / q.w();
    };
    for (const Eigen::Vector3f& offset :
         {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.02f, 0, 0), Eigen::Vector3f(0, 0, 0.01f)}) {
        const Eigen::Vector3f atConvergence =
            mono.position + st.convergenceDistance * mono.forward + offset.x() * mono.right + offset.z() * mono.up;
        EXPECT_NEAR(ndcX(eyes[0], atConvergence), ndcX(eyes[1], atConvergence), 1e-5f);
    }
    const Eigen::Vector3f far = mono.position + 0.3f * mono.forward, near = mono.position + 0.08f * mono.forward;
    // Behind the convergence plane: uncrossed (positive) parallax; in front: crossed (negative).
    EXPECT_LT(ndcX(eyes[0], far) - ndcX(eyes[1], far), 0.0f);   // left image point left of the right one
    EXPECT_GT(ndcX(eyes[0], near) - ndcX(eyes[1], near), 0.0f); // crossed
}

TEST(Settings, ValidationNamesTheField) {
    auto message = [](const RenderSettings& s) {
        try {
            s.validate();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    auto with = [&](auto change) {
        RenderSettings s;
        change(s);
        return message(s);
    };
    EXPECT_EQ(with([](RenderSettings&) {}), "accepted");
    EXPECT_THAT(with([](RenderSettings& s) { s.width = 4; }),
                HasSubstr("render::RenderSettings: width/height: must be in [8, 8192]"));
    EXPECT_THAT(with([](RenderSettings& s) {
                    s.sampling.bands = {{0.1f, 8}, {0.05f, 4}};
                }),
                HasSubstr("sampling.bands[1].maxDistance: bands must be sorted"));
    EXPECT_THAT(with([](RenderSettings& s) { s.sampling.uniformSamples = 0; }), HasSubstr("sampling.uniformSamples"));
    EXPECT_THAT(with([](RenderSettings& s) {
                    s.post.colourCurve.points = {{0.5f, 0.0f}, {0.2f, 1.0f}};
                }),
                HasSubstr("post.colourCurve.points[1]: x must increase"));
    RenderSettings s;
    s.width = 641;
    s.stereo.mode = StereoMode::SideBySide;
    EXPECT_THAT(message(s), HasSubstr("width: must be even"));
    EXPECT_THROW(Renderer(std::make_unique<MockBackend>(), s), std::invalid_argument);
}

TEST(CaseRender, TheCaseBlockSwitchesPassesOffAndOn) {
    RenderSettings s;
    applyCaseRender(s,
                    R"({"sss": false, "sampling": "painted", "stereo": "anaglyph",
                        "post": {"tone_mapping": false, "radial_mask": true, "sharpen": true}})",
                    "case.vcase:scene.json");
    EXPECT_FALSE(s.subsurface);
    EXPECT_EQ(s.sampling.mode, SampleMode::Painted);
    EXPECT_EQ(s.stereo.mode, StereoMode::Anaglyph);
    EXPECT_FALSE(s.post.toneMapping.enabled);
    EXPECT_TRUE(s.post.radialMask.enabled);
    EXPECT_TRUE(s.post.sharpen.enabled);
    // What the case leaves out runs no pass: only the two effects it named.
    RenderSettings mono = s;
    mono.stereo.mode = StereoMode::Off;
    EXPECT_EQ(kinds(planFrame(mono)), (std::vector<PassKind>{PassKind::GBuffer, PassKind::Lighting, PassKind::Sharpen,
                                                             PassKind::RadialMask, PassKind::Output}));
    RenderSettings unchanged;
    applyCaseRender(unchanged, "", "x");
    EXPECT_EQ(unchanged.post.anyEnabled(), RenderSettings().post.anyEnabled());
}

TEST(CaseRender, MalformedBlocksNameTheFieldAndLeaveTheSettingsAlone) {
    auto why = [](const char* json) {
        RenderSettings s;
        s.subsurface = true;
        try {
            applyCaseRender(s, json, "liver.vcase:scene.json");
        } catch (const viscera::InputError& e) {
            EXPECT_TRUE(s.subsurface) << "settings changed by a rejected block";
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_EQ(why(R"({"post": {"bloom": true}})").rfind("liver.vcase:scene.json: render.post.bloom: unknown field", 0),
              0u);
    EXPECT_THAT(why(R"({"sss": false, "post": {"noise": 1}})"), HasSubstr("render.post.noise: must be true or false"));
    EXPECT_THAT(why(R"({"sampling": "many"})"),
                HasSubstr("render.sampling: 'many' is not a sampling mode (uniform, distance, painted)"));
    EXPECT_THAT(why(R"({"stereo": 3})"), HasSubstr("render.stereo: must be a string (found number)"));
    EXPECT_THAT(why(R"({"shadows": true})"), HasSubstr("render.shadows: unknown field"));
    EXPECT_THAT(why(R"([1, 2])"), HasSubstr("render: must be an object (found array)"));
    EXPECT_THAT(why(R"({"post": [true]})"), HasSubstr("render.post: must be an object"));
}
