#include "app/curve_editor.hpp"

#include "app/number_text.hpp"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <limits>

namespace viscera::studio {
namespace {

/// Smallest gap kept between neighbouring control values (relative to their magnitude), so that
/// a strictly increasing list stays strictly increasing in floating point.
double gap(double neighbour) {
    return 1e-6 * std::max(std::abs(neighbour), 1e-3);
}

} // namespace

CurveEditor::CurveEditor(QWidget* parent) : QWidget(parent) {
    setFocusPolicy(Qt::StrongFocus);
    setMouseTracking(false);
    setMinimumSize(240, 110);
    setAutoFillBackground(false);
}

void CurveEditor::setCurve(const QString& name, const std::vector<sim::CurvePoint>& points, bool strictlyIncreasing,
                           bool frame) {
    const bool sameCount = points.size() == m_points.size() && name == m_name;
    const bool same =
        sameCount && strictlyIncreasing == m_strict && m_message.isEmpty() && m_curve &&
        std::equal(points.begin(), points.end(), m_points.begin(),
                   [](const sim::CurvePoint& a, const sim::CurvePoint& b) { return a.x == b.x && a.y == b.y; });
    if (same && !frame) return; // an edit of another curve: nothing to redraw
    m_name = name;
    m_message.clear();
    m_points = points;
    m_strict = strictlyIncreasing;
    m_curve.reset();
    try {
        m_curve.emplace(name.toStdString(), points,
                        strictlyIncreasing ? sim::CurveShape::StrictlyIncreasing : sim::CurveShape::Unconstrained);
    } catch (const std::exception& e) {
        m_message = QString::fromStdString(e.what());
    }
    if (!sameCount) {
        m_selected = -1;
        m_dragging = -1;
    }
    // the view frames itself after a preset, a fit or a curve-wide edit that left points out of
    // sight (not during a drag: the curve must not move under the mouse)
    if (frame || !sameCount || (m_dragging < 0 && !inView())) frameAll();
    update();
}

bool CurveEditor::inView() const {
    for (const sim::CurvePoint& p : m_points)
        if (!m_view.contains(QPointF(p.x, p.y))) return false;
    return true;
}

void CurveEditor::clearCurve(const QString& name, const QString& message) {
    if (name == m_name && message == m_message && m_points.empty() && !m_curve) return;
    m_name = name;
    m_message = message;
    m_points.clear();
    m_curve.reset();
    m_selected = m_dragging = -1;
    update();
}

void CurveEditor::setSelected(int index) {
    if (index < -1 || index >= static_cast<int>(m_points.size())) index = -1;
    if (index == m_selected) return;
    m_selected = index;
    emit selectionChanged(index);
    update();
}

bool CurveEditor::removable(int index) const {
    const int n = static_cast<int>(m_points.size());
    return index > 0 && index < n - 1 && !isRestPoint(m_points[index]) && n > 3;
}

QPointF CurveEditor::constrain(int index, QPointF want) const {
    const int n = static_cast<int>(m_points.size());
    if (index < 0 || index >= n) return want;
    const sim::CurvePoint& p = m_points[index];
    if (isRestPoint(p)) return {p.x, p.y};
    double x = want.x(), y = want.y();
    if (!std::isfinite(x)) x = p.x;
    if (!std::isfinite(y)) y = p.y;
    x = std::max(x, 0.01); // stretches and volume ratios are positive
    if (index > 0) x = std::max(x, m_points[index - 1].x + gap(m_points[index - 1].x));
    if (index < n - 1) x = std::min(x, m_points[index + 1].x - gap(m_points[index + 1].x));
    // the neighbours' own gap may leave no room: keep the point where it is
    if ((index > 0 && !(x > m_points[index - 1].x)) || (index < n - 1 && !(x < m_points[index + 1].x))) x = p.x;
    if (m_strict) {
        if (index > 0) y = std::max(y, m_points[index - 1].y + gap(m_points[index - 1].y));
        if (index < n - 1) y = std::min(y, m_points[index + 1].y - gap(m_points[index + 1].y));
        if ((index > 0 && !(y > m_points[index - 1].y)) || (index < n - 1 && !(y < m_points[index + 1].y))) y = p.y;
    }
    return {x, y};
}

namespace {

/// Pushes the values of `v` after `from` up and those before it down so that v stays strictly
/// increasing by at least gap() between neighbours (v[from] is where it must be).
void pushApart(std::vector<double>& v, size_t from) {
    for (size_t m = from + 1; m < v.size(); ++m)
        v[m] = std::max(v[m], v[m - 1] + gap(v[m - 1]));
    for (size_t m = from; m-- > 0;)
        v[m] = std::min(v[m], v[m + 1] - gap(v[m + 1]));
}

/// The bounds [lo, hi] of coordinate c of point i when the pinned points (and, below, `floor`)
/// stay: room for the points between, each a gap apart.
std::pair<double, double> pushBounds(const std::vector<double>& c, const std::vector<bool>& pinned, size_t i,
                                     double floor) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    double lo = floor, hi = inf;
    size_t from = 0; // the points from `from` to i - 1 must fit above lo
    for (size_t j = i; j-- > 0;)
        if (pinned[j]) {
            lo = c[j];
            from = j;
            break;
        }
    if (std::isfinite(lo))
        for (size_t m = from; m < i; ++m)
            lo += 2 * gap(lo);
    for (size_t j = i + 1; j < c.size(); ++j)
        if (pinned[j]) {
            hi = c[j];
            for (size_t m = i; m < j; ++m)
                hi -= 2 * gap(hi);
            break;
        }
    return {lo, hi};
}

} // namespace

std::vector<sim::CurvePoint> CurveEditor::dragged(const std::vector<sim::CurvePoint>& base, int index, QPointF want,
                                                  bool strictlyIncreasing) {
    std::vector<sim::CurvePoint> out = base;
    const int n = static_cast<int>(base.size());
    if (index < 0 || index >= n || isRestPoint(base[index])) return out;
    std::vector<bool> pinned(base.size());
    std::vector<double> xs(base.size()), ys(base.size());
    for (size_t k = 0; k < base.size(); ++k) {
        pinned[k] = isRestPoint(base[k]);
        xs[k] = base[k].x;
        ys[k] = base[k].y;
    }
    const auto i = static_cast<size_t>(index);
    auto place = [&](std::vector<double>& c, double w, double floor) {
        if (!std::isfinite(w)) return;
        const auto [lo, hi] = pushBounds(c, pinned, i, floor);
        if (!(lo < hi)) return; // no room at all: the point stays
        c[i] = std::clamp(w, lo, hi);
        pushApart(c, i);
    };
    place(xs, std::max(want.x(), 0.01), 0.01);
    if (strictlyIncreasing)
        place(ys, want.y(), -std::numeric_limits<double>::infinity());
    else if (std::isfinite(want.y()))
        ys[i] = want.y();
    for (size_t k = 0; k < base.size(); ++k)
        out[k] = {xs[k], ys[k]};
    return out;
}

QRectF CurveEditor::plotArea() const {
    return QRectF(56, 22, std::max(10, width() - 66), std::max(10, height() - 48));
}

QPointF CurveEditor::toWidget(QPointF d) const {
    const QRectF a = plotArea();
    return {a.left() + (d.x() - m_view.left()) / m_view.width() * a.width(),
            a.bottom() - (d.y() - m_view.top()) / m_view.height() * a.height()};
}

QPointF CurveEditor::toData(QPointF w) const {
    const QRectF a = plotArea();
    return {m_view.left() + (w.x() - a.left()) / a.width() * m_view.width(),
            m_view.top() + (a.bottom() - w.y()) / a.height() * m_view.height()};
}

double CurveEditor::niceStep(double range) {
    if (!(range > 0) || !std::isfinite(range)) return 1.0;
    const double raw = range / 6.0;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / mag;
    return mag * (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0);
}

double CurveEditor::gridStepX() const {
    return niceStep(m_view.width());
}
double CurveEditor::gridStepY() const {
    return niceStep(m_view.height());
}

double CurveEditor::curveValue(double x) const {
    return m_curve ? m_curve->value(x) : std::numeric_limits<double>::quiet_NaN();
}

void CurveEditor::frameAll() {
    if (m_points.empty()) {
        m_view = QRectF(0.0, -1.0, 3.0, 2.0);
        update();
        return;
    }
    double x0 = m_points.front().x, x1 = m_points.back().x;
    double y0 = m_points.front().y, y1 = y0;
    for (const auto& p : m_points) {
        y0 = std::min(y0, p.y);
        y1 = std::max(y1, p.y);
    }
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) {
        y0 -= std::max(1.0, std::abs(y0) * 0.5);
        y1 += std::max(1.0, std::abs(y1) * 0.5);
    }
    const double mx = 0.06 * (x1 - x0), my = 0.08 * (y1 - y0);
    m_view = QRectF(x0 - mx, y0 - my, (x1 - x0) + 2 * mx, (y1 - y0) + 2 * my);
    update();
}

int CurveEditor::pointAt(QPointF w) const {
    int best = -1;
    double bestD = kPickPixels;
    for (int i = 0; i < static_cast<int>(m_points.size()); ++i) {
        const QPointF q = toWidget({m_points[i].x, m_points[i].y});
        const double d = std::hypot(q.x() - w.x(), q.y() - w.y());
        if (d <= bestD) {
            bestD = d;
            best = i;
        }
    }
    return best;
}

void CurveEditor::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    p.fillRect(rect(), palette().base());
    const QRectF a = plotArea();
    // grid and labels
    const double sx = gridStepX(), sy = gridStepY();
    QPen grid(palette().mid().color(), 0, Qt::DotLine);
    p.setFont(QFont(font().family(), 8));
    for (double gx = std::ceil(m_view.left() / sx) * sx; gx <= m_view.right(); gx += sx) {
        const double px = toWidget({gx, 0}).x();
        p.setPen(grid);
        p.drawLine(QPointF(px, a.top()), QPointF(px, a.bottom()));
        p.setPen(palette().text().color());
        p.drawText(QRectF(px - 30, a.bottom() + 2, 60, 14), Qt::AlignHCenter,
                   numberText(std::abs(gx) < 1e-12 * sx ? 0 : gx));
    }
    for (double gy = std::ceil(m_view.top() / sy) * sy; gy <= m_view.bottom(); gy += sy) {
        const double py = toWidget({0, gy}).y();
        p.setPen(grid);
        p.drawLine(QPointF(a.left(), py), QPointF(a.right(), py));
        p.setPen(palette().text().color());
        p.drawText(QRectF(0, py - 7, a.left() - 4, 14), Qt::AlignRight | Qt::AlignVCenter,
                   numberText(std::abs(gy) < 1e-12 * sy ? 0 : gy));
    }
    p.setPen(QPen(palette().text().color(), 1));
    p.drawRect(a);
    // rest line x = 1 and y = 0
    p.setPen(QPen(QColor(150, 150, 150), 1, Qt::DashLine));
    if (m_view.left() < 1 && m_view.right() > 1)
        p.drawLine(QPointF(toWidget({1, 0}).x(), a.top()), QPointF(toWidget({1, 0}).x(), a.bottom()));
    if (m_view.top() < 0 && m_view.bottom() > 0)
        p.drawLine(QPointF(a.left(), toWidget({0, 0}).y()), QPointF(a.right(), toWidget({0, 0}).y()));
    p.setPen(palette().text().color());
    p.drawText(QRectF(a.left(), 2, a.width(), 18), Qt::AlignLeft | Qt::AlignVCenter,
               m_name + (m_strict ? tr("  (strictly increasing)") : tr("  (any shape)")) + tr("  [Pa]"));
    if (!m_message.isEmpty()) {
        p.drawText(a.adjusted(8, 8, -8, -8), Qt::AlignCenter | Qt::TextWordWrap, m_message);
        if (m_points.empty()) return;
    }
    p.setClipRect(a);
    if (m_curve) {
        QPainterPath path;
        const int steps = std::max(64, static_cast<int>(a.width()));
        for (int k = 0; k <= steps; ++k) {
            const double x = m_view.left() + m_view.width() * k / steps;
            const double y = m_curve->value(x);
            if (!std::isfinite(y)) continue;
            QPointF q = toWidget({x, y});
            q.setY(std::clamp(q.y(), -1e5, 1e5));
            k == 0 ? path.moveTo(q) : path.lineTo(q);
        }
        p.setPen(QPen(QColor(200, 60, 40), 2));
        p.drawPath(path);
    }
    for (int i = 0; i < static_cast<int>(m_points.size()); ++i) {
        const QPointF q = toWidget({m_points[i].x, m_points[i].y});
        const bool rest = isRestPoint(m_points[i]);
        p.setPen(QPen(i == m_selected ? QColor(20, 90, 220) : QColor(40, 40, 40), i == m_selected ? 2.5 : 1.2));
        p.setBrush(rest ? QColor(250, 200, 60) : (i == m_selected ? QColor(120, 170, 255) : QColor(255, 255, 255)));
        if (rest) {
            QPolygonF d;
            d << q + QPointF(0, -6) << q + QPointF(6, 0) << q + QPointF(0, 6) << q + QPointF(-6, 0);
            p.drawPolygon(d);
        } else {
            p.drawEllipse(q, 4.5, 4.5);
        }
    }
}

void CurveEditor::mousePressEvent(QMouseEvent* e) {
    setFocus(Qt::MouseFocusReason);
    if (e->button() == Qt::MiddleButton) {
        m_panning = true;
        m_panStart = e->position();
        m_panView = m_view;
        return;
    }
    if (e->button() != Qt::LeftButton || m_points.empty()) return;
    const int hit = pointAt(e->position());
    if (hit >= 0) {
        setSelected(hit);
        if (!isRestPoint(m_points[hit])) {
            m_dragging = hit;
            m_dragBase = m_points;
            emit dragStarted(hit);
        }
        return;
    }
    const QPointF d = toData(e->position());
    const double y = curveValue(d.x());
    if (std::isfinite(y) && std::abs(toWidget({d.x(), y}).y() - e->position().y()) <= kPickPixels &&
        d.x() > m_points.front().x && d.x() < m_points.back().x) {
        emit insertRequested(d.x(), y);
        return;
    }
    setSelected(-1);
}

void CurveEditor::mouseMoveEvent(QMouseEvent* e) {
    if (m_panning) {
        const QRectF a = plotArea();
        const QPointF dp = e->position() - m_panStart;
        m_view = m_panView.translated(-dp.x() / a.width() * m_view.width(), dp.y() / a.height() * m_view.height());
        update();
        return;
    }
    if (m_dragging < 0) return;
    QPointF d = toData(e->position());
    if (e->modifiers() & Qt::ControlModifier) {
        const double sx = gridStepX(), sy = gridStepY();
        d = QPointF(std::round(d.x() / sx) * sx, std::round(d.y() / sy) * sy);
    }
    if (m_dragBase.size() != m_points.size()) m_dragBase = m_points; // the curve changed under the drag
    emit curveDragged(m_dragging, dragged(m_dragBase, m_dragging, d, m_strict));
}

void CurveEditor::mouseReleaseEvent(QMouseEvent* e) {
    if (e->button() == Qt::MiddleButton) {
        m_panning = false;
        return;
    }
    if (e->button() == Qt::LeftButton && m_dragging >= 0) {
        const int i = m_dragging;
        m_dragging = -1;
        m_dragBase.clear();
        emit dragFinished(i);
        if (!inView()) frameAll(); // a drag may leave points out of sight: shown again at its end
    }
}

void CurveEditor::wheelEvent(QWheelEvent* e) {
    const double steps = e->angleDelta().y() / 120.0;
    if (steps == 0) return;
    const double f = std::pow(1.25, -steps);
    const QPointF c = toData(e->position());
    m_view = QRectF(c.x() - (c.x() - m_view.left()) * f, c.y() - (c.y() - m_view.top()) * f, m_view.width() * f,
                    m_view.height() * f);
    update();
    e->accept();
}

void CurveEditor::keyPressEvent(QKeyEvent* e) {
    if (e->key() == Qt::Key_Home) {
        frameAll();
        return;
    }
    if ((e->key() == Qt::Key_Delete || e->key() == Qt::Key_Backspace) && m_selected >= 0) {
        if (removable(m_selected)) emit removeRequested(m_selected);
        return;
    }
    QWidget::keyPressEvent(e);
}

void CurveEditor::resizeEvent(QResizeEvent*) {
    update();
}

} // namespace viscera::studio
