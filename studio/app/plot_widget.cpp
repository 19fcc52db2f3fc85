#include "app/plot_widget.hpp"

#include "app/number_text.hpp"

#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>

namespace viscera::studio {
namespace {

double niceStep(double range) {
    if (!(range > 0) || !std::isfinite(range)) return 1.0;
    const double raw = range / 5.0;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / mag;
    return mag * (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0);
}

} // namespace

PlotWidget::PlotWidget(QWidget* parent) : QWidget(parent) {
    setMinimumSize(220, 110);
}

void PlotWidget::setSeries(std::vector<Series> series) {
    m_series = std::move(series);
    update();
}

void PlotWidget::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    p.fillRect(rect(), palette().base());
    const int top = m_note.isEmpty() ? 22 : 36;
    const QRectF a(60, top, std::max(10, width() - 72), std::max(10, height() - top - 34));
    auto ty = [&](double y) { return m_logY ? std::log10(y) : y; }; // ≤ 0 on a log axis: NaN, skipped
    auto tx = [&](double x) { return m_logX ? std::log10(x) : x; };
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (const Series& s : m_series)
        for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
            const double x = tx(s.x[i]), y = ty(s.y[i]);
            if (!std::isfinite(x) || !std::isfinite(y)) continue;
            x0 = std::min(x0, x);
            x1 = std::max(x1, x);
            y0 = std::min(y0, y);
            y1 = std::max(y1, y);
        }
    p.setPen(palette().text().color());
    p.setFont(QFont(font().family(), 9, QFont::Bold));
    p.drawText(QRectF(a.left(), 2, a.width(), 18), Qt::AlignLeft | Qt::AlignVCenter, m_title);
    p.setFont(QFont(font().family(), 8));
    if (!m_note.isEmpty()) p.drawText(QRectF(a.left(), 18, a.width(), 16), Qt::AlignLeft | Qt::AlignVCenter, m_note);
    p.drawRect(a);
    p.drawText(QRectF(a.left(), a.bottom() + 16, a.width(), 16), Qt::AlignHCenter, m_xLabel);
    p.save();
    p.translate(10, a.center().y());
    p.rotate(-90);
    p.drawText(QRectF(-a.height() / 2, -8, a.height(), 16), Qt::AlignHCenter, m_yLabel);
    p.restore();
    if (!(x1 >= x0) || !(y1 >= y0)) {
        p.drawText(a, Qt::AlignCenter, tr("no data yet"));
        return;
    }
    if (x1 == x0) x0 -= 0.5, x1 += 0.5;
    if (y1 == y0) y0 -= 0.5, y1 += 0.5;
    const double my = 0.05 * (y1 - y0);
    y0 -= my;
    y1 += my;
    auto map = [&](double x, double y) {
        return QPointF(a.left() + (tx(x) - x0) / (x1 - x0) * a.width(),
                       a.bottom() - (ty(y) - y0) / (y1 - y0) * a.height());
    };
    QPen grid(palette().mid().color(), 0, Qt::DotLine);
    const double sx = m_logX ? 1.0 : niceStep(x1 - x0);
    for (double gx = std::ceil(x0 / sx) * sx; gx <= x1 + 1e-12 * sx; gx += sx) {
        const double px = a.left() + (gx - x0) / (x1 - x0) * a.width();
        p.setPen(grid);
        p.drawLine(QPointF(px, a.top()), QPointF(px, a.bottom()));
        p.setPen(palette().text().color());
        p.drawText(QRectF(px - 30, a.bottom() + 2, 60, 14), Qt::AlignHCenter,
                   m_logX ? QStringLiteral("1e%1").arg(static_cast<int>(std::lround(gx)))
                          : numberText(std::abs(gx) < 1e-9 * sx ? 0 : gx));
    }
    const double sy = m_logY ? 1.0 : niceStep(y1 - y0);
    for (double gy = std::ceil(y0 / sy) * sy; gy <= y1; gy += sy) {
        const double py = a.bottom() - (gy - y0) / (y1 - y0) * a.height();
        p.setPen(grid);
        p.drawLine(QPointF(a.left(), py), QPointF(a.right(), py));
        p.setPen(palette().text().color());
        const QString t = m_logY ? QStringLiteral("1e%1").arg(static_cast<int>(std::lround(gy)))
                                 : numberText(std::abs(gy) < 1e-9 * sy ? 0 : gy);
        p.drawText(QRectF(0, py - 7, a.left() - 4, 14), Qt::AlignRight | Qt::AlignVCenter, t);
    }
    p.setClipRect(a);
    int legend = 0;
    for (const Series& s : m_series) {
        p.setPen(QPen(s.color, s.points ? 1.2 : 2));
        if (s.points) {
            p.setBrush(Qt::NoBrush);
            for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
                if (std::isfinite(tx(s.x[i])) && std::isfinite(ty(s.y[i]))) p.drawEllipse(map(s.x[i], s.y[i]), 3, 3);
        } else {
            QPainterPath path;
            bool open = false;
            for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
                if (!std::isfinite(tx(s.x[i])) || !std::isfinite(ty(s.y[i]))) {
                    open = false;
                    continue;
                }
                const QPointF q = map(s.x[i], s.y[i]);
                open ? path.lineTo(q) : path.moveTo(q);
                open = true;
            }
            p.setBrush(Qt::NoBrush);
            p.drawPath(path);
        }
        if (!s.name.isEmpty()) {
            p.drawText(QRectF(a.right() - 180, a.top() + 4 + 14 * legend, 174, 14), Qt::AlignRight, s.name);
            ++legend;
        }
    }
}

} // namespace viscera::studio
