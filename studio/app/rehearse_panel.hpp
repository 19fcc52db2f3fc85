#pragma once
/// The Rehearse dock (issue 57 item 3): run the case in the viewport as the player runs it and
/// see its verdict; keep the session as the case's reference replay.
///
/// Device: a player --device spec, typed or picked (keyboard, the project's replays, the scripted
/// motions, the console); Frames (auto: a replay's length, 300 for a script, until Stop for the
/// keyboard and the console). Rehearse exports the model and runs it (Rehearsal); Stop ends it.
/// While a keyboard rehearsal runs, the viewport's keys and mouse drive the left master (arrows,
/// Page Up/Down, Space: clutch, C: camera pedal; a left drag moves x/y and the wheel z; Alt + drag
/// still orbits). The verdict and the assessment's lines show when the session ends. Keep as
/// reference replay writes the recorded device as replays/<name>.csv of the project and runs it
/// again in lockstep: the verdict shown then is the one `viscera-player run --device
/// replay:<file>` and the case's replay test give.
#include <QWidget>

#include <memory>

class QComboBox;
class QLabel;
class QLineEdit;
class QPlainTextEdit;
class QPushButton;
class QSpinBox;

namespace viscera::studio {

class Document;
class Rehearsal;
class Viewport;

class RehearsePanel : public QWidget {
    Q_OBJECT
public:
    RehearsePanel(Document* doc, QWidget* parent = nullptr);
    ~RehearsePanel() override;

    Rehearsal* rehearsal() { return m_rehearsal; }
    /// Where the session is drawn and whose keys and mouse drive the keyboard device (null: none).
    void connectViewport(Viewport* v);
    /// Starts a rehearsal with the device and frames in the fields; false (and the rule shown)
    /// when it cannot start.
    bool start();
    /// Keeps the last session as replays/<name in the field>.csv and rehearses that replay.
    bool keep();
    /// The device list again (the project's replays may have changed).
    void refreshDevices();

    QComboBox* deviceBox() const { return m_device; }
    QSpinBox* framesBox() const { return m_frames; }
    QLineEdit* replayName() const { return m_name; }
    QLabel* status() const { return m_status; }
    QLabel* verdict() const { return m_verdict; }
    QPlainTextEdit* summary() const { return m_summary; }
    QPushButton* startButton() const { return m_start; }
    QPushButton* stopButton() const { return m_stop; }
    QPushButton* keepButton() const { return m_keep; }

signals:
    /// A rehearsal began (the viewport shows it) or ended (the preview's scene comes back).
    void activeChanged(bool on);
    void refused(const QString& why);

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;

private:
    void onFinished(bool ok);
    void showScene();
    void syncButtons();
    bool keyboardEvent(QEvent* event);

    Document* m_doc;
    Rehearsal* m_rehearsal;
    Viewport* m_viewport = nullptr;
    QObject* m_canvas = nullptr; ///< the viewport surface the filter is on
    QComboBox* m_device;
    QLineEdit* m_pairingKey;
    QSpinBox* m_frames;
    QPushButton *m_start, *m_stop, *m_keep;
    QLineEdit* m_name;
    QLabel *m_status, *m_verdict;
    QPlainTextEdit* m_summary;
    QPoint m_mouse;
    bool m_dragging = false;
    bool m_replayingKept = false; ///< the session running is the replay just kept
};

} // namespace viscera::studio
