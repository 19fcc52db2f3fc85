#include "runtime/port_meter.hpp"

#include "sim/scene/interaction_runtime.hpp"

#include <algorithm>

namespace viscera::player {

void PortMeter::add(size_t slot, const std::string& tool, const char* kind, const sim::PortDesc& port,
                    const sim::Vec3& tip, const sim::Vec3& shaftPoint, const sim::Vec3& direction, bool atLimit) {
    if (slot >= m_ports.size()) m_ports.resize(slot + 1);
    PortFigures& p = m_ports[slot];
    const double insertion = (tip - port.position).norm();
    if (p.frames == 0) {
        p.tool = tool;
        p.kind = kind;
        p.port = port;
        p.insertionMin_m = p.insertionMax_m = insertion;
    }
    ++p.frames;
    if (direction.norm() > 0) {
        p.shaftMeasured = true;
        p.maxShaftDistance_m = std::max(
            p.maxShaftDistance_m, sim::shaftDistanceToPort(port.position, shaftPoint, direction, port.shaftLength));
    }
    p.insertionMin_m = std::min(p.insertionMin_m, insertion);
    p.insertionMax_m = std::max(p.insertionMax_m, insertion);
    if (atLimit) ++p.framesAtLimit;
}

void PortMeter::record(const sim::World& world) {
    size_t slot = 0;
    if (const sim::InteractionRuntime* in = world.interaction()) {
        const auto& states = in->summary().instruments;
        for (size_t i = 0; i < states.size() && i < in->instrumentCount(); ++i) {
            const sim::InstrumentDesc& d = in->instrumentDesc(i);
            if (!d.port.declared) continue;
            add(slot++, d.name, states[i].kind, d.port, states[i].tip, states[i].shaftPoint, states[i].shaftAxis,
                states[i].atPortLimit);
        }
    }
    for (size_t t = 0; t < world.toolCount(); ++t) {
        const sim::ToolDesc& d = world.toolDesc(t);
        if (!d.port.declared) continue;
        const sim::Vec3 c = world.toolContact(t).centre;
        const double in = (c - d.port.position).norm();
        const bool atLimit = in <= d.port.insertionMin + 1e-9 || in >= d.port.insertionMax - 1e-9;
        add(slot++, d.name, "probe", d.port, c, c, sim::Vec3::Zero(), atLimit);
    }
}

} // namespace viscera::player
