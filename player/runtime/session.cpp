#include "runtime/session.hpp"

#include "render/embedded_tint.hpp"

#include "render/case_references.hpp"
#include "runtime/realtime_watch.hpp"

#include "sim/skeleton/node_weights_io.hpp"

#include "render/case_settings.hpp"
#include "render/sample_map.hpp"

#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"
#include "sim/util/log.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace viscera::player {
namespace {

/// m: the largest distance of a node from its rest position now (every body).
double nodeDisplacement(const sim::World& world) {
    double d2 = 0;
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        const auto& rest = world.restMesh(b).positions();
        const auto& x = world.positions(b);
        for (size_t v = 0; v < x.size(); ++v)
            d2 = std::max(d2, (x[v] - rest[v]).squaredNorm());
    }
    return std::sqrt(d2);
}

} // namespace

namespace {

/// The corner UVs a material entry names: only for a body, one per boundary triangle.
void loadCornerUvs(LoadedCase& out, const std::vector<render::CaseMaterialMaps>& materials,
                   const std::vector<std::unique_ptr<sim::TetMesh>>& meshes, const std::string& sceneName) {
    const vcase::CasePackage& pkg = *out.package;
    for (const render::CaseMaterialMaps& m : materials) {
        if (m.uv.empty()) continue;
        size_t body = out.scene.bodies.size();
        for (size_t i = 0; i < out.scene.bodies.size(); ++i)
            if (out.scene.bodies[i].name == m.target) body = i;
        if (body == out.scene.bodies.size())
            throw InputError(pkg.name() + ": " + sceneName + ": render.materials." + m.target +
                             ".uv: only a body's maps can be laid by UVs ('" + m.target + "' is not a body)");
        auto probe = meshes[body]->clone(); // the boundary in the render mesh's order
        probe->requireLevel(3);
        out.cornerUvs.emplace_back(m.target, render::parseCornerUv(pkg.read(m.uv), pkg.name() + ":" + m.uv,
                                                                   probe->boundary().triangleCount()));
    }
}

} // namespace

LoadedCase loadCase(const std::filesystem::path& casePath, const vcase::TrustPolicy& trust) {
    LoadedCase out;
    // Whose case it is and whether it may run here, decided on manifest.json and signature.json
    // alone: an unsigned, untrusted, expired or rolled-back package is refused before any other
    // entry is inflated (the zip's directory and limits were checked before).
    out.package = vcase::CasePackage::open(
        casePath, {}, [&](const vcase::PackageHead& head) { out.provenance = vcase::checkProvenance(head, trust); });
    const vcase::CasePackage& pkg = *out.package;
    const std::string sceneName = "scene.json";
    if (!pkg.contains(sceneName))
        throw InputError(pkg.name() + ": " + sceneName + ": required file is missing from the package");
    out.scene = sim::parseScene(pkg.read(sceneName), pkg.name() + ":" + sceneName);
    render::RenderSettings look; // the look the case asks for is checked at load, not at the first frame
    render::applyCaseRender(look, out.scene.render, pkg.name() + ":" + sceneName);
    const std::vector<render::CaseMaterialMaps> materials =
        render::caseMaterialMaps(out.scene.render, pkg.name() + ":" + sceneName);
    // Every file the scene names is in the package (the table the studio's export writes by).
    for (const render::CaseFileRef& ref : render::caseFileReferences(out.scene, materials))
        if (!pkg.contains(ref.path))
            throw InputError(pkg.name() + ": " + sceneName + ": " + ref.field + ": '" + ref.path +
                             "' is not in the package");
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    for (const sim::BodyDesc& b : out.scene.bodies) {
        meshes.push_back(sim::parseVtet(pkg.read(b.meshPath), pkg.name() + ":" + b.meshPath));
    }
    for (size_t i = 0; i < out.scene.bodies.size(); ++i) { // painted stiffness weights travel as files
        sim::BodyDesc& b = out.scene.bodies[i];
        if (b.nodeWeightsPath.empty()) continue;
        b.nodeWeights = sim::parseNodeWeights(pkg.read(b.nodeWeightsPath), pkg.name() + ":" + b.nodeWeightsPath,
                                              meshes[i]->vertexCount());
    }
    out.sampleMaps.resize(out.scene.bodies.size());
    for (size_t i = 0; i < out.scene.bodies.size(); ++i) { // painted light samples, only where they are used
        const sim::BodyDesc& b = out.scene.bodies[i];
        if (b.sampleMapPath.empty()) continue;
        const std::string field =
            pkg.name() + ": " + sceneName + ": bodies[" + std::to_string(i) + "].sample_map_file: ";
        if (look.sampling.mode != render::SampleMode::Painted)
            throw InputError(field + "the case's render.sampling is not 'painted', so the map would not be used");
        out.sampleMaps[i] = render::parseSampleMap(pkg.read(b.sampleMapPath), pkg.name() + ":" + b.sampleMapPath,
                                                   meshes[i]->vertexCount());
    }
    std::vector<sim::TriMesh> surfaces;
    for (const sim::SurfaceDesc& sd : out.scene.surfaces) {
        surfaces.push_back(sim::parseVtri(pkg.read(sd.meshPath), pkg.name() + ":" + sd.meshPath));
    }
    for (const sim::SceneryDesc& sc : out.scene.scenery) // drawn only: no physics reads them
        out.scenery.push_back(sim::parseVtri(pkg.read(sc.meshPath), pkg.name() + ":" + sc.meshPath));
    for (size_t s = 0; s < out.scene.surfaces.size(); ++s) { // so do those painted on a fascia
        sim::SurfaceDesc& sd = out.scene.surfaces[s];
        if (sd.nodeWeightsPath.empty()) continue;
        sd.nodeWeights = sim::parseNodeWeights(pkg.read(sd.nodeWeightsPath), pkg.name() + ":" + sd.nodeWeightsPath,
                                               surfaces[s].vertexCount());
    }
    const auto readEntry = [&pkg](const std::string& path) { return pkg.read(path); };
    for (const render::CaseMaterialMaps& m : materials) {
        const std::string field = pkg.name() + ": " + sceneName + ": render.materials." + m.target + ": ";
        bool named = false;
        for (const sim::BodyDesc& b : out.scene.bodies)
            named |= b.name == m.target;
        for (const sim::SurfaceDesc& sd : out.scene.surfaces)
            named |= sd.name == m.target;
        for (const sim::SceneryDesc& sc : out.scene.scenery)
            named |= sc.name == m.target;
        if (!named) throw InputError(field + "'" + m.target + "' is not a body, surface or scenery of the scene");
    }
    // Before any map is decoded: what they take together, from their headers.
    render::checkDecodedImageBudget(materials, readEntry, pkg.name() + ": " + sceneName);
    for (const render::CaseMaterialMaps& m : materials)
        out.materialMaps.emplace_back(m.target, render::loadMaterialMaps(m, readEntry, pkg.name()));
    loadCornerUvs(out, materials, meshes, sceneName);
    if (out.scene.suture) { // the recorded needle trajectory travels with the case
        out.scene.suture->trajectoryText = pkg.read(out.scene.suture->trajectoryPath);
    }
    if (out.scene.interaction) // so do the instrument tracks
        for (size_t i = 0; i < out.scene.interaction->instruments.size(); ++i) {
            sim::InstrumentDesc& in = out.scene.interaction->instruments[i];
            in.trackText = pkg.read(in.trackPath);
        }
    sim::checkWorkBudget(out.scene, meshes, surfaces, pkg.name() + ": " + sceneName); // names the scene's field
    out.world = sim::World::assemble(out.scene, std::move(meshes), std::move(surfaces), pkg.manifest().features,
                                     pkg.name() + ": manifest.json");
    return out;
}

render::SceneView caseView(const LoadedCase& loaded) {
    render::SceneView view = render::SceneView::fromWorld(*loaded.world);
    for (size_t k = 0; k < loaded.scenery.size() && k < loaded.scene.scenery.size(); ++k)
        render::addScenery(view, loaded.scene.scenery[k].name, loaded.scenery[k]);
    for (size_t b = 0; b < loaded.sampleMaps.size(); ++b) // fascia cut from a body show its map too
        if (!loaded.sampleMaps[b].empty())
            render::applyBodySampleMap(view, b, loaded.scene.bodies[b].name, loaded.sampleMaps[b],
                                       loaded.scene.surfaces);
    for (const auto& [target, uv] : loaded.cornerUvs) // before the maps: the maps are then laid by them
        render::applyCornerUv(view, target, uv);
    for (const auto& [target, maps] : loaded.materialMaps)
        render::applyMaterialMaps(view, target, maps);
    render::tintSurfacesOverEmbeddedBodies(view, *loaded.world); // a vessel seen through the fascia
    return view;
}

namespace {

constexpr size_t kRateWindow = 60; // frames the live real-time factor averages over

/// m³, the sum of the tets' volumes (TetMesh::signedVolume).
double restVolume(const sim::TetMesh& mesh) {
    double v = 0;
    for (size_t t = 0; t < mesh.tetCount(); ++t)
        v += mesh.signedVolume(static_cast<int32_t>(t));
    return v;
}

/// The trainee window's copy of the session after a frame (under the view's lock).
void publishLive(const sim::World& world, const HapticRig* rig, const std::vector<sim::FrameRecord>& frames,
                 const sim::FrameRecord& rec, double frameDt, const std::string& realTimeWarning, LiveView& lv,
                 bool last) {
    // The physics never waits for the window (whose thread runs at idle priority): while the
    // window holds the view, this frame is not shown; the last frame always is.
    std::unique_lock<std::mutex> lock(lv.mutex, std::defer_lock);
    if (last)
        lock.lock();
    else if (!lock.try_lock())
        return;
    if (rig) lv.state = rig->live();
    lv.state.time_s = world.time();
    lv.state.frame = world.frameCount();
    lv.state.realTimeWarning = realTimeWarning;
    double ms = rec.stepMs;
    size_t n = 1;
    for (size_t k = frames.size(); k > 0 && n < kRateWindow; --k, ++n)
        ms += frames[k - 1].stepMs;
    lv.state.physicsMs = ms / static_cast<double>(n);
    lv.state.realTimeFactor = realTimeFactor(frameDt, lv.state.physicsMs);
    LiveGeometry& g = lv.geometry;
    g.nodes.clear();
    for (size_t b = 0; b < world.bodyCount(); ++b)
        g.nodes.insert(g.nodes.end(), world.positions(b).begin(), world.positions(b).end());
    g.surfaces.resize(world.surfaceCount());
    g.surfaceMasks.resize(world.surfaceCount());
    g.surfaceHeat.resize(world.surfaceCount());
    for (size_t k = 0; k < world.surfaceCount(); ++k) {
        g.surfaces[k].assign(world.surfacePositions(k).begin(), world.surfacePositions(k).end());
        if (const sim::InteractionRuntime* in = world.interaction(); in && in->dissects()) {
            in->surfaceFaceMaskInto(k, g.surfaceMasks[k]);
            in->surfaceHeatInto(k, g.surfaceHeat[k]);
        }
    }
    g.bodyTetMasks.resize(world.bodyCount());
    g.bodyHeat.resize(world.bodyCount());
    for (size_t b = 0; b < world.bodyCount(); ++b)
        if (const sim::InteractionRuntime* in = world.interaction(); in && in->dissectsBody(b)) {
            in->bodyTetMaskInto(b, g.bodyTetMasks[b]);
            in->bodyHeatInto(b, g.bodyHeat[b]);
        }
    g.tools = render::toolPoses(world);
}

/// A console link that never answered or degraded (dropped, or zeroed the forces or refused
/// packets out of order on 1 % or more): the session was not driven by the trainee's hands as it
/// should have been, so it is a warning and a failed status.
void checkLink(const HapticsResult& h, SessionResult& r) {
    if (h.backend != "console") return;
    const haptics::LinkStats& l = h.link;
    const uint64_t ticks = h.servo.safety.ticks, zeroed = h.servo.safety.disconnected;
    const double zeroedPct = ticks ? 100.0 * double(zeroed) / double(ticks) : 0.0;
    const uint64_t refused = l.rejectedMalformed + l.rejectedVersion + l.rejectedAuth + l.rejectedOrder +
                             l.rejectedJump + l.rejectedPeer + l.staleWelcomes;
    char buf[400];
    if (l.received == 0)
        std::snprintf(buf, sizeof buf,
                      "haptics: --device %s: the console never answered (0 valid state packets in %llu servo ticks, "
                      "%llu packets refused): the tools did not move",
                      h.spec.c_str(), (unsigned long long)ticks, (unsigned long long)refused);
    else if (l.disconnects > 0 || zeroedPct >= 1.0 || double(l.rejectedOrder) >= 0.01 * double(l.received))
        std::snprintf(buf, sizeof buf,
                      "haptics: the console link degraded: %llu disconnects, forces zeroed for the link on %.1f %% of "
                      "ticks, %llu packets out of order on %llu accepted (allowed: none, under 1 %%, under 1 %%)",
                      (unsigned long long)l.disconnects, zeroedPct, (unsigned long long)l.rejectedOrder,
                      (unsigned long long)l.received);
    else
        return;
    r.warnings.push_back(buf);
    r.errors.push_back(buf);
}

std::string utcNow() {
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

/// The device's figures at the end of a session with a rig.
void collectHaptics(HapticRig& rig, SessionResult& r) {
    rig.finish();
    r.haptics = rig.result();
    r.metrics = rig.metrics();
    r.trace = std::move(rig.trace());
    r.invariants.maxForce = r.metrics.maxForce_n;
    const haptics::HandoverFigures& ho = r.haptics->handover;
    if (ho.ticksOnOlderModel)
        r.errors.push_back("haptics: " + std::to_string(ho.ticksOnOlderModel) +
                           " servo ticks used an older contact model than the newest the physics had published");
    if (ho.logErrors)
        r.errors.push_back("haptics: the hand-over log has " + std::to_string(ho.logErrors) +
                           " publishes out of order");
    checkLink(*r.haptics, r);
}

/// The world's figures at the end of a session.
void collectWorld(const sim::World& world, SessionResult& r) {
    r.simTime = world.time();
    const double deviceMax = r.invariants.maxForce;
    r.invariants = world.invariants();
    r.invariants.maxForce = std::max(r.invariants.maxForce, deviceMax);
    r.accuracy = world.accuracy();
    if (world.hasSuture()) {
        r.suture = world.sutureSummary();
        r.sutureFrames = world.sutureFrames();
        r.metrics.punctures = r.suture->punctures;
        if (const sim::SutureReport* su = world.sutureReport()) {
            r.puncturePoints = su->threadPath();
            if (!r.puncturePoints.empty()) r.puncturePoints.pop_back(); // the needle's end
        }
        if (!r.suture->finite) r.errors.push_back("suture: the closure gauge or the thread tension was not finite");
    }
    r.finalNodeDisplacement = nodeDisplacement(world);
}

} // namespace

SessionResult runSession(LoadedCase& loaded, const RunOptions& options) {
    SessionResult r;
    const vcase::Manifest& m = loaded.package->manifest();
    r.caseId = m.caseId;
    r.caseVersion = m.caseVersion;
    r.package = loaded.provenance;
    r.title = m.title.value_or("");
    r.trainee = options.trainee;
    r.startedUtc = utcNow();
    sim::World& world = *loaded.world;
    r.activeSubsystems = world.activeSubsystems();
    const std::vector<double> added = world.addedInertiaKg();
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        r.nodes += world.restMesh(b).vertexCount();
        r.tets += world.restMesh(b).tetCount();
        if (b < added.size())
            r.inertia.push_back(
                {world.bodyName(b), restVolume(world.restMesh(b)) * loaded.scene.bodies[b].material.density, added[b]});
    }
    r.frames.reserve(static_cast<size_t>(std::max(options.frames, 0)));
    std::unique_ptr<HapticRig> rig;
    if (options.device) {
        rig = std::make_unique<HapticRig>(*options.device, options.deviceSpec, world, options.realtime,
                                          options.keepTrace);
        rig->setServoWait(options.servoWait, options.servoCpu, options.servoSpinNs);
        rig->configure(loaded.scene.xpbd.dt);
        r.activeSubsystems.push_back("haptics");
        if (!rig->drivesAnyTool())
            r.warnings.push_back("--device " + options.deviceSpec +
                                 ": the case declares no tool a device can drive (no 'tools', no instrument "
                                 "with a 'device'); the session runs as without it");
        for (const std::string& n : rig->mappingNotes())
            r.warnings.push_back("--device " + options.deviceSpec + ": " + n);
        for (const std::string& t : rig->undrivenTools())
            r.warnings.push_back("--device " + options.deviceSpec + ": tool '" + t +
                                 "' has no arm of this device to drive it");
        for (const std::string& w : r.warnings)
            log::warn(w);
    }
    TimelineRecorder timeline(world);
    PortMeter ports;
    if (options.live) {
        std::lock_guard<std::mutex> lock(options.live->mutex);
        for (size_t t = 0; t < world.toolCount(); ++t)
            options.live->toolRadius.push_back(world.toolDesc(t).radius);
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (rig) rig->start();
    const double frameDt = world.dt();
    r.frameDt = frameDt;
    // Only a paced session (a device on the wall clock) can fall behind real time.
    const bool paced = rig && options.realtime;
    RealTimeWatch watch(frameDt);
    std::string realTimeWarning;
    for (int f = 0; options.frames == 0 || f < options.frames; ++f) {
        if (options.stop && options.stop->load()) break;
        if (rig) rig->beforeStep();
        sim::FrameRecord rec = world.step();
        if (rig) rig->afterStep();
        timeline.record(world);
        ports.record(world);
        r.maxNodeDisplacement = std::max(r.maxNodeDisplacement, nodeDisplacement(world));
        if (options.live)
            publishLive(world, rig.get(), r.frames, rec, frameDt, realTimeWarning, *options.live,
                        options.frames > 0 && f + 1 == options.frames);
        if (!rec.finite)
            r.errors.push_back("frame " + std::to_string(rec.index) +
                               ": the step produced a non-finite value and was rolled back");
        r.frames.push_back(rec);
        if (paced)
            if (auto w = watch.afterFrame(r.frames)) {
                realTimeWarning = *w;
                r.warnings.push_back(*w);
                log::warn(*w);
            }
        if (options.progress) options.progress(f + 1, options.frames);
    }
    if (rig) collectHaptics(*rig, r);
    r.realTimeEstimate = watch.estimate();
    if (paced)
        if (std::string e = watch.verdict(r.frames, r.haptics->lagGrowthMaxMs, r.haptics->inputMissed); !e.empty())
            r.errors.push_back(e);
    r.metrics.time_s = world.time();
    if (options.live) {
        std::lock_guard<std::mutex> lock(options.live->mutex);
        options.live->finished = true;
    }
    r.wallTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    collectWorld(world, r);
    if (const sim::InteractionRuntime* in = world.interaction()) {
        r.interaction = in->summary();
        r.metrics.clips = static_cast<int>(r.interaction->clips.size());
        r.metrics.cutEdges = r.interaction->fasciaEdgesCut + r.interaction->fatEdgesCut;
    }
    r.timeline = timeline.take();
    r.ports = ports.take();
    r.assessment = assessSession(r, loaded.scene.assessment);
    return r;
}

int replayFrames(double duration, double dt) {
    if (!(dt > 0) || !std::isfinite(duration)) return 300;
    return static_cast<int>(std::ceil((std::max(duration, 0.0) + 0.5) / dt));
}

} // namespace viscera::player
