#include "runtime/report.hpp"

#include "runtime/assessment_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace viscera::player {

StepTimeStats stepTimeStats(const std::vector<sim::FrameRecord>& frames) {
    StepTimeStats s;
    if (frames.empty()) return s;
    std::vector<double> t;
    t.reserve(frames.size());
    for (const auto& f : frames)
        t.push_back(f.stepMs);
    std::sort(t.begin(), t.end());
    double sum = 0;
    for (double x : t)
        sum += x;
    s.mean = sum / static_cast<double>(t.size());
    auto pct = [&](double p) {
        size_t i = static_cast<size_t>(std::ceil(p * static_cast<double>(t.size()))) - 1;
        return t[std::min(i, t.size() - 1)];
    };
    s.p50 = pct(0.50);
    s.p99 = pct(0.99);
    s.max = t.back();
    return s;
}

RealTimeFigures realTimeFigures(const SessionResult& r) {
    RealTimeFigures f;
    const StepTimeStats st = stepTimeStats(r.frames);
    f.factorMean = realTimeFactor(r.frameDt, st.mean);
    f.factorP99 = realTimeFactor(r.frameDt, st.p99);
    for (const auto& fr : r.frames)
        f.framesOver += fr.stepMs > r.frameDt * 1e3 ? 1 : 0;
    return f;
}

namespace {

nlohmann::json distribution(const haptics::Distribution& d) {
    return {{"count", d.count}, {"mean", d.mean_us}, {"p50", d.p50_us},
            {"p99", d.p99_us},  {"max", d.max_us},   {"min", d.min_us}};
}

nlohmann::json hapticsJson(const HapticsResult& h) {
    using nlohmann::json;
    json tools = json::array();
    for (const auto& t : h.tools)
        tools.push_back(
            {{"name", t.name}, {"hand", t.hand}, {"arm", t.arm}, {"kind", t.kind}, {"driven_time_s", t.drivenTime_s}});
    const haptics::ServoStats& s = h.servo;
    json servo = {{"rate_hz", 1000.0}, {"ticks", s.ticks}, {"tick_cost_us", distribution(s.tickCost)}};
    if (h.mode == "realtime") {
        servo["overruns"] = s.overruns;
        servo["realtime_priority"] = s.realtimePriority;
        servo["wait"] = s.wait == haptics::ServoWait::Busy ? "busy" : "sleep";
        servo["cpu"] = s.cpu;
        if (s.wait == haptics::ServoWait::SleepSpin) servo["spin_us"] = s.spinNs / 1000;
        if (!s.priorityNote.empty()) servo["priority_note"] = s.priorityNote;
        servo["period_us"] = distribution(s.period);
        servo["jitter_us"] = distribution(s.jitter);
        servo["wake_latency_us"] = distribution(s.wakeLatency);
        servo["physics_realtime_priority"] = h.physicsRealtimePriority;
        servo["physics_cpus"] = h.physicsCpus;
        // How far the frames trailed the wall clock, and how many lacked their own instant's input
        // (HapticsResult): with none missed or earlier, the device's poses, buttons and pedals are
        // the lockstep run's (the proxies also depend on the contact model each tick saw).
        servo["frame_lag_ms"] = {
            {"mean", h.lagMeanMs}, {"max", h.lagMaxMs}, {"max_growth_after_warmup", h.lagGrowthMaxMs}};
        servo["frames_late"] = h.framesLate;
        servo["frames_input_missed"] = h.inputMissed;
        servo["frames_input_from_an_earlier_tick"] = h.inputEarlier;
    }
    const auto& a = s.contactAge;
    json contact = {
        {"physics_period_ms", h.physicsPeriod_s * 1e3},
        {"age_ms",
         {{"mean", a.mean_us * 1e-3}, {"p50", a.p50_us * 1e-3}, {"p99", a.p99_us * 1e-3}, {"max", a.max_us * 1e-3}}},
        {"max_age_over_period", h.maxContactAgeSteps},
        {"max_steps_behind", s.maxStepsBehind},
        {"models_used", s.contactModelsSeen}};
    // The hand-over checked against the physics thread's own publish log (haptics/handover_audit).
    const haptics::HandoverFigures& ho = h.handover;
    contact["handover"] = {
        {"ticks_checked", ho.ticksChecked},
        {"ticks_on_older_model", ho.ticksOnOlderModel},
        {"max_age_over_step", ho.maxAgeOverStep},
        {"models_published", ho.modelsPublished},
        {"physics_step_ms", {{"mean", ho.stepMean_ms}, {"p99", ho.stepP99_ms}, {"max", ho.stepMax_ms}}},
        {"steps_over_period", ho.stepsOverPeriod}};
    if (ho.firstOlderTick_s >= 0) contact["handover"]["first_older_tick_s"] = ho.firstOlderTick_s;
    if (ho.logErrors) contact["handover"]["log_errors"] = ho.logErrors;
    const haptics::SafetyCounts& c = s.safety;
    json safety = {{"ticks", c.ticks},
                   {"non_finite", c.nonFinite},
                   {"disconnected", c.disconnected},
                   {"sim_stale", c.simStale},
                   {"deadman", c.deadman},
                   {"clamped", c.clamped},
                   {"rate_limited", c.rateLimited}};
    const haptics::LinkStats& l = h.link;
    json link = {{"received", l.received},
                 {"rejected_malformed", l.rejectedMalformed},
                 {"rejected_version", l.rejectedVersion},
                 {"rejected_auth", l.rejectedAuth},
                 {"rejected_order", l.rejectedOrder},
                 {"rejected_jump", l.rejectedJump},
                 {"rejected_peer", l.rejectedPeer},
                 {"stale_welcomes", l.staleWelcomes},
                 {"handshakes", l.handshakes},
                 {"dropped_flood", l.droppedFlood},
                 {"sent", l.sent},
                 {"send_errors", l.sendErrors},
                 {"disconnects", l.disconnects},
                 {"reconnects", l.reconnects}};
    return {{"device",
             {{"spec", h.spec},
              {"backend", h.backend},
              {"name", h.name},
              {"arms", h.arms},
              {"pedals", h.pedals},
              {"max_force_n", h.deviceMaxForce_n}}},
            {"case_max_force_n", h.caseMaxForce_n},
            {"mode", h.mode},
            {"tools", tools},
            {"servo", servo},
            {"contact_model", contact},
            {"safety", safety},
            {"link", link},
            {"trace_samples", h.traceSamples},
            {"trace_dropped", s.traceDropped}};
}

} // namespace

std::string traceCsv(const SessionResult& r) {
    std::string out =
        "t_s,arm,device_x,device_y,device_z,tool_x,tool_y,tool_z,force_x,force_y,force_z,force_n,desired_n,"
        "grip_rad,pedals,connected,safety_rules,contact_age_ms,contact_frame\n";
    out.reserve(out.size() + r.trace.size() * 160);
    const int64_t t0 = r.trace.empty() ? 0 : r.trace.front().t_ns;
    char buf[512];
    for (const TraceRow& s : r.trace) {
        std::snprintf(
            buf, sizeof buf, "%.6f,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.5g,%.5g,%.5g,%.5g,%.5g,%.4g,%u,%d,%u,%.4f,%lld\n",
            1e-9 * double(s.t_ns - t0), int(s.arm), s.device.x(), s.device.y(), s.device.z(), s.tool.x(), s.tool.y(),
            s.tool.z(), s.force.x(), s.force.y(), s.force.z(), s.force.norm(), s.desired, s.grip, s.pedals,
            int(s.connected), s.rules, s.contactAge_s * 1e3, static_cast<long long>(s.contactFrame));
        out += buf;
    }
    return out;
}

/// Scripted instruments [A ch. 5]: where each ended, grasps, dissection counts, clips.
static nlohmann::json interactionJson(const sim::InteractionSummary& s) {
    using nlohmann::json;
    auto vec = [](const sim::Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
    json instruments = json::array();
    for (const auto& i : s.instruments)
        instruments.push_back({{"name", i.name},
                               {"kind", i.kind},
                               {"tip_m", vec(i.tip)},
                               {"jaw", i.jaw},
                               {"act", i.act},
                               {"contacts", i.contacts},
                               {"grasped_vertices", i.grasped}});
    json clips = json::array();
    for (const auto& c : s.clips)
        clips.push_back({{"instrument", c.instrument},
                         {"target", c.target},
                         {"fired_at_s", c.firedAt},
                         {"centre_m", vec(c.centre)},
                         {"travel_m", c.travel},
                         {"rotation_deg", c.rotationDeg},
                         {"max_contact_drift_m", c.maxContactDrift},
                         {"region_vertices", c.regionVertices},
                         {"auxiliary_nodes", c.auxiliaryNodes}});
    return {{"instruments", instruments},
            {"max_contacts", s.maxContacts},
            {"grasps", s.grasps},
            {"dissection",
             {{"fascia_edges_cut", s.fasciaEdgesCut},
              {"fascia_triangles_cut", s.fasciaTrianglesCut},
              {"fat_edges_cut", s.fatEdgesCut},
              {"fat_tets_cut", s.fatTetsCut},
              {"fascia_vertices", s.fasciaVertices},
              {"fascia_vertices_at_start", s.fasciaVerticesAtStart},
              {"max_edge_heat_c", s.maxEdgeHeat},
              {"grid_max_c", s.gridMaxC},
              {"ms_total", s.dissectionMs}}},
            {"clips", clips},
            {"clip_ms_total", s.clipMs}};
}

/// Suturing figures [B ch. 4] of a "fem" case: per frame the enforced constraint rows, contacts,
/// thread tension and needle force; the closure (gap, penetration) on sampled frames and at the end.
static nlohmann::json sutureJson(const SessionResult& r) {
    using nlohmann::json;
    const sim::SutureSummary& s = *r.suture;
    json frames = json::array();
    for (const auto& f : r.sutureFrames) {
        json j = {{"frame", f.frame},
                  {"active_rows", f.activeRows},
                  {"rejected_rows", f.rejectedRows},
                  {"contacts", f.contacts},
                  {"punctures", f.punctures},
                  {"thread_tension_n", f.threadTension},
                  {"needle_force_n", f.needleForce},
                  {"thread_engaged", f.threadEngaged}};
        if (f.maxGap >= 0) j["max_gap_m"] = f.maxGap;
        if (f.maxPenetration >= 0) j["max_penetration_m"] = f.maxPenetration;
        frames.push_back(std::move(j));
    }
    json doc = {{"punctures", s.punctures},
                {"thread_tension_n", s.finalThreadTension},
                {"max_thread_tension_n", s.maxThreadTension},
                {"max_active_rows", s.maxActiveRows},
                {"max_contacts", s.maxContacts},
                {"frames", std::move(frames)}};
    if (s.gauge) {
        doc["initial_gap_m"] = s.initialGap;
        doc["max_gap_m"] = s.finalGap;
        doc["max_penetration_m"] = s.maxPenetration;
    }
    return doc;
}

/// Tools through trocar ports: the port, its limits and what the run did with them.
static nlohmann::json portsJson(const std::vector<PortFigures>& ports) {
    nlohmann::json a = nlohmann::json::array();
    for (const PortFigures& p : ports)
        a.push_back({{"tool", p.tool},
                     {"kind", p.kind},
                     {"mode", sim::portModeName(p.port.mode)},
                     {"position_m", {p.port.position.x(), p.port.position.y(), p.port.position.z()}},
                     {"insertion_limits_m", {p.port.insertionMin, p.port.insertionMax}},
                     {"max_angle_deg", p.port.maxAngleDeg},
                     {"insertion_used_m", {p.insertionMin_m, p.insertionMax_m}},
                     {"frames_at_limit", p.framesAtLimit},
                     {"frames", p.frames}});
    for (size_t k = 0; k < ports.size(); ++k)
        if (ports[k].shaftMeasured) a[k]["max_shaft_distance_m"] = ports[k].maxShaftDistance_m;
    return a;
}

/// The session's timeline (tool tips, forces, task events): what `viscera-player plot` draws.
/// Positions rounded to 1 µm, forces to 0.1 mN, times to 1 µs.
static nlohmann::json timelineJson(const SessionTimeline& tl) {
    using nlohmann::json;
    // A non-finite value stays so (written as null: a gap in the plots, never a number).
    auto round = [](double v, double q) { return std::isfinite(v) ? std::round(v / q) * q : v; };
    json t = json::array();
    for (double v : tl.t_s)
        t.push_back(round(v, 1e-6));
    json tools = json::array();
    for (const SessionTimeline::Tool& tool : tl.tools) {
        json tip = json::array(), force = json::array();
        for (const Eigen::Vector3d& p : tool.tip)
            tip.push_back({round(p.x(), 1e-6), round(p.y(), 1e-6), round(p.z(), 1e-6)});
        for (double f : tool.force_n)
            force.push_back(round(f, 1e-4));
        tools.push_back(
            {{"name", tool.name}, {"kind", tool.kind}, {"hand", tool.hand}, {"tip_m", tip}, {"force_n", force}});
    }
    json events = json::array();
    for (const SessionTimeline::Event& e : tl.events) {
        events.push_back({{"t_s", round(e.t_s, 1e-6)},
                          {"frame", e.frame},
                          {"kind", e.kind},
                          {"tool", e.tool},
                          {"count", e.count},
                          {"at_m", {round(e.at.x(), 1e-6), round(e.at.y(), 1e-6), round(e.at.z(), 1e-6)}}});
        if (!e.swept.empty()) {
            json swept = json::array();
            for (const Eigen::Vector3d& p : e.swept)
                swept.push_back({round(p.x(), 1e-6), round(p.y(), 1e-6), round(p.z(), 1e-6)});
            events.back()["swept_m"] = swept;
        }
        if (e.rest)
            events.back()["rest_m"] = {round(e.rest->x(), 1e-6), round(e.rest->y(), 1e-6), round(e.rest->z(), 1e-6)};
    }
    json doc = {{"stride_frames", tl.stride}, {"t_s", t}, {"tools", tools}, {"events", events}};
    if (!tl.cameraTip.empty()) {
        json tip = json::array(), steering = json::array();
        for (const Eigen::Vector3d& p : tl.cameraTip)
            tip.push_back({round(p.x(), 1e-6), round(p.y(), 1e-6), round(p.z(), 1e-6)});
        for (char c : tl.cameraSteering)
            steering.push_back(c != 0);
        doc["camera"] = {{"tip_m", tip}, {"steering", steering}};
    }
    return doc;
}

namespace {

/// The task figures of the "metrics" block, every one from the session's assessment (one
/// definition each); the device's forces under their own names.
void writeTaskMetrics(const SessionResult& r, nlohmann::json& m) {
    const Assessment& a = r.assessment;
    auto value = [&](const char* name) {
        const MetricResult* x = a.find(name);
        return x && x->value ? *x->value : 0.0;
    };
    m["time_s"] = r.metrics.time_s;
    m["tool_path_length_m"] = value("path_length_m");
    m["tool_names"] = nlohmann::json::array();
    m["tool_path_length_per_tool_m"] = nlohmann::json::array();
    m["max_contact_force_per_tool_n"] = nlohmann::json::array();
    for (const ToolFigures& t : a.tools) {
        m["tool_names"].push_back(t.name);
        m["tool_path_length_per_tool_m"].push_back(t.pathM);
        m["max_contact_force_per_tool_n"].push_back(t.forceMaxN);
    }
    m["mean_contact_force_n"] = value("force_mean_n");
    m["max_contact_force_n"] = value("force_max_n");
    m["tissue_damage_ns"] = value("tissue_damage_ns");
    m["device_max_force_n"] = r.metrics.maxForce_n;
    m["device_mean_force_n"] = r.metrics.meanForce_n;
}

/// Who ran what, when, with which player: what the results database files a session under.
nlohmann::json recordJson(const SessionResult& r) {
    return {{"trainee", r.trainee}, {"started_utc", r.startedUtc},   {"player_version", VISCERA_VERSION},
            {"case_id", r.caseId},  {"case_version", r.caseVersion}, {"package_sha256", r.package.sha256}};
}

/// Which bytes ran and who signed them.
nlohmann::json packageJson(const vcase::Provenance& p) {
    auto orNull = [](const std::string& s) { return s.empty() ? nlohmann::json() : nlohmann::json(s); };
    return {{"file", p.file},
            {"sha256", p.sha256},
            {"bytes", p.bytes},
            {"signature", p.signature},
            {"signer", orNull(p.signer)},
            {"key_id", orNull(p.keyId)},
            {"expires", orNull(p.expires)},
            {"allow_unsigned", p.allowUnsigned}};
}

} // namespace

std::string packageSummary(const vcase::Provenance& p) {
    std::string who;
    if (p.signature == "trusted")
        who = "signed by " + p.signer + " (" + p.keyId + ")";
    else if (p.signature == "untrusted")
        who = "NOT VERIFIED: signed by " + p.keyId + " ('" + p.signer +
              "'), a key not trusted here (run with --allow-unsigned)";
    else
        who = "UNSIGNED (run with --allow-unsigned)";
    return who + "; sha256 " + p.sha256 + ", " + std::to_string(p.bytes) + " bytes";
}

nlohmann::json reportJson(const SessionResult& r) {
    using nlohmann::json;
    json doc;
    doc["schemaVersion"] = kReportSchemaVersion;
    doc["case"] = {{"id", r.caseId}, {"version", r.caseVersion}, {"title", r.title}};
    doc["package"] = packageJson(r.package);
    doc["active_subsystems"] = r.activeSubsystems;
    json frames = json::array();
    for (const auto& f : r.frames)
        frames.push_back({{"index", f.index},
                          {"step_ms", f.stepMs},
                          {"substeps", f.substeps},
                          {"iterations", f.iterations},
                          {"energy_j", f.energy},
                          {"max_displacement_m", f.maxDisplacement}});
    doc["frames"] = std::move(frames);
    json accuracy = json::array();
    for (const auto& a : r.accuracy)
        accuracy.push_back({{"frame", a.frame},
                            {"solver", a.solver},
                            {"iterations", a.iterations},
                            {"rel_error", a.relError},
                            {"time_ms", a.timeMs}});
    doc["accuracy"] = std::move(accuracy);
    doc["invariants"] = {{"all_finite", r.invariants.allFinite},
                         {"max_energy", r.invariants.maxEnergy},
                         {"max_step_displacement_m", r.invariants.maxStepDisplacement},
                         {"max_force_n", r.invariants.maxForce},
                         {"speed_clamps", r.invariants.speedClamps}};
    const StepTimeStats st = stepTimeStats(r.frames);
    doc["metrics"] = {{"frames", r.frames.size()},
                      {"sim_time_s", r.simTime},
                      {"wall_time_s", r.wallTime},
                      {"step_ms_mean", st.mean},
                      {"step_ms_p50", st.p50},
                      {"step_ms_p99", st.p99},
                      {"step_ms_max", st.max},
                      {"nodes", r.nodes},
                      {"tets", r.tets},
                      {"max_node_displacement_m", r.maxNodeDisplacement},
                      {"final_node_displacement_m", r.finalNodeDisplacement}};
    const RealTimeFigures rt = realTimeFigures(r);
    doc["metrics"]["frame_dt_s"] = r.frameDt;
    doc["metrics"]["real_time_factor"] = rt.factorMean;
    doc["metrics"]["real_time_factor_p99"] = rt.factorP99;
    doc["metrics"]["frames_slower_than_real_time"] = rt.framesOver;
    doc["metrics"]["slower_than_real_time"] = rt.slower();
    if (r.realTimeEstimate > 0) doc["metrics"]["real_time_estimate"] = r.realTimeEstimate;
    for (const SessionResult::BodyInertia& b : r.inertia) // selective inertia scaling, per body
        doc["metrics"]["added_inertia"][b.name] = {{"mass_kg", b.massKg}, {"added_kg", b.addedKg}};
    writeTaskMetrics(r, doc["metrics"]);
    doc["record"] = recordJson(r);
    doc["assessment"] = assessmentJson(r.assessment);
    const TaskMetrics& tm = r.metrics;
    doc["metrics"]["punctures"] = tm.punctures;
    doc["metrics"]["clips"] = tm.clips;
    doc["metrics"]["cut_edges"] = tm.cutEdges;
    if (r.haptics) doc["haptics"] = hapticsJson(*r.haptics);
    if (r.suture) doc["suture"] = sutureJson(r);
    if (r.interaction) doc["interaction"] = interactionJson(*r.interaction);
    if (!r.ports.empty()) doc["ports"] = portsJson(r.ports);
    if (r.render) {
        json passes = json::array();
        for (const auto& p : r.render->passes)
            passes.push_back({{"name", p.name}, {"eye", p.eye}, {"ms", p.ms}});
        doc["render"] = {{"device", r.render->device},
                         {"image", r.render->image},
                         {"width", r.render->width},
                         {"height", r.render->height},
                         {"frame_ms", r.render->totalMs},
                         {"upload_ms", r.render->uploadMs},
                         {"passes", passes}};
    }
    doc["timeline"] = timelineJson(r.timeline);
    doc["errors"] = r.errors;
    doc["warnings"] = r.warnings;
    return doc;
}

namespace {

/// The summary's device lines: servo timing, pacing, forces, the hand-over and the console link.
std::string hapticsSummary(const HapticsResult& h, const TaskMetrics& m) {
    std::string out;
    const auto& p = h.servo.period;
    const auto& j = h.servo.jitter;
    char line[512];
    if (h.mode == "realtime") {
        std::snprintf(line, sizeof line,
                      "haptics       %s (%s), %llu ticks, period mean %.1f us, jitter p99 %.1f us, max %.1f us\n",
                      h.spec.c_str(), h.mode.c_str(), (unsigned long long)h.servo.ticks, p.mean_us, j.p99_us, j.max_us);
        out += line;
        std::snprintf(line, sizeof line,
                      "pacing        frames started late against the wall clock: mean %.1f ms, max %.1f ms, %lld "
                      "over one frame, %lld without their own input, %lld from an earlier tick; servo %s, %s\n",
                      h.lagMeanMs, h.lagMaxMs, (long long)h.framesLate, (long long)h.inputMissed,
                      (long long)h.inputEarlier,
                      h.servo.wait == haptics::ServoWait::Busy
                          ? "busy"
                          : ("sleep, spin " + std::to_string(h.servo.spinNs / 1000) + " us").c_str(),
                      h.servo.cpu >= 0 ? ("on CPU " + std::to_string(h.servo.cpu) + ", the physics off it").c_str()
                                       : "sharing the physics' CPUs");
    } else
        std::snprintf(line, sizeof line, "haptics       %s (%s), %llu ticks\n", h.spec.c_str(), h.mode.c_str(),
                      (unsigned long long)h.servo.ticks);
    out += line;
    std::snprintf(
        line, sizeof line,
        "device force  max %.2f N, mean %.2f N (after the safety filter), contact model age max %.2f ms (%.2f "
        "periods)\n",
        m.maxForce_n, m.meanForce_n, h.servo.contactAge.max_us * 1e-3, h.maxContactAgeSteps);
    out += line;
    const haptics::HandoverFigures& ho = h.handover;
    std::snprintf(line, sizeof line,
                  "hand-over     %llu of %llu ticks on an older model than the newest published; age <= %.4f of the "
                  "physics step in progress; steps mean %.2f ms, p99 %.2f, max %.2f (%lld over the period)\n",
                  (unsigned long long)ho.ticksOnOlderModel, (unsigned long long)ho.ticksChecked, ho.maxAgeOverStep,
                  ho.stepMean_ms, ho.stepP99_ms, ho.stepMax_ms, (long long)ho.stepsOverPeriod);
    out += line;
    if (h.backend == "console") {
        const haptics::LinkStats& l = h.link;
        std::snprintf(line, sizeof line,
                      "link          %llu sessions, %llu disconnects, %llu reconnects; refused: %llu forged or "
                      "of no session, %llu replayed or late, %llu jumped, %llu from another address, %llu "
                      "malformed, %llu of another version, %llu stale welcomes\n",
                      (unsigned long long)l.handshakes, (unsigned long long)l.disconnects,
                      (unsigned long long)l.reconnects, (unsigned long long)l.rejectedAuth,
                      (unsigned long long)l.rejectedOrder, (unsigned long long)l.rejectedJump,
                      (unsigned long long)l.rejectedPeer, (unsigned long long)l.rejectedMalformed,
                      (unsigned long long)l.rejectedVersion, (unsigned long long)l.staleWelcomes);
        out += line;
    }
    return out;
}

} // namespace

namespace {

/// The tools line: each tool's path and largest tissue force, as the page and the plots give them.
std::string toolsSummary(const Assessment& a) {
    if (a.tools.empty()) return {};
    std::string per;
    for (const ToolFigures& t : a.tools)
        per += (per.empty() ? "" : "; ") + t.name + " " + formatFigure(t.pathM) + " m, " + formatFigure(t.forceMaxN) +
               " N";
    const MetricResult* path = a.find("path_length_m");
    const MetricResult* force = a.find("force_max_n");
    return "tools         path " + formatFigure(path ? path->value : std::nullopt) +
           " m, largest force from the tissue " + formatFigure(force ? force->value : std::nullopt) + " N (" + per +
           ")\n";
}

/// The port lines and the solver's error against run time on the last sampled frame [A eq. 4.45].
std::string portsAndAccuracySummary(const SessionResult& r) {
    std::string out;
    for (const PortFigures& p : r.ports) {
        char line[256], shaft[64] = "";
        if (p.shaftMeasured)
            std::snprintf(shaft, sizeof shaft, "shaft within %.3f mm of the port, ", p.maxShaftDistance_m * 1e3);
        std::snprintf(line, sizeof line,
                      "port          %s (%s): %sinsertion %.0f-%.0f mm of %.0f-%.0f, %d of %d frames at a limit\n",
                      p.tool.c_str(), sim::portModeName(p.port.mode), shaft, p.insertionMin_m * 1e3,
                      p.insertionMax_m * 1e3, p.port.insertionMin * 1e3, p.port.insertionMax * 1e3, p.framesAtLimit,
                      p.frames);
        out += line;
    }
    // Error against run time on the last sampled frame [A eq. 4.45].
    for (auto it = r.accuracy.rbegin(); it != r.accuracy.rend(); ++it) {
        if (it->solver != "xpbd" || it->relError.size() < 2) continue;
        size_t k = 1;
        while (k < it->relError.size() && it->relError[k] > 1e-4)
            ++k;
        char line[256];
        if (k < it->relError.size())
            std::snprintf(
                line, sizeof line,
                "accuracy      frame %d: XPBD rel. error %.2e after 1 iteration, <= 1e-4 after %d (%.3f ms)\n",
                it->frame, it->relError[1], it->iterations[k], it->timeMs[k]);
        else
            std::snprintf(line, sizeof line,
                          "accuracy      frame %d: XPBD rel. error %.2e after 1 iteration, %.2e after %d (%.3f ms)\n",
                          it->frame, it->relError[1], it->relError.back(), it->iterations.back(), it->timeMs.back());
        out += line;
        break;
    }
    return out;
}

} // namespace

std::string verdictText(const Assessment& a) {
    if (!a.judged) return "none (the case has no assessment)";
    int failed = 0;
    std::string names;
    for (const MetricResult& m : a.metrics)
        if (!m.passed) names += (failed++ ? ", " : "") + m.name;
    const std::string detail = a.verdictDetail();
    return std::string(a.passed ? "PASS" : "FAIL") + (a.passed ? "" : " (" + names + ")") +
           (detail.empty() ? "" : "; " + detail);
}

std::string assessmentSummary(const Assessment& a) {
    std::string out;
    for (const MetricResult& m : a.metrics)
        out += "metric        " + metricLine(m) + "\n";
    return out + "verdict       " + verdictText(a) + "\n";
}

std::string summaryText(const SessionResult& r) {
    const StepTimeStats st = stepTimeStats(r.frames);
    std::string subs;
    for (const auto& s : r.activeSubsystems)
        subs += (subs.empty() ? "" : ", ") + s;
    char buf[1400];
    std::snprintf(buf, sizeof buf,
                  "case          %s %s%s%s\n"
                  "subsystems    %s\n"
                  "mesh          %zu nodes, %zu tets\n"
                  "frames        %zu (%.3f s simulated in %.3f s wall)\n"
                  "step time     mean %.3f ms, p50 %.3f ms, p99 %.3f ms, max %.3f ms\n"
                  "displacement  largest node distance from rest %.3f mm over the run (%.3f mm at the end); "
                  "largest node move in one frame %.3f mm\n"
                  "energy        largest total %.4g J (elastic + kinetic + gravitational, measured from the rest "
                  "pose)\n"
                  "invariants    all finite: %s\n"
                  "status        %s\n",
                  r.caseId.c_str(), r.caseVersion.c_str(), r.title.empty() ? "" : " — ", r.title.c_str(),
                  subs.empty() ? "(none)" : subs.c_str(), r.nodes, r.tets, r.frames.size(), r.simTime, r.wallTime,
                  st.mean, st.p50, st.p99, st.max, r.maxNodeDisplacement * 1e3, r.finalNodeDisplacement * 1e3,
                  r.invariants.maxStepDisplacement * 1e3, r.invariants.maxEnergy, r.invariants.allFinite ? "yes" : "NO",
                  r.ok() ? "ok"
                         : ("FAILED: " + (r.errors.empty() ? std::string("invariants") : r.errors.front())).c_str());
    std::string out = buf;
    if (!r.package.sha256.empty()) out.insert(out.find('\n') + 1, "package       " + packageSummary(r.package) + "\n");
    if (const RealTimeFigures rt = realTimeFigures(r); rt.factorMean > 0) {
        char line[320];
        std::snprintf(line, sizeof line,
                      "real time     factor %.2f (p99 step %.2f); %zu of %zu frames over %.1f ms%s\n", rt.factorMean,
                      rt.factorP99, rt.framesOver, r.frames.size(), r.frameDt * 1e3,
                      rt.slower() ? " — PHYSICS SLOWER THAN REAL TIME" : "");
        out += line;
    }
    for (const SessionResult::BodyInertia& b : r.inertia)
        if (b.addedKg > 0) {
            char line[256];
            std::snprintf(line, sizeof line,
                          "inertia       '%s' +%.2f g on %.1f g (%.1f %%, selective inertia scaling)\n", b.name.c_str(),
                          b.addedKg * 1e3, b.massKg * 1e3, b.massKg > 0 ? 100 * b.addedKg / b.massKg : 0.0);
            out += line;
        }
    for (const std::string& w : r.warnings)
        out += "warning       " + w + "\n";
    out += toolsSummary(r.assessment);
    if (r.haptics) out += hapticsSummary(*r.haptics, r.metrics);
    if (!r.trainee.empty()) out += "trainee       " + r.trainee + ", started " + r.startedUtc + "\n";
    if (r.render) {
        std::string passes;
        for (const auto& p : r.render->passes) {
            char item[96];
            std::snprintf(item, sizeof item, "%s%s %.1f", passes.empty() ? "" : ", ", p.name.c_str(), p.ms);
            passes += item;
        }
        char line[1024];
        std::snprintf(line, sizeof line, "render        %dx%d frame %.1f ms (%s ms) -> %s\n", r.render->width,
                      r.render->height, r.render->totalMs, passes.c_str(), r.render->image.c_str());
        out += line;
    }
    if (r.suture) {
        char line[256];
        std::snprintf(line, sizeof line,
                      "suture        %d punctures, thread tension %.3f N (max %.3f N), max %d rows, %d contacts\n",
                      r.suture->punctures, r.suture->finalThreadTension, r.suture->maxThreadTension,
                      r.suture->maxActiveRows, r.suture->maxContacts);
        out += line;
        if (r.suture->gauge) {
            std::snprintf(line, sizeof line, "closure       gap %.3f mm (from %.3f mm), max penetration %.3f mm\n",
                          r.suture->finalGap * 1e3, r.suture->initialGap * 1e3, r.suture->maxPenetration * 1e3);
            out += line;
        }
    }
    if (r.interaction) {
        const sim::InteractionSummary& in = *r.interaction;
        char line[512];
        std::snprintf(
            line, sizeof line,
            "instruments   %zu, max %d contacts, %d grasps; cut %d fascia edges (%d triangles), %d fat edges; "
            "fascia vertices %zu of %zu; %zu clips\n",
            in.instruments.size(), in.maxContacts, in.grasps, in.fasciaEdgesCut, in.fasciaTrianglesCut, in.fatEdgesCut,
            in.fasciaVertices, in.fasciaVerticesAtStart, in.clips.size());
        out += line;
        for (const auto& c : in.clips) {
            std::snprintf(line, sizeof line,
                          "clip          on %s at %.2f s: travel %.2f mm, rotation %.1f deg, max drift %.3f mm\n",
                          c.target.c_str(), c.firedAt, c.travel * 1e3, c.rotationDeg, c.maxContactDrift * 1e3);
            out += line;
        }
    }
    out += portsAndAccuracySummary(r);
    return out + assessmentSummary(r.assessment);
}

} // namespace viscera::player
