#include "app/preview_panel.hpp"

#include "app/plot_widget.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QVBoxLayout>

namespace viscera::studio {

PreviewPanel::PreviewPanel(Preview* preview, QWidget* parent) : QWidget(parent), m_preview(preview) {
    setObjectName("previewPanel");
    auto* pl = new QVBoxLayout(this);
    auto* modeRow = new QHBoxLayout;
    m_mode = new QComboBox(this);
    m_mode->setObjectName("previewMode");
    m_mode->addItems({tr("Preview: the scene"), tr("Preview: uniaxial specimen of the selected material")});
    connect(m_mode, &QComboBox::currentIndexChanged, this, [this](int) { emit modeChanged(); });
    modeRow->addWidget(m_mode, 1);
    auto* pause = new QCheckBox(tr("Pause"), this);
    pause->setObjectName("previewPause");
    connect(pause, &QCheckBox::toggled, this, [this](bool on) { m_preview->setPaused(on); });
    modeRow->addWidget(pause);
    pl->addLayout(modeRow);
    m_verdict = new QLabel(this);
    m_verdict->setObjectName("stabilityVerdict");
    m_verdict->setWordWrap(true);
    pl->addWidget(m_verdict);
    m_errorPlot = new PlotWidget(this);
    m_errorPlot->setObjectName("errorPlot");
    m_errorPlot->setTitle(tr("Relative error vs Newton [A eq. 4.45]"));
    m_errorPlot->setAxes(tr("wall time [ms]"), tr("relative error"));
    m_errorPlot->setLogY(true);
    m_errorPlot->setLogX(true);
    pl->addWidget(m_errorPlot, 1);
    m_costPlot = new PlotWidget(this);
    m_costPlot->setObjectName("costPlot");
    m_costPlot->setTitle(tr("Physics cost per frame"));
    m_costPlot->setAxes(tr("frame"), tr("ms"));
    pl->addWidget(m_costPlot, 1);
}

Preview::Mode PreviewPanel::mode() const {
    return m_mode->currentIndex() == 1 ? Preview::Mode::Specimen : Preview::Mode::Scene;
}

void PreviewPanel::show(const Preview::Snapshot& s, double frameDt, bool newFrames) {
    // Only what changed is redrawn: an edit alone changes the verdict, not the cost, and a
    // repaint of a plot is what costs on the UI thread.
    if (newFrames) showCost(s, frameDt);
    QString verdict = s.verdict;
    if (!s.error.isEmpty()) verdict += (verdict.isEmpty() ? "" : "\n") + s.error;
    if (verdict != m_verdict->text()) {
        m_verdict->setText(verdict);
        m_verdict->setStyleSheet(s.verdictOk && s.error.isEmpty() ? "color: #106010" : "color: #b00020");
    }
    showAccuracy(s);
}

void PreviewPanel::showCost(const Preview::Snapshot& s, double dt) {
    PlotWidget::Series c{tr("physics ms"), {}, {}, QColor(40, 90, 200)};
    const double first = static_cast<double>(s.frames) - static_cast<double>(s.frameMs.size());
    for (size_t i = 0; i < s.frameMs.size(); ++i) {
        c.x.push_back(first + static_cast<double>(i));
        c.y.push_back(s.frameMs[i]);
    }
    // The frame's budget beside the cost, and what it says of real time.
    m_realTime = estimateRealTime(s.frameMs, dt);
    std::vector<PlotWidget::Series> series{c};
    if (dt > 0 && !c.x.empty())
        series.push_back({tr("%1 ms frame").arg(1e3 * dt, 0, 'f', 1),
                          {c.x.front(), c.x.back()},
                          {1e3 * dt, 1e3 * dt},
                          QColor(120, 120, 120)});
    m_costPlot->setSeries(std::move(series));
    QString note = tr("last %1 ms").arg(s.stepMs, 0, 'f', 1);
    if (m_realTime.frames > 0)
        note += tr(", mean %1 ms: ×%2 real time%3")
                    .arg(m_realTime.meanMs, 0, 'f', 1)
                    .arg(m_realTime.factor, 0, 'f', 2)
                    .arg(m_realTime.slower() ? tr(" — TOO SLOW") : QString());
    m_costPlot->setNote(note);
}

void PreviewPanel::showAccuracy(const Preview::Snapshot& s) {
    const int sampled = s.accuracy ? s.accuracy->frame : -1;
    if (!s.accuracy || sampled == m_shownSample) return;
    m_shownSample = sampled;
    std::vector<PlotWidget::Series> series{
        {tr("XPBD, current settings"), s.accuracy->timeMs, s.accuracy->relError, QColor(200, 60, 40)}};
    if (s.accuracyNewton)
        series.push_back(
            {tr("Newton (reference)"), s.accuracyNewton->timeMs, s.accuracyNewton->relError, QColor(40, 90, 200)});
    m_errorPlot->setSeries(std::move(series));
    m_errorPlot->setNote(tr("frame %1 of %2: %3 iterations of its first substep, one point each")
                             .arg(s.accuracy->frame)
                             .arg(s.accuracyOf)
                             .arg(s.accuracy->iterations.empty() ? 0 : s.accuracy->iterations.back()));
}

} // namespace viscera::studio
