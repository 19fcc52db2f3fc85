#pragma once
/// The "Preview and plots" panel: what the preview simulates (the scene or a uniaxial specimen of
/// the selected material), pause, the stability verdict, the live error against Newton and the
/// physics cost per frame against the frame's budget with the real-time factor it implies.
#include "app/preview.hpp"

#include <QWidget>

class QCheckBox;
class QComboBox;
class QLabel;

namespace viscera::studio {

class PlotWidget;

class PreviewPanel : public QWidget {
    Q_OBJECT
public:
    explicit PreviewPanel(Preview* preview, QWidget* parent = nullptr);

    /// The snapshot's verdict, cost and error into the plots. `frameDt`: the scene's frame (s);
    /// `newFrames`: the snapshot has frames not shown yet (the cost plot is redrawn).
    void show(const Preview::Snapshot& s, double frameDt, bool newFrames);
    Preview::Mode mode() const;

    QComboBox* modeBox() { return m_mode; }
    QLabel* verdictLabel() { return m_verdict; }
    PlotWidget* errorPlot() { return m_errorPlot; }
    PlotWidget* costPlot() { return m_costPlot; }
    const RealTimeEstimate& realTime() const { return m_realTime; }

signals:
    /// The artist chose what to preview.
    void modeChanged();

private:
    void showCost(const Preview::Snapshot& s, double frameDt);
    void showAccuracy(const Preview::Snapshot& s);

    Preview* m_preview;
    QComboBox* m_mode = nullptr;
    QLabel* m_verdict = nullptr;
    PlotWidget *m_errorPlot = nullptr, *m_costPlot = nullptr;
    RealTimeEstimate m_realTime; ///< of the preview's last frames (the cost plot's note, the export warning)
    int m_shownSample = -2;      ///< frame of the error sample on the plot
};

} // namespace viscera::studio
