#include "sim/reference/accuracy.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

int firstBelow(const AccuracyTrace& trace, double threshold) {
    for (size_t i = 0; i < trace.relError.size(); ++i)
        if (trace.relError[i] <= threshold) return static_cast<int>(i);
    return -1;
}

namespace {

void setFloor(AccuracyTrace& t) {
    const double noise = 64 * std::numeric_limits<double>::epsilon() * std::abs(t.fStar);
    const double span = t.f0 - t.fStar;
    t.relErrorFloor = span > noise ? noise / span : 1.0;
}

void setReference(AccuracyTrace& trace, const StepProblem& problem, const NewtonResult& reference) {
    trace.h = problem.h;
    trace.fStar = reference.f;
    trace.referenceStatus = newtonStatusName(reference.status);
    trace.referenceIterations = reference.iterations;
    trace.referenceGradientNorm = reference.gradientNorms.empty() ? 0.0 : reference.gradientNorms.back();
    trace.referenceMs = 1e3 * reference.totalSeconds;
}

} // namespace

AccuracyRecorder::AccuracyRecorder(std::string solver, const StepProblem& problem, const NewtonResult& reference,
                                   const std::vector<Vec3>& x0)
    : m_problem(problem) {
    const size_t nv = problem.xTilde.size();
    if (x0.size() != nv || reference.x.size() != nv)
        throw std::invalid_argument("sim::AccuracyRecorder(): x0 (" + std::to_string(x0.size()) +
                                    ") and the reference (" + std::to_string(reference.x.size()) +
                                    ") must have one position per node (" + std::to_string(nv) + ")");
    m_trace.solver = std::move(solver);
    setReference(m_trace, problem, reference);
    m_trace.f0 = problem.objective(x0);
    setFloor(m_trace);
    m_trace.iterations.push_back(0);
    m_trace.relError.push_back(relativeError(m_trace.f0, m_trace.f0, m_trace.fStar));
    m_trace.timeMs.push_back(0.0);
}

void AccuracyRecorder::observe(int k, const std::vector<Vec3>& xk, double seconds) {
    if (k == 0) return;
    if (k <= m_trace.iterations.back())
        throw std::invalid_argument("sim::AccuracyRecorder::observe(): iteration " + std::to_string(k) +
                                    " does not follow " + std::to_string(m_trace.iterations.back()));
    if (xk.size() != m_problem.xTilde.size())
        throw std::invalid_argument("sim::AccuracyRecorder::observe(): x_k has " + std::to_string(xk.size()) +
                                    " nodes, the problem has " + std::to_string(m_problem.xTilde.size()));
    m_trace.iterations.push_back(k);
    m_trace.relError.push_back(relativeError(m_problem.objective(xk), m_trace.f0, m_trace.fStar));
    m_trace.timeMs.push_back(1e3 * seconds);
}

AccuracyTrace measureXpbd(const XpbdSolver& solver, int maxIterations, const NewtonSettings& settings,
                          XpbdIteration mode, double chebyshevRho) {
    if (maxIterations < 1)
        throw std::invalid_argument("sim::measureXpbd(): max_iterations " + std::to_string(maxIterations) +
                                    " must be >= 1");
    const StepProblem problem = solver.nextSubstepProblem();
    const NewtonResult reference = solveNewton(problem, problem.xTilde, settings);
    const char* name = mode == XpbdIteration::Standard          ? "xpbd"
                       : mode == XpbdIteration::PrimalCorrected ? "xpbd-primal"
                                                                : "xpbd-chebyshev";
    AccuracyRecorder recorder(name, problem, reference, problem.xTilde);
    solver.iterateOn(
        problem, maxIterations,
        [&](int k, const std::vector<Vec3>& xk, double seconds) { recorder.observe(k, xk, seconds); }, mode,
        chebyshevRho);
    return recorder.take();
}

AccuracyTrace measureNewton(const XpbdSolver& solver, const NewtonSettings& settings) {
    return measureNewton(solver.nextSubstepProblem(), settings);
}

AccuracyTrace measureNewton(const StepProblem& problem, const NewtonSettings& settings) {
    const NewtonResult r = solveNewton(problem, problem.xTilde, settings);
    AccuracyTrace t;
    t.solver = "newton";
    setReference(t, problem, r);
    if (r.objectives.empty()) return t; // x_0 itself was not finite: nothing to measure
    t.f0 = r.objectives.front();
    setFloor(t);
    for (size_t k = 0; k < r.objectives.size(); ++k) {
        t.iterations.push_back(static_cast<int>(k));
        t.relError.push_back(relativeError(r.objectives[k], t.f0, t.fStar));
        t.timeMs.push_back(1e3 * r.seconds[k]);
    }
    return t;
}

} // namespace viscera::sim
