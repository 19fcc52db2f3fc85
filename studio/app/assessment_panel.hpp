#pragma once
/// The "Assessment" panel [issue 41]: the case's verdict rules as a table of every metric the
/// player measures (sim::metricCatalogue()): its unit, which way is better, the limit and the
/// expert level (mean, sd); the force threshold; a summary of the task's targets. A typed cell is
/// one undo step through Document::editAssessment, checked by the scene reader's rules: a refused
/// value shows the rule under the table and the cell shows the model's value again. An empty cell
/// removes the limit or the expert level. "Import expert levels…" takes the levels that
/// `viscera-results expert-levels` derived from expert sessions (a JSON fragment) into the case,
/// one undo step. The targets themselves (cut lines, clip sites, the wound's plane, the vessel)
/// are drawn on the anatomy with the target tool and listed above the metrics (target_panel.hpp).
#include <QString>
#include <QWidget>

class QLabel;
class QLineEdit;
class QTableWidget;

namespace viscera::studio {

class Document;
class TargetPanel;
class TargetTool;
struct Change;

class AssessmentPanel : public QWidget {
    Q_OBJECT
public:
    enum Column { Metric = 0, Unit, Better, Limit, ExpertMean, ExpertSd, Columns };
    /// `targets`: the tool the target rows' buttons drive (null: no target section).
    AssessmentPanel(Document* doc, TargetTool* targets, QWidget* parent = nullptr);
    TargetPanel* targetPanel() { return m_targetPanel; }
    QTableWidget* table() { return m_table; }
    QLabel* errorLabel() { return m_error; }
    QLabel* targetsLabel() { return m_targets; }
    QLineEdit* thresholdField() { return m_threshold; }
    /// Reads a `viscera-results expert-levels` file and sets those expert levels (limits kept).
    /// Returns the error shown (one line naming the file, the field and the rule), empty when done.
    QString importExpertLevels(const QString& path);

private:
    /// The model's assessment into the table and the fields.
    void fill();
    /// A cell the user typed into: the edit through the Document, or the refusal shown.
    void cellTyped(int row, int column);
    void thresholdTyped();
    /// Shows `why` (empty: accepted); a refusal puts the model's values back in the cells.
    void apply(const QString& why);

    Document* m_doc;
    QTableWidget* m_table = nullptr;
    QLabel* m_targets = nullptr;
    QLabel* m_error = nullptr;
    QLineEdit* m_threshold = nullptr;
    TargetPanel* m_targetPanel = nullptr;
    bool m_filling = false;
};

} // namespace viscera::studio
