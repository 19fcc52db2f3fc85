#pragma once
/// The task's targets in the Assessment dock [issue 57 item 2]: the pick tools (Draw cut line,
/// Pick clip site, Pick suture plane, Pick vessel; target_tool.hpp) as buttons, and every target
/// as rows of one table — target, field, value — in the units an artist thinks in (mm, %). A
/// typed value is one undo step through Document::editAssessment, checked by the scene reader's
/// rules: a refused value shows the rule under the table and the cell shows the model's value
/// again. "Remove target" takes the target of the selected row out (one undo step; refused while
/// a metric needs that kind of target). Read-only rows say where a target lies.
#include "sim/scene/assessment.hpp"

#include <QString>
#include <QWidget>
#include <functional>
#include <optional>
#include <vector>

class QLabel;
class QPushButton;
class QTableWidget;

namespace viscera::studio {

class Document;
class TargetTool;

class TargetPanel : public QWidget {
    Q_OBJECT
public:
    enum Column { Target = 0, Field, Value, Columns };
    TargetPanel(Document* doc, TargetTool* tool, QWidget* parent = nullptr);
    QTableWidget* table() { return m_table; }
    QLabel* errorLabel() { return m_error; }
    QPushButton* removeButton() { return m_remove; }
    /// The row of `field` of target `target` ("cut 1", "clip 2", "suture", "vessel"); -1: none.
    int row(const QString& target, const QString& field) const;
    /// Takes out the target of row `row`; returns the refusal, empty when done.
    QString removeTargetOf(int row);

    /// One row: which target, which field, its text, and (editable rows) how a typed value is set.
    struct Row {
        QString target, field;
        enum class Kind { Cut, Clip, Suture, Vessel } kind = Kind::Cut;
        int index = 0; ///< cut or clip index
        std::function<QString(const sim::AssessmentDesc&)> text;
        /// Sets the typed text into the assessment; returns the error (what was typed), empty when set.
        std::function<QString(sim::AssessmentDesc&, const QString&)> set; ///< empty: read-only
    };

private:
    void fill();
    void typed(int row, int column);
    void show(const QString& why);
    std::optional<sim::AssessmentDesc> model() const;

    Document* m_doc;
    QTableWidget* m_table = nullptr;
    QLabel* m_error = nullptr;
    QPushButton* m_remove = nullptr;
    std::vector<Row> m_rows;
    bool m_filling = false;
};

} // namespace viscera::studio
