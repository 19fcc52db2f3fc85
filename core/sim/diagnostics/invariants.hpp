#pragma once
/// Per-step invariants checked by the player and the stability suite.
namespace viscera::sim {

struct Invariants {
    bool allFinite = true;
    double maxEnergy = 0;           ///< J, largest total energy seen
    double maxStepDisplacement = 0; ///< m, largest node displacement in one frame
    double maxForce = 0;            ///< N, largest force sent to a haptic device
    int speedClamps = 0;            ///< node-substeps clamped to the solver's maximum speed

    void record(bool finite, double energy, double stepDisplacement, double force) {
        allFinite = allFinite && finite;
        if (energy > maxEnergy) maxEnergy = energy;
        if (stepDisplacement > maxStepDisplacement) maxStepDisplacement = stepDisplacement;
        if (force > maxForce) maxForce = force;
    }
};

} // namespace viscera::sim
