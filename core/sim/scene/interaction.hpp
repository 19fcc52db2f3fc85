#pragma once
/// The "interaction" section of scene.json (XPBD scenes): scripted instruments on recorded tracks
/// and what they do to the tissue [A ch. 5].
///
/// "interaction": {
///   "collision": {"method": "circumsphere", "delta": 0.7,           optional (defaults shown)
///                 "bare_body": false},
///   "instruments": [
///     {"name": "grasper", "kind": "grasper", "track": "tools/grasper.track",
///      "radius": 0.0025, "jaw_length": 0.012},                       → features collision, grasp
///     {"name": "hook", "kind": "energy_hook", "track": "tools/hook.track",
///      "radius": 0.0012, "temperature_c": 170},                      → features collision, dissection
///     {"name": "clipper", "kind": "clip_applier", "track": "tools/clipper.track",
///      "target": "vessel", "jaw_length": 0.008}                      → features collision, clip
///     {"name": "scissors", "kind": "scissors", "track": "tools/scissors.track",
///      "radius": 0.0015, "jaw_length": 0.014}                        → features collision, dissection
///     {"name": "driver", "kind": "needle_driver", "track": "tools/driver.track",
///      "radius": 0.002, "jaw_length": 0.009}                         → features collision
///   ],
///   "tissues": [{"layer": "fascia", "ignition_c": 160, "conductivity": 0.4,
///                "shrink": [0.1, 0.3, 1.0]}]                         what the energy hook can cut
/// }
/// "tissues" lists what the energy hook and the scissors can cut (at least one with either).
/// An instrument may also name the master that drives it when the player runs with a device:
///   "device": {"hand": "left", "motion_scale": 0.25, "force_scale": 1.0, "max_force_n": 15,
///              "damage_force_n": 4, "grip_open_rad": 1.0}                 all optional
/// With a device the master places the tip (its workspace centre at the track's first key, its
/// orientation turning the track's first direction), the grip sets the jaws (jaw = grip /
/// grip_open_rad), the energy pedals (cut or coag) energize a hook and a fully closed grip
/// (jaw < 0.2) fires a clip; the contact force goes back to the master. Several instruments on
/// one hand: the arm's first button hands the arm to the next one (the others wait at their
/// track's first key). Without a device every instrument follows its track.
/// Tracks are files inside the case (instrument_track.hpp). An instrument's tip is the track's
/// position; its shaft points along the track's direction. Grasper: jaws (two capsules) that
/// hold the surface vertices between them while closed (jaw < 0.5). Energy hook: a capsule whose
/// tip sphere is the heat source while act = 1. Clip applier: fires a clip onto `target` at the
/// first key with act = 1; the clip then follows the vessel [A §5.4]. Scissors: jaws that cut
/// (a cold cut, sim::Dissection::shear) every tissue edge within `radius` of the wedge their blades
/// sweep (the clevis to both open tips) each time they close (jaw falls below 0.5 from above it);
/// their blades pass through what they close on. Needle
/// driver: short, strong jaws that hold what lies between them while closed, as a grasper's.
/// Units SI; temperatures °C. Parsing is strict; errors name the origin, the field and the rule.
#include "sim/scene/device_mapping.hpp"
#include "sim/scene/instrument_track.hpp"
#include "sim/scene/port.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

/// How a haptic master drives an instrument (scene "device" of an instrument; see above).
struct InstrumentDeviceDesc : DeviceMapping {
    /// N, contact force above which tissue is damaged (session metrics); none: the case's
    /// assessment force_threshold_n.
    std::optional<double> damageForceN;
    double gripOpenRad = 1.0; ///< rad: the grip angle at which the jaws are fully open
};

struct InstrumentDesc {
    enum class Kind { Grasper, EnergyHook, ClipApplier, Scissors, NeedleDriver };
    /// Jaws that open and close (grasper, clip applier, scissors, needle driver; not the hook).
    bool hasJaws() const { return kind != Kind::EnergyHook; }
    /// Jaws that hold the tissue between them while closed (grasper, needle driver).
    bool holds() const { return kind == Kind::Grasper || kind == Kind::NeedleDriver; }
    std::string name;
    Kind kind = Kind::Grasper;
    std::string trackPath;     ///< file inside the case
    std::string trackText;     ///< its contents, filled by whoever reads the case (not serialized)
    double radius = 0.0025;    ///< m: jaw / shaft radius
    double jawLength = 0.012;  ///< m: grasper and clip jaws
    double temperatureC = 170; ///< energy hook
    std::string target;        ///< clip applier: the tet body (vessel) it clips
    InstrumentDeviceDesc device;
    /// "port" (port.hpp): the shaft passes through it, on the track and under a device; the
    /// track's directions are then replaced by the port's, its tips held to the port's limits.
    PortDesc port;
};

struct DissectionTissueDesc {
    std::string layer;                 ///< a surface (fascia) or tet body name
    double ignitionC = 160;            ///< °C
    double conductivity = 0.4;         ///< ξ of [A eq. 5.11]
    Vec3 shrink = Vec3(0.1, 0.3, 1.0); ///< S_x, S_y, S_z of [A eq. 5.12], each in (0, 1]
};

struct InteractionDesc {
    std::string collisionMethod = "circumsphere"; ///< circumsphere, bounding_sphere or polygon
    double delta = 0.7;                           ///< area-change update threshold δ [A §5.2.4]
    /// "bare_body": with a tissue layer, the tools also meet the body it is attached to where the
    /// layer leaves it bare (InteractionRuntime); off, they meet the layer alone (the cases packaged
    /// before it keep their physics: the rectum's grasper would touch the bare fat at its fascia's
    /// edge, 0.05 → 0.18 N). The studio turns it on for every interaction it makes.
    bool bareBody = false;
    std::vector<InstrumentDesc> instruments;
    std::vector<DissectionTissueDesc> tissues;

    bool has(InstrumentDesc::Kind k) const {
        for (const auto& i : instruments)
            if (i.kind == k) return true;
        return false;
    }
};

/// `json` is the text of the section object. Throws viscera::InputError
/// "<origin>: interaction.<field>: <rule>".
InteractionDesc parseInteractionSection(std::string_view json, const std::string& origin);
/// Checks the names the section refers to: every clip target a tet body, every tissue layer a body
/// or a surface. Throws viscera::InputError "<origin>: interaction.<field>: <rule>".
void checkInteractionNames(const InteractionDesc& desc, const std::vector<std::string>& bodies,
                           const std::vector<std::string>& surfaces, const std::string& origin);
/// The section object as JSON text (parseInteractionSection reads it back).
std::string formatInteractionSection(const InteractionDesc& desc);
const char* kindName(InstrumentDesc::Kind k);

} // namespace viscera::sim
