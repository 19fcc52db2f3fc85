#pragma once
/// Ports over a session (sim/scene/port.hpp): for every instrument and probe that declares one,
/// the insertion range it used and the frames its tip was held at the port's insertion or angle
/// limit; for an instrument also how far from the port its collision shape's shaft passed (the
/// line through the shape's frame along its axis, back the port's shaft length: the geometry the
/// tissue meets, posed by the interaction). A probe's shaft is drawn from its centre through the
/// port, so it has no such figure. Report "ports".
#include "sim/scene/port.hpp"
#include "sim/scene/world.hpp"

#include <string>
#include <vector>

namespace viscera::player {

struct PortFigures {
    std::string tool, kind; ///< kind: the instrument kind or "probe"
    sim::PortDesc port;
    bool shaftMeasured = false;                    ///< instruments: maxShaftDistance_m is measured
    double maxShaftDistance_m = 0;                 ///< largest distance from the port to the shaft, any frame
    double insertionMin_m = 0, insertionMax_m = 0; ///< port to tip, over the run
    int framesAtLimit = 0;                         ///< frames the tip was held at a limit
    int frames = 0;
};

class PortMeter {
public:
    /// After each step.
    void record(const sim::World& world);
    std::vector<PortFigures> take() { return std::move(m_ports); }

private:
    /// direction: the shaft's axis through shaftPoint (towards the tip), or zero (not measured).
    void add(size_t slot, const std::string& tool, const char* kind, const sim::PortDesc& port, const sim::Vec3& tip,
             const sim::Vec3& shaftPoint, const sim::Vec3& direction, bool atLimit);
    std::vector<PortFigures> m_ports;
};

} // namespace viscera::player
