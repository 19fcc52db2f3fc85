#include "line_plot.hpp"

#include <QColor>
#include <QFont>
#include <QGuiApplication>
#include <QImage>
#include <QPainter>
#include <QPainterPath>
#include <QPen>
#include <QString>

#include <algorithm>
#include <cmath>
#include <limits>

namespace viscera::bench {
namespace {

/// QPainter needs a QGuiApplication for fonts; the offscreen platform needs no display.
void ensureGuiApplication() {
    if (QGuiApplication::instance()) return;
    static char name[] = "viscera-plot", platform[] = "-platform", offscreen[] = "offscreen";
    static char* argv[] = {name, platform, offscreen, nullptr};
    static int argc = 3;
    static QGuiApplication app(argc, argv);
}

const QColor kPalette[] = {QColor(31, 119, 180),  QColor(255, 127, 14), QColor(44, 160, 44),   QColor(214, 39, 40),
                           QColor(148, 103, 189), QColor(140, 86, 75),  QColor(227, 119, 194), QColor(127, 127, 127),
                           QColor(188, 189, 34),  QColor(23, 190, 207)};

struct Axis {
    bool log = false;
    double lo = 0, hi = 1; // in transformed units (log10 for a log axis)

    bool accepts(double v) const { return std::isfinite(v) && (!log || v > 0); }
    double t(double v) const { return log ? std::log10(v) : v; }
};

/// Range of the plottable values, widened to whole decades (log) or padded (linear); a given
/// bound replaces the data's.
bool fitAxis(Axis& a, const std::vector<double>& values, std::optional<double> fixedMin,
             std::optional<double> fixedMax) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : values)
        if (a.accepts(v)) {
            lo = std::min(lo, a.t(v));
            hi = std::max(hi, a.t(v));
        }
    if (!(lo <= hi)) return false;
    if (a.log) {
        lo = std::floor(lo);
        hi = std::ceil(hi);
    } else {
        const double pad = hi > lo ? 0.03 * (hi - lo) : std::max(1.0, std::abs(lo)) * 0.5;
        lo -= pad;
        hi += pad;
    }
    if (fixedMin && a.accepts(*fixedMin)) lo = a.t(*fixedMin);
    if (fixedMax && a.accepts(*fixedMax)) hi = a.t(*fixedMax);
    if (!(hi > lo)) hi = lo + 1;
    a.lo = lo;
    a.hi = hi;
    return true;
}

/// Tick positions (in data units) and labels.
std::vector<std::pair<double, QString>> ticks(const Axis& a) {
    std::vector<std::pair<double, QString>> out;
    if (a.log) {
        const int first = static_cast<int>(std::ceil(a.lo - 1e-9)), last = static_cast<int>(std::floor(a.hi + 1e-9));
        const int step = std::max(1, (last - first + 11) / 12);
        for (int k = first; k <= last; k += step)
            out.emplace_back(std::pow(10.0, k), QString("1e%1").arg(k));
        return out;
    }
    const double raw = (a.hi - a.lo) / 8;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * mag >= raw) {
            step = m * mag;
            break;
        }
    for (double v = std::ceil(a.lo / step) * step; v <= a.hi + 1e-9 * step; v += step)
        out.emplace_back(std::abs(v) < 1e-12 * step ? 0.0 : v, QString::number(v, 'g', 5));
    return out;
}

} // namespace

std::string writeLinePlotPng(const std::string& path, const PlotSpec& spec, const std::vector<PlotSeries>& series) {
    ensureGuiApplication();
    Axis ax{spec.logX}, ay{spec.logY};
    std::vector<double> xs, ys(spec.yMarks);
    for (const PlotSeries& s : series)
        for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
            if (ax.accepts(s.x[i]) && ay.accepts(s.y[i])) {
                xs.push_back(s.x[i]);
                ys.push_back(s.y[i]);
            }
    if (xs.empty() || !fitAxis(ax, xs, spec.xMin, spec.xMax) || !fitAxis(ay, ys, spec.yMin, spec.yMax))
        return "no plottable point for " + path;

    QImage image(spec.width, spec.height, QImage::Format_ARGB32);
    image.fill(Qt::white);
    QPainter p(&image);
    p.setRenderHint(QPainter::Antialiasing);
    QFont font("DejaVu Sans");
    font.setPixelSize(std::max(12, spec.height / 55));
    p.setFont(font);
    double legendWidth = 0;
    for (const PlotSeries& s : series)
        legendWidth = std::max(legendWidth,
                               static_cast<double>(p.fontMetrics().horizontalAdvance(QString::fromStdString(s.label))));
    const double boxW = legendWidth + 60;
    const bool outside = spec.legend == LegendPlacement::OutsideRight;
    const double left = std::max(90.0, spec.width * 0.07);
    const double right = outside ? boxW + 30 : spec.width * 0.03;
    const QRectF plot(left, spec.height * 0.08, spec.width - left - right, spec.height * 0.80);
    auto px = [&](double x) { return plot.left() + (ax.t(x) - ax.lo) / (ax.hi - ax.lo) * plot.width(); };
    auto py = [&](double y) { return plot.bottom() - (ay.t(y) - ay.lo) / (ay.hi - ay.lo) * plot.height(); };

    // Grid, ticks and labels.
    const QPen gridPen(QColor(225, 225, 225), 1), axisPen(Qt::black, 1.5);
    const double fh = font.pixelSize();
    for (const auto& [v, label] : ticks(ax)) {
        const double x = px(v);
        p.setPen(gridPen);
        p.drawLine(QPointF(x, plot.top()), QPointF(x, plot.bottom()));
        p.setPen(Qt::black);
        p.drawText(QRectF(x - 60, plot.bottom() + 4, 120, fh * 1.5), Qt::AlignHCenter | Qt::AlignTop, label);
    }
    for (const auto& [v, label] : ticks(ay)) {
        const double y = py(v);
        p.setPen(gridPen);
        p.drawLine(QPointF(plot.left(), y), QPointF(plot.right(), y));
        p.setPen(Qt::black);
        p.drawText(QRectF(0, y - fh, plot.left() - 8, 2 * fh), Qt::AlignRight | Qt::AlignVCenter, label);
    }
    p.setPen(axisPen);
    p.drawRect(plot);
    p.drawText(QRectF(plot.left(), plot.bottom() + fh * 1.8, plot.width(), fh * 1.6), Qt::AlignHCenter,
               QString::fromStdString(spec.xLabel));
    p.save();
    p.translate(fh * 0.4, plot.center().y());
    p.rotate(-90);
    p.drawText(QRectF(-plot.height() / 2, 0, plot.height(), fh * 1.6), Qt::AlignHCenter | Qt::AlignTop,
               QString::fromStdString(spec.yLabel));
    p.restore();
    QFont titleFont = font;
    titleFont.setPixelSize(static_cast<int>(fh * 1.3));
    titleFont.setBold(true);
    p.setFont(titleFont);
    p.drawText(QRectF(0, 0, spec.width, plot.top()), Qt::AlignCenter, QString::fromStdString(spec.title));
    p.setFont(font);

    p.setClipRect(plot);
    for (double m : spec.yMarks) {
        if (!ay.accepts(m)) continue;
        p.setPen(QPen(QColor(90, 90, 90), 1.5, Qt::DashLine));
        p.drawLine(QPointF(plot.left(), py(m)), QPointF(plot.right(), py(m)));
        p.drawText(QPointF(plot.left() + 6, py(m) - 4), QString::number(m, 'g', 3));
    }
    for (size_t s = 0; s < series.size(); ++s) {
        const PlotSeries& ser = series[s];
        const QColor color = kPalette[s % std::size(kPalette)];
        QPainterPath path;
        bool open = false;
        for (size_t i = 0; i < std::min(ser.x.size(), ser.y.size()); ++i) {
            if (!ax.accepts(ser.x[i]) || !ay.accepts(ser.y[i])) {
                open = false; // a gap where the axis cannot show the point
                continue;
            }
            const QPointF q(px(ser.x[i]), py(ser.y[i]));
            if (open) {
                path.lineTo(q);
            } else {
                path.moveTo(q);
                open = true;
            }
        }
        p.setPen(QPen(color, 2.2));
        p.setBrush(Qt::NoBrush);
        p.drawPath(path);
        if (ser.markers) {
            p.setBrush(color);
            for (size_t i = 0; i < std::min(ser.x.size(), ser.y.size()); ++i)
                if (ax.accepts(ser.x[i]) && ay.accepts(ser.y[i]))
                    p.drawEllipse(QPointF(px(ser.x[i]), py(ser.y[i])), 4, 4);
        }
    }
    p.setClipping(false);

    // Legend: right of the plot, or in a corner inside it.
    const double rowH = fh * 1.5, boxH = rowH * series.size() + fh * 0.6;
    const bool atLeft = spec.legend == LegendPlacement::TopLeft || spec.legend == LegendPlacement::BottomLeft;
    const bool atTop = outside || spec.legend == LegendPlacement::TopLeft || spec.legend == LegendPlacement::TopRight;
    const double boxX = outside ? plot.right() + 20 : atLeft ? plot.left() + 10 : plot.right() - boxW - 10;
    const QRectF box(boxX, atTop ? plot.top() + (outside ? 0 : 10) : plot.bottom() - boxH - 10, boxW, boxH);
    p.setPen(QPen(QColor(160, 160, 160), 1));
    p.setBrush(QColor(255, 255, 255, 230));
    p.drawRect(box);
    for (size_t s = 0; s < series.size(); ++s) {
        const double y = box.top() + fh * 0.3 + rowH * (s + 0.5);
        p.setPen(QPen(kPalette[s % std::size(kPalette)], 3));
        p.drawLine(QPointF(box.left() + 8, y), QPointF(box.left() + 40, y));
        p.setPen(Qt::black);
        p.drawText(QRectF(box.left() + 48, y - rowH / 2, legendWidth + 10, rowH), Qt::AlignLeft | Qt::AlignVCenter,
                   QString::fromStdString(series[s].label));
    }
    p.end();
    if (!image.save(QString::fromStdString(path), "PNG")) return "cannot write " + path;
    return {};
}

} // namespace viscera::bench
