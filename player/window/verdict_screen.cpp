#include "window/verdict_screen.hpp"

#include <QFont>

namespace viscera::player {

namespace {

const QColor kPass(70, 190, 90), kFail(230, 80, 60), kText(225, 225, 225), kDim(150, 150, 150);

QString q(const std::string& s) {
    return QString::fromStdString(s);
}

void paintHeadline(QPainter& p, int w, const Assessment& a, const std::string& title) {
    QFont f = p.font();
    f.setPointSize(13);
    p.setFont(f);
    p.setPen(kDim);
    p.drawText(QRect(0, 18, w, 24), Qt::AlignHCenter, q("Session ended — " + title));
    f.setPointSize(40);
    f.setBold(true);
    p.setFont(f);
    const char* word = !a.judged ? "NO VERDICT" : a.passed ? "PASS" : "FAIL";
    p.setPen(!a.judged ? kDim : a.passed ? kPass : kFail);
    p.drawText(QRect(0, 48, w, 64), Qt::AlignHCenter, word);
    f.setPointSize(12);
    f.setBold(false);
    p.setFont(f);
    p.setPen(kText);
    std::string line;
    if (!a.judged)
        line = "This case has no assessment: the figures below are for your information.";
    else if (a.find("completion_time_s") && !a.completionS)
        line = "Task not completed: its targets were not all met.";
    else if (a.find("completion_time_s")) {
        const std::string detail = a.verdictDetail(); // "completion 5.88 s[; within the expert level]"
        const size_t semi = detail.find("; ");
        line = "Task completed in " + formatFigure(a.completionS) + " s" +
               (semi == std::string::npos ? std::string() : " — " + detail.substr(semi + 2));
    } else
        line = a.verdictDetail();
    p.drawText(QRect(0, 116, w, 22), Qt::AlignHCenter, q(line));
}

/// One row per metric: name, value and unit, limit, result, expert level.
void paintTable(QPainter& p, int w, int top, int bottom, const Assessment& a) {
    QFont f = p.font();
    f.setPointSize(11);
    p.setFont(f);
    const int x0 = std::max(20, w / 2 - 420), cols[] = {x0, x0 + 260, x0 + 420, x0 + 540, x0 + 640};
    const int rowH = 20;
    p.setPen(kDim);
    const char* heads[] = {"metric", "value", "limit", "result", "expert level"};
    for (int c = 0; c < 5; ++c)
        p.drawText(cols[c], top, heads[c]);
    int y = top + rowH + 4;
    for (const MetricResult& m : a.metrics) {
        if (y > bottom) {
            p.setPen(kDim);
            p.drawText(x0, y, "… the rest in the report");
            break;
        }
        const std::string dir = m.lowerIsBetter ? "≤ " : "≥ ";
        p.setPen(kText);
        p.drawText(cols[0], y, q(m.name));
        p.drawText(cols[1], y, q(formatFigure(m.value) + " " + m.unit));
        p.drawText(cols[2], y, m.limit ? q(dir + formatFigure(m.limit)) : QString());
        if (m.limit) {
            p.setPen(m.passed ? kPass : kFail);
            p.drawText(cols[3], y, m.passed ? "pass" : "FAIL");
        }
        if (m.expert) {
            p.setPen(*m.withinExpert ? kPass : kDim);
            p.drawText(cols[4], y, q(dir + formatFigure(m.bound) + (*m.withinExpert ? " within" : " outside")));
        }
        y += rowH;
    }
}

} // namespace

void paintVerdictScreen(QPainter& p, const QSize& size, const Assessment& a, const std::string& title) {
    const int w = size.width(), h = size.height();
    p.fillRect(QRect(0, 0, w, h), QColor(24, 24, 28));
    p.setRenderHint(QPainter::Antialiasing);
    paintHeadline(p, w, a, title);
    paintTable(p, w, 170, h - 50, a);
    QFont f = p.font();
    f.setPointSize(11);
    p.setFont(f);
    p.setPen(kDim);
    p.drawText(QRect(0, h - 32, w, 22), Qt::AlignHCenter, "Enter or Esc: close");
}

} // namespace viscera::player
