#pragma once
/// The Light samples tool's side-by-side render: the scene as the player would draw it, uniform
/// 1× beside the painted map, each with its error against the many-sample reference near the
/// light and its frame time (render::compareSampling, the bench's measure). It renders off the UI
/// thread in a headless EGL context of its own, with progress and Cancel.
#include "render/sampling_compare.hpp"

#include <QDialog>
#include <QFutureWatcher>

#include <atomic>
#include <memory>
#include <optional>

class QLabel;
class QProgressBar;
class QPushButton;

namespace viscera::studio {

class SampleCompareDialog : public QDialog {
    Q_OBJECT
public:
    explicit SampleCompareDialog(QWidget* parent = nullptr);
    ~SampleCompareDialog() override;

    /// Starts rendering `view` with `settings` (a copy of each is kept); a comparison still running
    /// is cancelled first.
    void start(const render::SceneView& view, const render::RenderSettings& settings);
    void cancel();
    bool running() const { return m_watcher && m_watcher->isRunning(); }
    /// Waits for the comparison (tests and scripted use).
    void waitForFinished();
    /// The last comparison's figures; empty before one finished (or when it failed).
    const std::optional<render::SamplingComparison>& result() const { return m_result; }
    /// The last error (no EGL context, cancelled), empty when it worked.
    const QString& error() const { return m_error; }

signals:
    void finished();

private:
    struct Outcome {
        std::optional<render::SamplingComparison> cmp;
        QString error, device;
    };
    void present(const Outcome& o);

    QLabel *m_uniform = nullptr, *m_painted = nullptr, *m_uniformError = nullptr, *m_paintedError = nullptr,
           *m_uniformText = nullptr, *m_paintedText = nullptr;
    QLabel* m_summary = nullptr;
    QProgressBar* m_bar = nullptr;
    QPushButton* m_cancel = nullptr;
    QFutureWatcher<std::shared_ptr<Outcome>>* m_watcher = nullptr;
    std::shared_ptr<std::atomic<bool>> m_stop;
    std::optional<render::SamplingComparison> m_result;
    QString m_error;
};

} // namespace viscera::studio
