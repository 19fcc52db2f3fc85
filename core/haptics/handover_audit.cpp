#include "haptics/handover_audit.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::haptics {

void HandoverAudit::reserve(size_t frames) {
    m_stamp.reserve(frames);
    m_done.reserve(frames);
    m_lastUse.reserve(frames);
}

void HandoverAudit::published(int64_t frame, int64_t stamp_ns, int64_t done_ns) {
    if (frame != static_cast<int64_t>(m_stamp.size()) || (!m_done.empty() && done_ns < m_done.back())) {
        ++m_logErrors;
        return;
    }
    m_stamp.push_back(stamp_ns);
    m_done.push_back(std::max(done_ns, stamp_ns));
    m_lastUse.push_back(-1);
}

void HandoverAudit::used(int64_t t_ns, int64_t frame) {
    if (frame < 0) return;
    if (frame >= static_cast<int64_t>(m_stamp.size())) { // a model the log never saw published
        ++m_logErrors;
        return;
    }
    ++m_checked;
    // The newest frame whose publish had completed when the tick started.
    const auto it = std::upper_bound(m_done.begin(), m_done.end(), t_ns);
    const int64_t newest = static_cast<int64_t>(it - m_done.begin()) - 1;
    if (frame < newest) {
        ++m_older;
        if (m_firstOlder < 0) m_firstOlder = t_ns;
    }
    int64_t& last = m_lastUse[static_cast<size_t>(frame)];
    last = std::max(last, t_ns);
}

HandoverFigures HandoverAudit::figures() const {
    HandoverFigures f;
    f.ticksChecked = m_checked;
    f.ticksOnOlderModel = m_older;
    if (m_firstOlder >= 0 && !m_stamp.empty()) f.firstOlderTick_s = 1e-9 * double(m_firstOlder - m_stamp.front());
    f.logErrors = m_logErrors;
    f.modelsPublished = static_cast<int64_t>(m_stamp.size());
    const size_t n = m_stamp.size();
    std::vector<double> steps;
    steps.reserve(n);
    const int64_t periodNs = static_cast<int64_t>(std::llround(m_period_s * 1e9));
    for (size_t k = 0; k + 1 < n; ++k) {
        const int64_t step = m_done[k + 1] - m_done[k];
        steps.push_back(1e-6 * double(step));
        if (periodNs > 0 && step > periodNs + kOverPeriodSlack_ns) ++f.stepsOverPeriod;
        if (m_lastUse[k] >= 0) {
            const double inProgress = double(m_done[k + 1] - m_stamp[k]);
            if (inProgress > 0)
                f.maxAgeOverStep = std::max(f.maxAgeOverStep, double(m_lastUse[k] - m_stamp[k]) / inProgress);
        }
    }
    if (!steps.empty()) {
        double sum = 0;
        for (double s : steps)
            sum += s;
        f.stepMean_ms = sum / double(steps.size());
        std::sort(steps.begin(), steps.end());
        const size_t i99 = std::min(steps.size() - 1, static_cast<size_t>(std::ceil(0.99 * double(steps.size()))) - 1);
        f.stepP99_ms = steps[i99];
        f.stepMax_ms = steps.back();
    }
    return f;
}

} // namespace viscera::haptics
