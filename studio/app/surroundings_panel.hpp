#pragma once
/// The "Surroundings" panel [issue 57 item 1]: the static anatomy around the simulated tissue —
/// the render-only scenery primitives (a cylinder wall seen from inside or outside, a disc) the
/// trainee sees and the ports are placed on. Lists them; *Add wall* (a cylinder) and *Add floor*
/// (a disc) add one, *Remove* takes the selected one out; the selected one's fields: name, radius
/// (mm), for a wall its axis start and end (m, "x, y, z"), its arc (from / to, degrees) and its
/// facing (inward: seen from inside), for a floor its centre and normal. Every value is one undo
/// step through Document::editScenery, checked by the project reader's rule for "scenery"; a
/// refused value shows the rule under the fields and the field shows the model's value again.
/// *Import mesh…* adds static anatomy from a surface file (copied into the project's anatomy/
/// folder; its unit guessed from its size, as Import anatomy does, and editable as "Metres per
/// file unit"), drawn as it is.
/// The selected one's material maps (texture spec, tiles, normal strength, generator) are the
/// Material maps dock's, as for a body: selecting one targets that dock (selectedChanged), and
/// *Material maps…* brings it to the front (mapsRequested).
#include <QString>
#include <QWidget>
#include <map>

class QComboBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QPushButton;

namespace viscera::studio {

class Document;

class SurroundingsPanel : public QWidget {
    Q_OBJECT
public:
    explicit SurroundingsPanel(Document* doc, QWidget* parent = nullptr);
    QListWidget* list() { return m_list; }
    /// The field named `key`: "name", "radius_mm", "start", "end", "from_deg", "to_deg", "center",
    /// "normal" (null for another name).
    QLineEdit* field(const QString& key) const;
    QComboBox* facing() { return m_facing; }
    QLabel* errorLabel() { return m_error; }
    QPushButton* addWallButton() { return m_addWall; }
    QPushButton* addFloorButton() { return m_addFloor; }
    QPushButton* removeButton() { return m_remove; }
    QPushButton* mapsButton() { return m_maps; }
    QPushButton* importButton() { return m_import; }
    /// Adds `path` (copied into the project's anatomy/ folder unless it is a project file) as an
    /// imported surrounding, its scale from the unit its size suggests: one undo step. Returns the
    /// refusal (empty when added), also shown under the fields.
    QString importFile(const QString& path);
    /// The last import's unit guess ("'liver.obj': 0.18 units long: looks like metres (1 m per unit)").
    const QString& unitGuess() const { return m_guess; }
    int selected() const { return m_selected; }

signals:
    /// The selected primitive changed (-1: none).
    void selectedChanged(int index);
    /// *Material maps…*: the selected primitive's maps are wanted in front.
    void mapsRequested(int index);

private:
    void fill();
    /// The typed value of `key` into the selected primitive, one undo step (or the refusal shown).
    void typed(const QString& key);
    void add(bool wall);
    void remove();
    /// Import mesh…: a file dialog ("sceneryImportDialog"); the file chosen goes to importFile.
    void askImport();
    void show(const QString& why);

    Document* m_doc;
    QListWidget* m_list = nullptr;
    std::map<QString, QLineEdit*> m_fields;
    QComboBox* m_facing = nullptr;
    QLabel* m_error = nullptr;
    QPushButton *m_addWall = nullptr, *m_addFloor = nullptr, *m_remove = nullptr, *m_maps = nullptr,
                *m_import = nullptr;
    QString m_guess;
    int m_selected = -1;
    bool m_filling = false;
};

} // namespace viscera::studio
