#pragma once
/// A small x–y plot drawn with QPainter: titled axes, lines and point series, linear or
/// logarithmic y. Used for the material response, the fit, the live error against wall time
/// and the cost per frame. Non-finite samples are skipped, never drawn.
#include <QColor>
#include <QString>
#include <QWidget>

#include <vector>

namespace viscera::studio {

class PlotWidget : public QWidget {
    Q_OBJECT
public:
    struct Series {
        QString name;
        std::vector<double> x, y;
        QColor color = QColor(200, 60, 40);
        bool points = false; ///< markers instead of a line
    };

    explicit PlotWidget(QWidget* parent = nullptr);
    /// 220 × 150 wanted; 220 × 110 at least (the main window fits a 1920 × 1080 screen).
    QSize sizeHint() const override { return {220, 150}; }
    void setTitle(const QString& title) {
        m_title = title;
        update();
    }
    void setAxes(const QString& x, const QString& y) {
        m_xLabel = x;
        m_yLabel = y;
        update();
    }
    void setLogY(bool on) {
        m_logY = on;
        update();
    }
    void setLogX(bool on) {
        m_logX = on;
        update();
    }
    void setSeries(std::vector<Series> series);
    const std::vector<Series>& series() const { return m_series; }
    /// A line of text under the title (figures such as SSE and R²).
    void setNote(const QString& note) {
        m_note = note;
        update();
    }
    const QString& note() const { return m_note; }

protected:
    void paintEvent(QPaintEvent*) override;

private:
    QString m_title, m_xLabel, m_yLabel, m_note;
    bool m_logX = false, m_logY = false;
    std::vector<Series> m_series;
};

} // namespace viscera::studio
