#include "results/progress_page.hpp"

#include "plots/html_text.hpp"
#include "plots/offscreen_gui.hpp"

#include "sim/util/atomic_file.hpp"

#include <QBuffer>
#include <QByteArray>
#include <QFont>
#include <QFontMetricsF>
#include <QImage>
#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

namespace viscera::player {

namespace {

const QColor kInk(40, 40, 48), kGrid(225, 227, 232), kLine(31, 119, 180), kPass(44, 160, 44), kFail(214, 39, 40);
const QColor kBand(kExpertBandRgb[0], kExpertBandRgb[1], kExpertBandRgb[2]), kBound(30, 110, 60),
    kProficient(148, 103, 189);
constexpr int kW = 960, kH = 440;

double niceStep(double span, int target) {
    const double raw = span / std::max(target, 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / mag;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

/// One metric over the attempts.
struct Series {
    std::string name, unit;
    bool lowerIsBetter = true;
    struct Point {
        int attempt = 0;
        std::optional<double> value;
        bool passed = false;
        std::optional<ExpertLevel> expert;
    };
    std::vector<Point> points;
};

Series seriesOf(const LearningCurve& c, const std::string& metric) {
    Series s;
    s.name = metric;
    for (const Attempt& a : c.attempts)
        for (const MetricRecord& m : a.session->metrics)
            if (m.name == metric) {
                s.unit = m.unit;
                s.lowerIsBetter = m.lowerIsBetter;
                s.points.push_back({a.number, m.value, a.session->passed, m.expert});
            }
    return s;
}

struct Frame {
    QRectF area;
    double x0, x1, y0, y1;
    QPointF map(double x, double y) const {
        return {area.left() + (x - x0) / (x1 - x0) * area.width(),
                area.bottom() - (y - y0) / (y1 - y0) * area.height()};
    }
};

Frame frameFor(const Series& s, int attempts) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto add = [&](double v) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    };
    for (const auto& p : s.points) {
        if (p.value) add(*p.value);
        if (p.expert) {
            add(p.expert->mean - p.expert->sd);
            add(p.expert->mean + p.expert->sd);
            add(p.expert->bound);
        }
    }
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) lo -= 0.5, hi += 0.5;
    const double pad = 0.08 * (hi - lo);
    return {QRectF(84, 44, kW - 84 - 24, kH - 44 - 56), 0.5, attempts + 0.5, lo - pad, hi + pad};
}

void drawAxes(QPainter& p, const Frame& f, const Series& s, int attempts) {
    const QFontMetricsF fm(p.font());
    p.fillRect(f.area, QColor(250, 250, 252));
    const int xs = std::max(1, static_cast<int>(niceStep(attempts, 12)));
    for (int a = 1; a <= attempts; a += (a == 1 && xs > 1 ? xs - 1 : xs)) {
        const double px = f.map(a, 0).x();
        p.setPen(QPen(kGrid, 1));
        p.drawLine(QPointF(px, f.area.top()), QPointF(px, f.area.bottom()));
        p.setPen(kInk);
        const QString t = QString::number(a);
        p.drawText(QPointF(px - fm.horizontalAdvance(t) / 2, f.area.bottom() + fm.ascent() + 4), t);
    }
    const double ys = niceStep(f.y1 - f.y0, 6);
    for (double y = std::ceil(f.y0 / ys) * ys; y <= f.y1; y += ys) {
        const double py = f.map(0, y).y();
        p.setPen(QPen(kGrid, 1));
        p.drawLine(QPointF(f.area.left(), py), QPointF(f.area.right(), py));
        p.setPen(kInk);
        const QString t = QString::number(std::abs(y) < 1e-12 * ys ? 0.0 : y, 'g', 5);
        p.drawText(QPointF(f.area.left() - fm.horizontalAdvance(t) - 6, py + fm.ascent() / 2 - 1), t);
    }
    QFont bold = p.font();
    bold.setBold(true);
    p.save();
    p.setFont(bold);
    p.drawText(QPointF(f.area.left(), 26),
               QString::fromStdString(s.name + " (" + (s.lowerIsBetter ? "lower" : "higher") + " is better)"));
    p.restore();
    const QString xl = "attempt";
    p.drawText(QPointF(f.area.center().x() - fm.horizontalAdvance(xl) / 2, kH - 12), xl);
    const QString yl = QString::fromStdString(s.name + (s.unit.empty() ? "" : " (" + s.unit + ")"));
    p.save();
    p.translate(18, f.area.center().y() + fm.horizontalAdvance(yl) / 2);
    p.rotate(-90);
    p.drawText(QPointF(0, 0), yl);
    p.restore();
}

/// The band (mean ± sd) and the bound, one attempt wide each: the level may change with the case.
void drawExpert(QPainter& p, const Frame& f, const Series& s) {
    p.save();
    p.setClipRect(f.area);
    for (const auto& pt : s.points) {
        if (!pt.expert) continue;
        const ExpertLevel& e = *pt.expert;
        p.fillRect(QRectF(f.map(pt.attempt - 0.5, e.mean + e.sd), f.map(pt.attempt + 0.5, e.mean - e.sd)), kBand);
        p.setPen(QPen(QColor(120, 175, 135), 1));
        p.drawLine(f.map(pt.attempt - 0.5, e.mean), f.map(pt.attempt + 0.5, e.mean));
        p.setPen(QPen(kBound, 2, Qt::DashLine));
        p.drawLine(f.map(pt.attempt - 0.5, e.bound), f.map(pt.attempt + 0.5, e.bound));
    }
    p.restore();
}

void drawValues(QPainter& p, const Frame& f, const Series& s) {
    p.save();
    p.setClipRect(f.area);
    p.setRenderHint(QPainter::Antialiasing);
    QPainterPath path;
    bool open = false;
    for (const auto& pt : s.points) {
        if (!pt.value) {
            open = false;
            continue;
        }
        const QPointF q = f.map(pt.attempt, *pt.value);
        open ? path.lineTo(q) : path.moveTo(q);
        open = true;
    }
    p.setPen(QPen(kLine, 2));
    p.drawPath(path);
    for (const auto& pt : s.points) {
        if (!pt.value) continue;
        const QPointF q = f.map(pt.attempt, *pt.value);
        if (pt.passed) {
            p.setPen(QPen(kPass.darker(130), 1.5));
            p.setBrush(kPass);
            p.drawEllipse(q, 5.5, 5.5);
        } else {
            p.setPen(QPen(kFail, 2.6));
            p.drawLine(q + QPointF(-5, -5), q + QPointF(5, 5));
            p.drawLine(q + QPointF(-5, 5), q + QPointF(5, -5));
        }
    }
    p.restore();
}

void drawLegend(QPainter& p, const std::optional<int>& proficientAt) {
    const QFontMetricsF fm(p.font());
    double x = kW - 24;
    const double y = 26;
    auto item = [&](const QString& label, auto&& glyph) {
        x -= fm.horizontalAdvance(label);
        p.setPen(kInk);
        p.drawText(QPointF(x, y), label);
        glyph(QPointF(x - 14, y - fm.ascent() / 2 + 1));
        x -= 34;
    };
    item("failed", [&](QPointF c) {
        p.setPen(QPen(kFail, 2.4));
        p.drawLine(c + QPointF(-4, -4), c + QPointF(4, 4));
        p.drawLine(c + QPointF(-4, 4), c + QPointF(4, -4));
    });
    item("passed", [&](QPointF c) {
        p.setPen(Qt::NoPen);
        p.setBrush(kPass);
        p.drawEllipse(c, 5, 5);
    });
    item("bound (mean ± 2 sd)", [&](QPointF c) {
        p.setPen(QPen(kBound, 2, Qt::DashLine));
        p.drawLine(c - QPointF(9, 0), c + QPointF(9, 0));
    });
    item("expert mean ± sd", [&](QPointF c) { p.fillRect(QRectF(c - QPointF(9, 6), c + QPointF(9, 6)), kBand); });
    if (proficientAt)
        item("proficient", [&](QPointF c) {
            p.setPen(QPen(kProficient, 2, Qt::DotLine));
            p.drawLine(c - QPointF(0, 7), c + QPointF(0, 7));
        });
}

QByteArray curvePng(const LearningCurve& c, const Series& s) {
    QImage image(kW, kH, QImage::Format_RGB32);
    image.fill(Qt::white);
    {
        QPainter p(&image);
        QFont font("DejaVu Sans");
        font.setPixelSize(13);
        p.setFont(font);
        p.setRenderHint(QPainter::TextAntialiasing);
        const int n = c.attempts.empty() ? 1 : c.attempts.back().number;
        const Frame f = frameFor(s, n);
        drawAxes(p, f, s, n);
        drawExpert(p, f, s);
        if (c.proficientAt) {
            p.setPen(QPen(kProficient, 2, Qt::DotLine));
            const double px = f.map(*c.proficientAt, 0).x();
            p.drawLine(QPointF(px, f.area.top()), QPointF(px, f.area.bottom()));
        }
        drawValues(p, f, s);
        p.setPen(QPen(kInk, 1));
        p.setBrush(Qt::NoBrush);
        p.drawRect(f.area);
        drawLegend(p, c.proficientAt);
    }
    QByteArray bytes;
    QBuffer buf(&bytes);
    buf.open(QIODevice::WriteOnly);
    image.save(&buf, "PNG");
    return bytes;
}

/// The metrics that have an expert level in some attempt, in the order they first appear.
std::vector<std::string> expertMetrics(const LearningCurve& c) {
    std::vector<std::string> names;
    for (const Attempt& a : c.attempts)
        for (const MetricRecord& m : a.session->metrics)
            if (m.expert && std::find(names.begin(), names.end(), m.name) == names.end()) names.push_back(m.name);
    return names;
}

std::string attemptTable(const LearningCurve& c) {
    std::string t = "<table><tr><th>attempt</th><th>started (UTC)</th><th>case version</th><th>passed</th>"
                    "<th>completion time</th><th>within expert level</th></tr>\n";
    for (const Attempt& a : c.attempts) {
        const SessionRecord& s = *a.session;
        t += "<tr><td>" + std::to_string(a.number) + "</td><td>" + htmlText(s.startedUtc) + "</td><td>" +
             htmlText(s.caseVersion) + "</td><td class=\"" + (s.passed ? "ok\">yes" : "bad\">no") + "</td><td>" +
             (s.completionTime_s ? formatNumber("%.1f s", *s.completionTime_s) : "—") + "</td><td>" +
             std::to_string(a.withinExpert) + " of " + std::to_string(a.expertMetrics) +
             (c.proficientAt && a.number == *c.proficientAt ? " — proficient" : "") + "</td></tr>\n";
    }
    return t + "</table>\n";
}

} // namespace

std::string progressImageName(const std::string& metric) {
    std::string out;
    for (char ch : metric)
        out += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.') ? ch : '_';
    if (out.empty() || out[0] == '.') out.insert(out.begin(), '_');
    return out + ".png";
}

ProgressFiles writeProgress(const LearningCurve& c, const std::filesystem::path& dir) {
    requireWritableFolder(dir);
    ensureOffscreenGui();
    ProgressFiles out;
    const std::string title = "Learning curve — " + c.trainee + ", " + c.caseId;
    std::string page = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" + htmlText(title) +
                       "</title>\n<style>" + std::string(kPageStyle) + "</style></head><body>\n<h1>" + htmlText(title) +
                       "</h1>\n<p class=\"verdict " + (c.proficientAt ? "ok" : "bad") + "\"><b>" +
                       htmlText(c.verdict()) + "</b></p>\n" + attemptTable(c);
    const std::vector<std::string> names = expertMetrics(c);
    if (names.empty()) page += "<p>No metric of these sessions has an expert level: there is no curve to draw.</p>\n";
    for (const std::string& name : names) {
        const QByteArray png = curvePng(c, seriesOf(c, name));
        const std::filesystem::path file = dir / progressImageName(name);
        writeFileAtomic(file, std::string_view(png.constData(), static_cast<size_t>(png.size())));
        out.images.push_back(file);
        page +=
            "<figure><img class=\"curve\" alt=\"" + htmlText(name) + "\" src=\"data:image/png;base64," +
            png.toBase64().toStdString() + "\"><figcaption>" + htmlText(name) +
            " by attempt. Shaded: the expert mean ± one standard deviation; dashed: the expert bound (mean ± 2 "
            "sd, on the worse side). Green dots: passed attempts; red crosses: failed ones.</figcaption></figure>\n";
    }
    // Marks the page once every chart has decoded (a headless browser's check reads it back).
    page += "<script>window.addEventListener('load',function(){var n=0,i=document.querySelectorAll('img.curve');"
            "i.forEach(function(e){if(e.complete&&e.naturalWidth>0)n++;});document.body.setAttribute("
            "'data-curves-loaded',n+'/'+i.length);});</script>\n";
    page += "<p class=\"foot\">Made by viscera-results " VISCERA_VERSION ".</p>\n</body></html>\n";
    out.page = dir / "progress.html";
    writeFileAtomic(out.page, page);
    return out;
}

} // namespace viscera::player
