#include "plots/session_plots.hpp"

#include "plots/html_text.hpp"
#include "plots/offscreen_gui.hpp"
#include "runtime/assessment_json.hpp"
#include "runtime/report.hpp"
#include "runtime/report_reader.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <QBuffer>
#include <QByteArray>
#include <QFont>
#include <QFontMetricsF>
#include <QGuiApplication>
#include <QImage>
#include <QPainter>
#include <QPainterPath>
#include <QString>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>

namespace viscera::player {

namespace {

using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The newest report schema these plots read: the one this player writes (a report of a newer
/// player may have changed a field's meaning).
constexpr int kNewestSchema = kReportSchemaVersion;

// ---- reading ----------------------------------------------------------------------------------

using Reader = ReportReader;

std::string at(const std::string& field, size_t i) {
    return field + "[" + std::to_string(i) + "]";
}

} // namespace

namespace {
void readTimelineInput(const Reader& rd, const json& doc, const std::vector<std::string>& names,
                       const std::vector<double>& paths, const std::vector<double>& forces, PlotInput& in);
void readAssessmentInput(const Reader& rd, const json& doc, PlotInput& in);
} // namespace

PlotInput readPlotInput(const json& doc, const std::string& origin) {
    const Reader rd{origin};
    PlotInput in;
    in.origin = origin;
    if (!doc.is_object()) rd.fail("(document)", "a session report must be a JSON object");
    const int schema = rd.integer(rd.member(doc, "", "schemaVersion"), "schemaVersion");
    if (schema < 1) rd.fail("schemaVersion", "must be at least 1");
    if (schema > kNewestSchema)
        rd.fail("schemaVersion",
                std::to_string(schema) + " is newer than this player reads (" + std::to_string(kNewestSchema) + ")");
    const json& c = rd.member(doc, "", "case");
    in.caseId = rd.string(rd.member(c, "case", "id"), "case.id");
    if (const json* v = rd.optional(c, "version")) in.caseVersion = rd.string(*v, "case.version");
    if (const json* v = rd.optional(c, "title")) in.title = rd.string(*v, "case.title");

    const json& frames = rd.array(rd.member(doc, "", "frames"), "frames");
    for (size_t i = 0; i < frames.size(); ++i) {
        const std::string f = at("frames", i);
        PlotInput::Frame fr;
        fr.stepMs = rd.number(rd.member(frames[i], f, "step_ms"), f + ".step_ms");
        if (fr.stepMs < 0) rd.fail(f + ".step_ms", "must not be negative");
        fr.energyJ = rd.numberOrNaN(rd.member(frames[i], f, "energy_j"), f + ".energy_j");
        fr.maxDisplacementM = rd.numberOrNaN(rd.member(frames[i], f, "max_displacement_m"), f + ".max_displacement_m");
        in.frames.push_back(fr);
    }
    const json& m = rd.member(doc, "", "metrics");
    in.frameDt_s = rd.number(rd.member(m, "metrics", "frame_dt_s"), "metrics.frame_dt_s");
    if (!(in.frameDt_s > 0)) rd.fail("metrics.frame_dt_s", "must be positive");
    auto metric = [&](const char* key, double& out) {
        if (const json* v = rd.optional(m, key)) out = rd.numberOrNaN(*v, std::string("metrics.") + key);
    };
    metric("sim_time_s", in.simTime_s);
    metric("wall_time_s", in.wallTime_s);
    metric("real_time_factor", in.realTimeFactor);
    metric("step_ms_mean", in.stepMsMean);
    metric("step_ms_p99", in.stepMsP99);
    if (const json* v = rd.optional(m, "punctures")) in.punctures = rd.integer(*v, "metrics.punctures");
    if (const json* v = rd.optional(m, "clips")) in.clips = rd.integer(*v, "metrics.clips");
    if (const json* v = rd.optional(m, "cut_edges")) in.cutEdges = rd.integer(*v, "metrics.cut_edges");
    std::vector<std::string> names;
    std::vector<double> paths, forces;
    if (const json* v = rd.optional(m, "tool_names")) names = rd.strings(*v, "metrics.tool_names");
    if (const json* v = rd.optional(m, "tool_path_length_per_tool_m"))
        paths = rd.numbers(*v, "metrics.tool_path_length_per_tool_m");
    if (const json* v = rd.optional(m, "max_contact_force_per_tool_n"))
        forces = rd.numbers(*v, "metrics.max_contact_force_per_tool_n");
    if (const json* h = rd.optional(doc, "haptics")) {
        const json& dev = rd.member(*h, "haptics", "device");
        in.device = rd.string(rd.member(dev, "haptics.device", "spec"), "haptics.device.spec");
        if (const json* v = rd.optional(*h, "case_max_force_n"))
            in.caseMaxForceN = rd.number(*v, "haptics.case_max_force_n");
        const char* key = schema >= 5 ? "device_max_force_n" : "max_force_n"; // renamed in schema 5
        if (const json* v = rd.optional(m, key)) in.maxDeviceForceN = rd.number(*v, std::string("metrics.") + key);
    }
    if (const json* i = rd.optional(doc, "interaction"))
        if (const json* g = rd.optional(*i, "grasps")) in.grasps = rd.integer(*g, "interaction.grasps");
    if (const json* inv = rd.optional(doc, "invariants"))
        if (const json* f = rd.optional(*inv, "all_finite")) {
            if (!f->is_boolean()) rd.fail("invariants.all_finite", "must be true or false");
            in.allFinite = f->get<bool>();
        }
    if (const json* e = rd.optional(doc, "errors")) in.errors = rd.strings(*e, "errors");
    if (const json* w = rd.optional(doc, "warnings")) in.warnings = rd.strings(*w, "warnings");

    if (const json* acc = rd.optional(doc, "accuracy")) {
        rd.array(*acc, "accuracy");
        for (size_t i = 0; i < acc->size(); ++i) {
            const std::string f = at("accuracy", i);
            PlotInput::Accuracy a;
            a.frame = rd.integer(rd.member((*acc)[i], f, "frame"), f + ".frame");
            a.solver = rd.string(rd.member((*acc)[i], f, "solver"), f + ".solver");
            a.timeMs = rd.numbers(rd.member((*acc)[i], f, "time_ms"), f + ".time_ms");
            a.relError = rd.numbers(rd.member((*acc)[i], f, "rel_error"), f + ".rel_error");
            if (a.timeMs.size() != a.relError.size())
                rd.fail(f + ".rel_error", "has " + std::to_string(a.relError.size()) + " values, time_ms has " +
                                              std::to_string(a.timeMs.size()));
            in.accuracy.push_back(std::move(a));
        }
    }

    readTimelineInput(rd, doc, names, paths, forces, in);
    readAssessmentInput(rd, doc, in);
    return in;
}

namespace {

void readTimelineInput(const Reader& rd, const json& doc, const std::vector<std::string>& names,
                       const std::vector<double>& paths, const std::vector<double>& forces, PlotInput& in) {
    if (const json* tl = rd.optional(doc, "timeline")) {
        in.hasTimeline = true;
        in.strideFrames = rd.integer(rd.member(*tl, "timeline", "stride_frames"), "timeline.stride_frames");
        if (in.strideFrames < 1) rd.fail("timeline.stride_frames", "must be at least 1");
        in.t_s = rd.numbers(rd.member(*tl, "timeline", "t_s"), "timeline.t_s");
        for (size_t i = 0; i < in.t_s.size(); ++i)
            if (!std::isfinite(in.t_s[i]) || (i > 0 && in.t_s[i] < in.t_s[i - 1]))
                rd.fail(at("timeline.t_s", i), "times must be finite and must not decrease");
        const json& tools = rd.array(rd.member(*tl, "timeline", "tools"), "timeline.tools");
        for (size_t k = 0; k < tools.size(); ++k) {
            const std::string f = at("timeline.tools", k);
            PlotInput::Tool t;
            t.name = rd.string(rd.member(tools[k], f, "name"), f + ".name");
            t.kind = rd.string(rd.member(tools[k], f, "kind"), f + ".kind");
            const json& tip = rd.array(rd.member(tools[k], f, "tip_m"), f + ".tip_m");
            for (size_t s = 0; s < tip.size(); ++s) {
                const std::string g = at(f + ".tip_m", s);
                if (!tip[s].is_array() || tip[s].size() != 3) rd.fail(g, "must be [x, y, z]");
                t.tip.push_back(
                    {rd.numberOrNaN(tip[s][0], g), rd.numberOrNaN(tip[s][1], g), rd.numberOrNaN(tip[s][2], g)});
            }
            t.forceN = rd.numbers(rd.member(tools[k], f, "force_n"), f + ".force_n");
            for (const auto& [field, n] : {std::pair{".tip_m", t.tip.size()}, std::pair{".force_n", t.forceN.size()}})
                if (n != in.t_s.size())
                    rd.fail(f + field,
                            "has " + std::to_string(n) + " samples, timeline.t_s has " + std::to_string(in.t_s.size()));
            for (size_t n = 0; n < names.size(); ++n)
                if (names[n] == t.name) {
                    if (n < paths.size()) t.pathM = paths[n];
                    if (n < forces.size()) t.maxForceN = forces[n];
                }
            in.tools.push_back(std::move(t));
        }
        const json& events = rd.array(rd.member(*tl, "timeline", "events"), "timeline.events");
        for (size_t e = 0; e < events.size(); ++e) {
            const std::string f = at("timeline.events", e);
            PlotInput::Event ev;
            ev.t_s = rd.number(rd.member(events[e], f, "t_s"), f + ".t_s");
            ev.kind = rd.string(rd.member(events[e], f, "kind"), f + ".kind");
            ev.tool = rd.string(rd.member(events[e], f, "tool"), f + ".tool");
            ev.count = rd.integer(rd.member(events[e], f, "count"), f + ".count");
            if (ev.count < 1) rd.fail(f + ".count", "must be at least 1");
            in.events.push_back(std::move(ev));
        }
    }
}

void readAssessmentInput(const Reader& rd, const json& doc, PlotInput& in) {
    if (const json* r = rd.optional(doc, "record")) {
        in.trainee = rd.string(rd.member(*r, "record", "trainee"), "record.trainee");
        in.startedUtc = rd.string(rd.member(*r, "record", "started_utc"), "record.started_utc");
    }
    const json* a = rd.optional(doc, "assessment");
    if (!a) return;
    in.hasAssessment = true;
    Assessment& out = in.assessment;
    const json& judged = rd.member(*a, "assessment", "judged");
    if (!judged.is_boolean()) rd.fail("assessment.judged", "must be true or false");
    out.judged = judged.get<bool>();
    const json& passed = rd.member(*a, "assessment", "passed");
    if (out.judged && !passed.is_boolean()) rd.fail("assessment.passed", "must be true or false");
    out.passed = !out.judged || passed.get<bool>();
    const json& c = rd.member(*a, "assessment", "completion_time_s");
    if (!c.is_null()) out.completionS = rd.number(c, "assessment.completion_time_s");
    const json& metrics = rd.array(rd.member(*a, "assessment", "metrics"), "assessment.metrics");
    for (size_t i = 0; i < metrics.size(); ++i)
        out.metrics.push_back(readMetricJson(rd, metrics[i], at("assessment.metrics", i)));
}

} // namespace

PlotInput readPlotInputFile(const std::filesystem::path& reportPath) {
    return readPlotInput(parseReportText(readFile(reportPath), reportPath.string()), reportPath.string());
}

// ---- drawing ----------------------------------------------------------------------------------

namespace {

const QColor kToolColors[] = {QColor(31, 119, 180),  QColor(214, 39, 40), QColor(44, 160, 44),  QColor(255, 127, 14),
                              QColor(148, 103, 189), QColor(140, 86, 75), QColor(227, 119, 194)};
QColor toolColor(size_t k) {
    return kToolColors[k % (sizeof kToolColors / sizeof kToolColors[0])];
}
const QColor kInk(40, 40, 48), kGrid(225, 227, 232), kBudget(200, 30, 30);

QString q(const std::string& s) {
    return QString::fromStdString(s);
}

/// "Nice" tick step (1, 2 or 5 × 10^k) giving about `target` ticks over `span`.
double niceStep(double span, int target) {
    const double raw = span / std::max(target, 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / mag;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

struct Range {
    double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
    void add(double v) {
        if (!std::isfinite(v)) return;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    bool valid() const { return lo <= hi; }
    /// Padded, never empty; `zero`: include 0.
    Range padded(bool zero) const {
        Range r = valid() ? *this : Range{0, 1};
        if (zero) {
            r.lo = std::min(r.lo, 0.0);
            r.hi = std::max(r.hi, 0.0);
        }
        if (r.hi - r.lo < 1e-12 * std::max(1.0, std::abs(r.hi))) {
            const double d = std::max(std::abs(r.hi) * 0.1, 1e-9);
            r.lo -= d;
            r.hi += d;
        }
        const double pad = 0.05 * (r.hi - r.lo);
        if (!(zero && r.lo == 0)) r.lo -= pad;
        r.hi += pad;
        return r;
    }
};

/// The time axis [0, end], never empty (end non-finite or ≤ 1 ms: 1 ms).
Range timeAxis(double end) {
    return {0.0, std::fmax(end, 1e-3)};
}

class Chart {
public:
    Chart(QPainter& p, const QRectF& box, const QString& title, const QString& xLabel, const QString& yLabel)
        : m_p(p), m_box(box), m_title(title), m_xLabel(xLabel), m_yLabel(yLabel) {
        m_area = box.adjusted(74, 34, -16, -46);
    }
    void setRange(Range x, Range y, bool logY = false, bool logX = false) {
        m_x = x;
        m_y = y;
        m_logY = logY;
        m_logX = logX;
        auto decades = [](Range& r, const Range& v) {
            r.lo = std::floor(std::log10(std::max(v.lo, 1e-300)));
            r.hi = std::ceil(std::log10(std::max(v.hi, 1e-300)));
            if (r.hi <= r.lo) r.hi = r.lo + 1;
        };
        if (logY) decades(m_y, y);
        if (logX) decades(m_x, x);
    }
    /// Same scale on both axes (a map of positions): widens the narrower range.
    void equalAspect() {
        const double sx = (m_x.hi - m_x.lo) / m_area.width(), sy = (m_y.hi - m_y.lo) / m_area.height();
        if (sx > sy) {
            const double c = 0.5 * (m_y.lo + m_y.hi), h = 0.5 * sx * m_area.height();
            m_y = {c - h, c + h};
        } else {
            const double c = 0.5 * (m_x.lo + m_x.hi), h = 0.5 * sy * m_area.width();
            m_x = {c - h, c + h};
        }
    }
    QPointF map(double x, double y) const {
        const double yy = m_logY ? std::log10(std::max(y, 1e-300)) : y;
        const double xx = m_logX ? std::log10(std::max(x, 1e-300)) : x;
        return {m_area.left() + (xx - m_x.lo) / (m_x.hi - m_x.lo) * m_area.width(),
                m_area.bottom() - (yy - m_y.lo) / (m_y.hi - m_y.lo) * m_area.height()};
    }
    void axes() {
        m_p.save();
        m_p.setPen(Qt::NoPen);
        m_p.setBrush(QColor(250, 250, 252));
        m_p.drawRect(m_area);
        QFont f = m_p.font();
        const QFontMetricsF fm(f);
        // x ticks
        if (m_logX) {
            for (double e = m_x.lo; e <= m_x.hi + 1e-9; e += 1) {
                const double px = m_area.left() + (e - m_x.lo) / (m_x.hi - m_x.lo) * m_area.width();
                m_p.setPen(QPen(kGrid, 1));
                m_p.drawLine(QPointF(px, m_area.top()), QPointF(px, m_area.bottom()));
                m_p.setPen(kInk);
                const QString s = QString::number(std::pow(10.0, e), 'g', 4);
                m_p.drawText(
                    QPointF(std::min(px - fm.horizontalAdvance(s) / 2, m_box.right() - fm.horizontalAdvance(s) - 2),
                            m_area.bottom() + fm.ascent() + 4),
                    s);
            }
        } else {
            const double xs = niceStep(m_x.hi - m_x.lo, 8);
            for (double t = std::ceil(m_x.lo / xs) * xs; t <= m_x.hi + 1e-9 * xs; t += xs) {
                const double px = map(t, 0).x();
                m_p.setPen(QPen(kGrid, 1));
                m_p.drawLine(QPointF(px, m_area.top()), QPointF(px, m_area.bottom()));
                m_p.setPen(kInk);
                const QString s = QString::number(std::abs(t) < 1e-12 * xs ? 0.0 : t, 'g', 5);
                m_p.drawText(
                    QPointF(std::min(px - fm.horizontalAdvance(s) / 2, m_box.right() - fm.horizontalAdvance(s) - 2),
                            m_area.bottom() + fm.ascent() + 4),
                    s);
            }
        }
        // y ticks
        if (m_logY) {
            for (double e = m_y.lo; e <= m_y.hi + 1e-9; e += 1) {
                const double py = m_area.bottom() - (e - m_y.lo) / (m_y.hi - m_y.lo) * m_area.height();
                m_p.setPen(QPen(kGrid, 1));
                m_p.drawLine(QPointF(m_area.left(), py), QPointF(m_area.right(), py));
                m_p.setPen(kInk);
                const QString s = QString("1e%1").arg(static_cast<int>(e));
                m_p.drawText(QPointF(m_area.left() - fm.horizontalAdvance(s) - 6, py + fm.ascent() / 2 - 1), s);
            }
        } else if (!m_noYTicks) {
            const double ys = niceStep(m_y.hi - m_y.lo, 6);
            for (double t = std::ceil(m_y.lo / ys) * ys; t <= m_y.hi + 1e-9 * ys; t += ys) {
                const double py = map(0, t).y();
                m_p.setPen(QPen(kGrid, 1));
                m_p.drawLine(QPointF(m_area.left(), py), QPointF(m_area.right(), py));
                m_p.setPen(kInk);
                const QString s = QString::number(std::abs(t) < 1e-12 * ys ? 0.0 : t, 'g', 5);
                m_p.drawText(QPointF(m_area.left() - fm.horizontalAdvance(s) - 6, py + fm.ascent() / 2 - 1), s);
            }
        }
        m_p.setPen(QPen(kInk, 1));
        m_p.setBrush(Qt::NoBrush);
        m_p.drawRect(m_area);
        QFont bold = f;
        bold.setBold(true);
        m_p.setFont(bold);
        m_p.drawText(QPointF(m_area.left(), m_box.top() + 22), m_title);
        m_p.setFont(f);
        m_p.drawText(QPointF(m_area.center().x() - fm.horizontalAdvance(m_xLabel) / 2, m_box.bottom() - 8), m_xLabel);
        m_p.translate(m_box.left() + 16, m_area.center().y() + fm.horizontalAdvance(m_yLabel) / 2);
        m_p.rotate(-90);
        m_p.drawText(QPointF(0, 0), m_yLabel);
        m_p.restore();
    }
    /// A polyline; a non-finite value breaks it.
    void line(const std::vector<double>& x, const std::vector<double>& y, const QColor& c, double width = 1.6,
              Qt::PenStyle style = Qt::SolidLine) {
        m_p.save();
        m_p.setClipRect(m_area);
        m_p.setRenderHint(QPainter::Antialiasing);
        m_p.setPen(QPen(c, width, style, Qt::RoundCap, Qt::RoundJoin));
        QPainterPath path;
        bool open = false;
        for (size_t i = 0; i < x.size() && i < y.size(); ++i) {
            if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || (m_logY && y[i] <= 0) || (m_logX && x[i] <= 0)) {
                open = false;
                continue;
            }
            const QPointF p = map(x[i], y[i]);
            if (open)
                path.lineTo(p);
            else
                path.moveTo(p);
            open = true;
        }
        m_p.drawPath(path);
        m_p.restore();
    }
    void marker(double x, double y, const QColor& c, bool filled, double r = 4.5) {
        if (!std::isfinite(x) || !std::isfinite(y)) return;
        m_p.save();
        m_p.setRenderHint(QPainter::Antialiasing);
        m_p.setPen(QPen(c, 1.8));
        m_p.setBrush(filled ? QBrush(c) : QBrush(Qt::white));
        m_p.drawEllipse(map(x, y), r, r);
        m_p.restore();
    }
    void hline(double y, const QColor& c, const QString& label) {
        if (!std::isfinite(y)) return;
        const double py = map(m_x.lo, y).y();
        if (py < m_area.top() || py > m_area.bottom()) return;
        m_p.save();
        m_p.setPen(QPen(c, 1.4, Qt::DashLine));
        m_p.drawLine(QPointF(m_area.left(), py), QPointF(m_area.right(), py));
        m_p.setPen(c);
        const QFontMetricsF fm(m_p.font());
        m_p.drawText(QPointF(m_area.right() - fm.horizontalAdvance(label) - 6, py - 4), label);
        m_p.restore();
    }
    /// Right-aligned on the title's line, above the plot area (never over the data).
    void legend(const std::vector<std::pair<QString, QColor>>& items) {
        if (items.empty()) return;
        m_p.save();
        const QFontMetricsF fm(m_p.font());
        double x = m_box.right() - 16;
        const double y = m_box.top() + 22;
        for (auto it = items.rbegin(); it != items.rend(); ++it) {
            const double w = fm.horizontalAdvance(it->first);
            x -= w;
            m_p.setPen(kInk);
            m_p.drawText(QPointF(x, y), it->first);
            m_p.setPen(QPen(it->second, 3));
            m_p.drawLine(QPointF(x - 22, y - fm.ascent() / 2 + 1), QPointF(x - 6, y - fm.ascent() / 2 + 1));
            x -= 22 + 14;
        }
        m_p.restore();
    }
    void hideYTicks() { m_noYTicks = true; }
    void message(const QString& s) {
        m_p.save();
        m_p.setPen(QColor(110, 110, 120));
        m_p.drawText(m_area, Qt::AlignCenter | Qt::TextWordWrap, s);
        m_p.restore();
    }
    const QRectF& area() const { return m_area; }
    double yOfRow(double v) const { return map(m_x.lo, v).y(); }

private:
    QPainter& m_p;
    QRectF m_box, m_area;
    QString m_title, m_xLabel, m_yLabel;
    Range m_x{0, 1}, m_y{0, 1};
    bool m_logY = false, m_logX = false, m_noYTicks = false;
};

struct Canvas {
    QImage image;
    std::unique_ptr<QPainter> p;
    Canvas(int w, int h) : image(w, h, QImage::Format_RGB32) {
        image.fill(Qt::white);
        p = std::make_unique<QPainter>(&image);
        QFont f("DejaVu Sans");
        f.setPixelSize(13);
        p->setFont(f);
        p->setRenderHint(QPainter::TextAntialiasing);
    }
    QByteArray png() {
        p->end();
        QByteArray bytes;
        QBuffer buf(&bytes);
        buf.open(QIODevice::WriteOnly);
        image.save(&buf, "PNG");
        return bytes;
    }
};

std::vector<double> frameTimes(const PlotInput& in) {
    std::vector<double> t(in.frames.size());
    for (size_t i = 0; i < t.size(); ++i)
        t[i] = (static_cast<double>(i) + 1) * in.frameDt_s;
    return t;
}

QString fmt(const char* f, double v) {
    return QString::fromStdString(formatNumber(f, v));
}

QByteArray stepTimePlot(const PlotInput& in) {
    Canvas c(1100, 440);
    const std::vector<double> t = frameTimes(in);
    std::vector<double> ms;
    Range y;
    for (const auto& f : in.frames) {
        ms.push_back(f.stepMs);
        y.add(f.stepMs);
    }
    const double budget = in.frameDt_s * 1e3;
    y.add(budget);
    Chart ch(*c.p, QRectF(0, 0, 1100, 440),
             "Physics step time per frame" + (in.realTimeFactor > 0
                                                  ? fmt(" — real-time factor %.2f", in.realTimeFactor) +
                                                        (in.realTimeFactor < 1 ? " (slower than real time)" : "")
                                                  : QString()),
             "session time (s)", "step time (ms)");
    const Range x = timeAxis(t.empty() ? 1 : t.back());
    ch.setRange(x, y.padded(true));
    ch.axes();
    if (in.frames.empty()) {
        ch.message("The report has no frames.");
        return c.png();
    }
    ch.line(t, ms, toolColor(0), 1.2);
    ch.hline(budget, kBudget, fmt("real-time budget %.1f ms (one frame)", budget));
    ch.legend({{fmt("step (mean %.2f ms", in.stepMsMean) + fmt(", p99 %.2f ms)", in.stepMsP99), toolColor(0)}});
    return c.png();
}

QByteArray forcePlot(const PlotInput& in) {
    Canvas c(1100, 440);
    Chart ch(*c.p, QRectF(0, 0, 1100, 440), "Force from the tissue on each tool", "session time (s)", "force (N)");
    const Range x = timeAxis(in.t_s.empty() ? in.simTime_s : in.t_s.back());
    Range y;
    for (const auto& tool : in.tools)
        for (double f : tool.forceN)
            y.add(f);
    ch.setRange(x, y.padded(true));
    ch.axes();
    if (in.tools.empty()) {
        ch.message(in.hasTimeline ? "This case has no tool (no instrument, probe or needle)."
                                  : "The report has no timeline (written before the timeline was added).");
        return c.png();
    }
    std::vector<std::pair<QString, QColor>> legend;
    for (size_t k = 0; k < in.tools.size(); ++k) {
        ch.line(in.t_s, in.tools[k].forceN, toolColor(k));
        legend.push_back(
            {q(in.tools[k].name) + " (max " + q(formatFigure(in.tools[k].maxForceN)) + " N)", toolColor(k)});
    }
    ch.legend(legend);
    return c.png();
}

QByteArray pathPlot(const PlotInput& in) {
    Canvas c(1100, 470); // a legend row across the top, then three panels
    auto panel = [&](const QRectF& box, int a, int b, const QString& title, const QString& xl, const QString& yl) {
        Chart ch(*c.p, box, title, xl, yl);
        Range x, y;
        for (const auto& tool : in.tools)
            for (const auto& p : tool.tip) {
                x.add(p[a] * 1e3);
                y.add(p[b] * 1e3);
            }
        ch.setRange(x.padded(false), y.padded(false));
        ch.equalAspect();
        ch.axes();
        if (in.tools.empty()) {
            ch.message("No tool moved in this case.");
            return;
        }
        for (size_t k = 0; k < in.tools.size(); ++k) {
            std::vector<double> xs, ys;
            for (const auto& p : in.tools[k].tip) {
                xs.push_back(p[a] * 1e3);
                ys.push_back(p[b] * 1e3);
            }
            ch.line(xs, ys, toolColor(k), 1.6);
            if (!xs.empty()) {
                ch.marker(xs.front(), ys.front(), toolColor(k), false);
                ch.marker(xs.back(), ys.back(), toolColor(k), true);
            }
        }
    };
    panel(QRectF(0, 26, 370, 444), 0, 1, "Tool tips from above", "x (mm)", "y (mm)");
    panel(QRectF(370, 26, 370, 444), 0, 2, "From the side", "x (mm)", "z (mm, up)");
    // Path length over time.
    Chart ch(*c.p, QRectF(740, 26, 360, 444), "Path length", "session time (s)", "path (mm)");
    std::vector<std::vector<double>> len(in.tools.size());
    const Range x = timeAxis(in.t_s.empty() ? 1 : in.t_s.back());
    Range y;
    for (size_t k = 0; k < in.tools.size(); ++k) {
        double s = 0;
        for (size_t i = 0; i < in.tools[k].tip.size(); ++i) {
            if (i > 0) {
                const auto& p = in.tools[k].tip[i];
                const auto& o = in.tools[k].tip[i - 1];
                const double d = std::sqrt((p[0] - o[0]) * (p[0] - o[0]) + (p[1] - o[1]) * (p[1] - o[1]) +
                                           (p[2] - o[2]) * (p[2] - o[2]));
                if (std::isfinite(d)) s += d;
            }
            len[k].push_back(s * 1e3);
            y.add(s * 1e3);
        }
    }
    ch.setRange(x, y.padded(true));
    ch.axes();
    std::vector<std::pair<QString, QColor>> legend;
    for (size_t k = 0; k < in.tools.size(); ++k) {
        ch.line(in.t_s, len[k], toolColor(k));
        legend.push_back({q(in.tools[k].name), toolColor(k)});
    }
    Chart(*c.p, QRectF(0, -4, 1100, 30), "", "", "").legend(legend);
    if (in.tools.empty()) ch.message("No tool.");
    return c.png();
}

QByteArray eventPlot(const PlotInput& in) {
    static const char* kKinds[] = {"grasp", "release", "cut", "clip", "puncture"};
    static const char* kLabels[] = {"grasps", "releases", "cuts", "clips", "punctures"};
    Canvas c(1100, 360);
    Chart ch(*c.p, QRectF(110, 0, 990, 360), "Task events", "session time (s)", "");
    const Range x = timeAxis(std::fmax(in.simTime_s, in.t_s.empty() ? 0.0 : in.t_s.back()));
    const Range y{0.5, 5.5};
    ch.setRange(x, y);
    ch.hideYTicks(); // the rows are labelled on the left
    ch.axes();
    std::map<std::string, size_t> colorOf;
    for (size_t k = 0; k < in.tools.size(); ++k)
        colorOf[in.tools[k].name] = k;
    QPainter& p = *c.p;
    const QFontMetricsF fm(p.font());
    for (int row = 0; row < 5; ++row) {
        int64_t n = 0, total = 0;
        for (const auto& e : in.events)
            if (e.kind == kKinds[row]) {
                ++n;
                total += e.count;
            }
        const double yc = ch.yOfRow(5 - row);
        QString label = kLabels[row];
        if (row == 2 && n > 0)
            label = QString("cuts (%1 edges)").arg(total);
        else
            label = QString("%1 (%2)").arg(kLabels[row]).arg(row == 4 ? total : n);
        p.setPen(kInk);
        p.drawText(QPointF(8, yc + fm.ascent() / 2 - 2), label);
        for (const auto& e : in.events) {
            if (e.kind != kKinds[row]) continue;
            const auto it = colorOf.find(e.tool);
            const QColor col = it == colorOf.end() ? kInk : toolColor(it->second);
            const double px = ch.map(e.t_s, 0).x();
            const double h = row == 2 ? std::min(24.0, 6.0 + 3.0 * e.count) : 22.0;
            p.setPen(QPen(col, row == 2 ? 1.5 : 3));
            p.drawLine(QPointF(px, yc - h / 2), QPointF(px, yc + h / 2));
        }
    }
    std::vector<std::pair<QString, QColor>> legend;
    for (size_t k = 0; k < in.tools.size(); ++k)
        legend.push_back({q(in.tools[k].name), toolColor(k)});
    ch.legend(legend);
    if (in.events.empty()) ch.message("No grasp, cut, clip or puncture in this session.");
    return c.png();
}

QByteArray stabilityPlot(const PlotInput& in) {
    Canvas c(1100, 440);
    const std::vector<double> t = frameTimes(in);
    std::vector<double> e, d;
    Range ye, yd;
    const Range x = timeAxis(t.empty() ? 1 : t.back());
    for (const auto& f : in.frames) {
        e.push_back(f.energyJ);
        d.push_back(f.maxDisplacementM * 1e3);
        ye.add(f.energyJ);
        yd.add(f.maxDisplacementM * 1e3);
    }
    Chart a(*c.p, QRectF(0, 0, 550, 440), "Total energy (elastic + kinetic + gravitational)", "session time (s)",
            "energy (J)");
    a.setRange(x, ye.padded(false));
    a.axes();
    a.line(t, e, toolColor(4));
    Chart b(*c.p, QRectF(550, 0, 550, 440), "Largest node move in one frame", "session time (s)", "move (mm)");
    b.setRange(x, yd.padded(true));
    b.axes();
    b.line(t, d, toolColor(3));
    if (in.frames.empty()) {
        a.message("No frames.");
        b.message("No frames.");
    }
    return c.png();
}

QByteArray accuracyPlot(const PlotInput& in) {
    Canvas c(1100, 440);
    Chart ch(*c.p, QRectF(0, 0, 1100, 440), "Solver error against run time, on the sampled frames",
             "solver time (ms, log)", "relative error (log)");
    Range x, y;
    for (const auto& a : in.accuracy)
        for (size_t i = 0; i < a.timeMs.size(); ++i)
            if (a.relError[i] > 0 && a.timeMs[i] > 0) {
                x.add(a.timeMs[i]);
                y.add(a.relError[i]);
            }
    ch.setRange(x.valid() ? x : Range{0.1, 10}, y.valid() ? y : Range{1e-6, 1}, true, true);
    ch.axes();
    // One colour per solver; each sampled frame is one curve of it.
    const QColor xpbd(214, 39, 40), newton(31, 119, 180);
    int nx = 0, nn = 0;
    for (const auto& a : in.accuracy) {
        const bool isX = a.solver == "xpbd";
        (isX ? nx : nn) += 1;
        const QColor col = isX ? xpbd : newton;
        ch.line(a.timeMs, a.relError, col, 1.4);
        for (size_t i = 0; i < a.timeMs.size(); ++i)
            if (a.relError[i] > 0 && a.timeMs[i] > 0) ch.marker(a.timeMs[i], a.relError[i], col, true, 2.5);
    }
    ch.hline(1e-4, kBudget, "1e-4");
    std::vector<std::pair<QString, QColor>> legend;
    if (nx) legend.push_back({QString("XPBD, %1 frames").arg(nx), xpbd});
    if (nn) legend.push_back({QString("Newton (reference), %1 frames").arg(nn), newton});
    ch.legend(legend);
    return c.png();
}

/// The verdict and one row per metric: value, limit, pass or fail, expert level; each row also
/// carries the summary's line for the metric (data-line), so the page and the summary agree.
std::string verdictHtml(const Assessment& a) {
    std::string s = "<h2 id=\"verdict\">";
    if (a.judged)
        s += std::string("<span class=\"") + (a.passed ? "pass\">PASS" : "bad\">FAIL") + "</span>";
    else
        s += "No verdict (the case has no assessment)";
    s += "</h2>\n<p>" + htmlText(a.judged ? a.verdictDetail() : "") + "</p>\n";
    s += "<table id=\"metrics\"><tr><th>metric</th><th>value</th><th>unit</th><th>limit</th><th>result</th><th>expert "
         "level</th></tr>\n";
    for (const MetricResult& m : a.metrics) {
        const std::string dir = m.lowerIsBetter ? "≤ " : "≥ ";
        s += "<tr data-line=\"" + htmlText(metricLine(m)) + "\"><td>" + htmlText(m.name) + "</td><td>" +
             formatFigure(m.value) + "</td><td>" + htmlText(m.unit) + "</td><td>" +
             (m.limit ? dir + formatFigure(m.limit) : "") + "</td><td" + (m.passed ? ">" : " class=\"bad\">") +
             (m.limit ? (m.passed ? "pass" : "FAIL") : "") + "</td><td>" +
             (m.expert ? dir + formatFigure(m.bound) + (*m.withinExpert ? " within" : " outside") : "") +
             "</td></tr>\n";
    }
    return s + "</table>\n";
}

} // namespace

PlotFiles writeSessionPlots(const PlotInput& in, const std::filesystem::path& dir) {
    requireWritableFolder(dir);
    ensureOffscreenGui();
    struct Item {
        const char* file;
        const char* caption;
        QByteArray png;
    };
    std::vector<Item> items;
    items.push_back({"step_time.png",
                     "Physics step time per frame. Below the dashed line the physics keeps up with real time; above "
                     "it the trainee sees the tissue in slow motion.",
                     stepTimePlot(in)});
    items.push_back({"forces.png", "Force the tissue puts on each tool, over the session.", forcePlot(in)});
    items.push_back({"tool_paths.png",
                     "Where each tool tip went (open circle: start, filled: end) and the path each one travelled.",
                     pathPlot(in)});
    items.push_back(
        {"events.png", "Grasps, releases, cuts (energy hook), clips and needle punctures, in time.", eventPlot(in)});
    items.push_back({"stability.png",
                     "Stability: the total energy and the largest node move in one frame. Spikes mark frames worth a "
                     "look.",
                     stabilityPlot(in)});
    if (!in.accuracy.empty())
        items.push_back({"accuracy.png",
                         "Error of the solver against the time it ran, on the sampled frames (relative to a "
                         "converged solve).",
                         accuracyPlot(in)});
    PlotFiles out;
    for (const Item& it : items) {
        const std::filesystem::path p = dir / it.file;
        writeFileAtomic(p, std::string_view(it.png.constData(), static_cast<size_t>(it.png.size())));
        out.images.push_back(p);
    }

    // The page: headline figures, then the charts embedded.
    std::string page =
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>Session — " +
        htmlText(in.title.empty() ? in.caseId : in.title) +
        "</title>\n<style>body{font-family:sans-serif;max-width:1140px;margin:24px auto;color:#28283"
        "0}table{border-collapse:collapse}td,th{padding:3px 12px 3px 0;text-align:left}th{color:#666;"
        "font-weight:normal}.pass{color:#070}.bad{color:#b00}.warn{color:#a60}figure{margin:18px 0}img{max-width:100%;"
        "border:1px solid #ddd}</style></head><body>\n";
    page += "<h1>" + htmlText(in.title.empty() ? in.caseId : in.title) + "</h1>\n<p>Case " + htmlText(in.caseId) + " " +
            htmlText(in.caseVersion) + (in.device.empty() ? "" : ", device " + htmlText(in.device)) + "</p>\n";
    const bool ok = in.errors.empty() && in.allFinite;
    page += std::string("<p class=\"") + (ok ? "" : "bad") + "\"><b>" +
            (ok ? "Session ran to the end without a broken invariant." : "The session broke an invariant.") +
            "</b></p>\n";
    for (const std::string& e : in.errors)
        page += "<p class=\"bad\">" + htmlText(e) + "</p>\n";
    for (const std::string& w : in.warnings)
        page += "<p class=\"warn\">warning: " + htmlText(w) + "</p>\n";
    page += "<table>\n";
    auto row = [&](const std::string& k, const std::string& v) {
        page += "<tr><th>" + k + "</th><td>" + v + "</td></tr>\n";
    };
    row("frames", std::to_string(in.frames.size()) + formatNumber(" (%.2f s simulated", in.simTime_s) +
                      formatNumber(" in %.2f s)", in.wallTime_s));
    if (in.realTimeFactor > 0)
        row("real-time factor",
            formatNumber("%.2f", in.realTimeFactor) + (in.realTimeFactor < 1 ? " — slower than real time" : ""));
    row("step time", formatNumber("mean %.2f ms", in.stepMsMean) + formatNumber(", p99 %.2f ms", in.stepMsP99) +
                         formatNumber(" (budget %.1f ms)", in.frameDt_s * 1e3));
    if (!in.trainee.empty()) row("trainee", htmlText(in.trainee) + ", started " + htmlText(in.startedUtc));
    for (const auto& t : in.tools)
        row(htmlText(t.name) + " (" + htmlText(t.kind) + ")",
            "path " + formatFigure(t.pathM) + " m, largest force " + formatFigure(t.maxForceN) + " N");
    if (!in.device.empty())
        row("device force", "max " + formatFigure(in.maxDeviceForceN) + " N" +
                                (in.caseMaxForceN > 0 ? formatNumber(" (case limit %.1f N)", in.caseMaxForceN) : ""));
    std::map<std::string, int64_t> counts;
    for (const auto& e : in.events)
        counts[e.kind] += e.kind == "cut" || e.kind == "puncture" ? e.count : 1;
    if (in.grasps || counts["grasp"]) row("grasps", std::to_string(counts["grasp"]));
    if (in.cutEdges || counts["cut"]) row("edges cut", std::to_string(in.cutEdges));
    if (in.clips || counts["clip"]) row("clips", std::to_string(in.clips));
    if (in.punctures || counts["puncture"]) row("punctures", std::to_string(in.punctures));
    page += "</table>\n";
    if (in.hasAssessment) page += verdictHtml(in.assessment);
    for (const Item& it : items)
        page += "<figure><img alt=\"" + std::string(it.file) + "\" src=\"data:image/png;base64," +
                it.png.toBase64().toStdString() + "\"><figcaption>" + htmlText(it.caption) + "</figcaption></figure>\n";
    page += "<p style=\"color:#888\">Made by viscera-player from " + htmlText(in.origin) + ".</p>\n</body></html>\n";
    out.page = dir / "session.html";
    writeFileAtomic(out.page, page);
    return out;
}

} // namespace viscera::player
