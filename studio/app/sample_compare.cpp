#include "app/sample_compare.hpp"

#include <QCoreApplication>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QImage>
#include <QLabel>
#include <QPixmap>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QtConcurrent/QtConcurrent>

#include <algorithm>
#include <cstdlib>

namespace viscera::studio {
namespace {

/// |reference − image| per channel, ×16 (an 8-bit error of 16 shows white), opaque.
render::Image errorImage(const render::Image& reference, const render::Image& img) {
    render::Image e = img;
    if (reference.rgba.size() != img.rgba.size()) return e;
    for (size_t i = 0; i < e.rgba.size(); ++i)
        e.rgba[i] = i % 4 == 3
                        ? 255
                        : static_cast<uint8_t>(std::min(255, 16 * std::abs(int(reference.rgba[i]) - int(img.rgba[i]))));
    return e;
}

QPixmap pixmapOf(const render::Image& img) {
    if (img.width <= 0 || img.height <= 0) return {};
    QImage q(img.rgba.data(), img.width, img.height, img.width * 4, QImage::Format_RGBA8888);
    return QPixmap::fromImage(q.copy());
}

} // namespace

SampleCompareDialog::SampleCompareDialog(QWidget* parent) : QDialog(parent) {
    setObjectName("sampleCompareDialog");
    setWindowTitle(tr("Light sampling: uniform 1× | painted"));
    auto* grid = new QGridLayout(this);
    m_uniform = new QLabel(this);
    m_painted = new QLabel(this);
    m_uniformText = new QLabel(tr("Uniform 1×"), this);
    m_paintedText = new QLabel(tr("Painted map"), this);
    m_uniformError = new QLabel(this);
    m_paintedError = new QLabel(this);
    m_uniform->setObjectName("compareUniform");
    m_painted->setObjectName("comparePainted");
    for (QLabel* l : {m_uniform, m_painted, m_uniformError, m_paintedError}) {
        l->setMinimumSize(320, 240);
        l->setAlignment(Qt::AlignCenter);
        l->setStyleSheet("background:#202020");
    }
    m_summary = new QLabel(this);
    m_summary->setObjectName("compareSummary");
    m_summary->setWordWrap(true);
    m_bar = new QProgressBar(this);
    m_cancel = new QPushButton(tr("Cancel"), this);
    auto* close = new QPushButton(tr("Close"), this);
    grid->addWidget(m_uniformText, 0, 0);
    grid->addWidget(m_paintedText, 0, 1);
    grid->addWidget(m_uniform, 1, 0);
    grid->addWidget(m_painted, 1, 1);
    auto* errorText = new QLabel(tr("Error against the reference, ×16 (white: 16 or more of 255)"), this);
    grid->addWidget(errorText, 2, 0, 1, 2);
    grid->addWidget(m_uniformError, 3, 0);
    grid->addWidget(m_paintedError, 3, 1);
    grid->addWidget(m_summary, 4, 0, 1, 2);
    grid->addWidget(m_bar, 5, 0);
    grid->setRowStretch(1, 1); // the pictures take the room
    grid->setRowStretch(3, 1);
    auto* buttons = new QHBoxLayout;
    buttons->addStretch(1);
    buttons->addWidget(m_cancel);
    buttons->addWidget(close);
    grid->addLayout(buttons, 5, 1);
    connect(m_cancel, &QPushButton::clicked, this, &SampleCompareDialog::cancel);
    connect(close, &QPushButton::clicked, this, &QDialog::close);
}

SampleCompareDialog::~SampleCompareDialog() {
    if (m_stop) *m_stop = true;
    if (m_watcher) m_watcher->waitForFinished();
}

void SampleCompareDialog::cancel() {
    if (m_stop) *m_stop = true;
}

void SampleCompareDialog::waitForFinished() {
    if (m_watcher) m_watcher->waitForFinished();
    QCoreApplication::processEvents(); // delivers finished()
}

void SampleCompareDialog::start(const render::SceneView& view, const render::RenderSettings& settings) {
    if (m_watcher && m_watcher->isRunning()) {
        *m_stop = true;
        m_watcher->waitForFinished();
    }
    m_stop = std::make_shared<std::atomic<bool>>(false);
    m_result.reset();
    m_error.clear();
    m_bar->setValue(0);
    m_bar->setRange(0, 1);
    m_cancel->setEnabled(true);
    m_summary->setText(tr("Rendering the reference, uniform 1× and the painted map…"));
    if (!m_watcher) {
        m_watcher = new QFutureWatcher<std::shared_ptr<Outcome>>(this);
        connect(m_watcher, &QFutureWatcher<std::shared_ptr<Outcome>>::finished, this, [this] {
            present(*m_watcher->result());
            emit finished();
        });
    }
    auto shared = std::make_shared<const render::SceneView>(view);
    const std::shared_ptr<std::atomic<bool>> stop = m_stop;
    QPointer<QProgressBar> bar = m_bar;
    m_watcher->setFuture(QtConcurrent::run([shared, settings, stop, bar] {
        auto o = std::make_shared<Outcome>();
        try {
            std::string why;
            auto r = render::HeadlessRenderer::create(settings, &why); // its own context, this thread
            if (!r) {
                o->error = QObject::tr("No OpenGL context for the comparison: %1").arg(QString::fromStdString(why));
                return o;
            }
            o->device = QString::fromStdString(r->description());
            r->renderFrame(*shared); // shader compilation and first upload
            o->cmp = render::compareSampling(*r, *shared, settings, 5, [stop, bar](int done, int total) {
                QMetaObject::invokeMethod(
                    bar,
                    [bar, done, total] {
                        if (!bar) return;
                        bar->setRange(0, total);
                        bar->setValue(done);
                    },
                    Qt::QueuedConnection);
                return !*stop;
            });
            if (!o->cmp) o->error = QObject::tr("Cancelled.");
        } catch (const std::exception& e) {
            o->error = QString::fromStdString(e.what());
        }
        return o;
    }));
}

void SampleCompareDialog::present(const Outcome& o) {
    m_cancel->setEnabled(false);
    m_error = o.error;
    m_result = o.cmp;
    if (!o.cmp) {
        m_summary->setText(o.error);
        return;
    }
    const render::SamplingComparison& c = *o.cmp;
    const QSize box = m_uniform->size();
    m_uniform->setPixmap(pixmapOf(c.uniform).scaled(box, Qt::KeepAspectRatio, Qt::SmoothTransformation));
    m_painted->setPixmap(pixmapOf(c.painted).scaled(box, Qt::KeepAspectRatio, Qt::SmoothTransformation));
    m_uniformError->setPixmap(
        pixmapOf(errorImage(c.reference, c.uniform)).scaled(box, Qt::KeepAspectRatio, Qt::SmoothTransformation));
    m_paintedError->setPixmap(
        pixmapOf(errorImage(c.reference, c.painted)).scaled(box, Qt::KeepAspectRatio, Qt::SmoothTransformation));
    m_uniformText->setText(tr("Uniform 1×: RMSE near the light %1, frame %2 ms")
                               .arg(c.rmseNearUniform, 0, 'f', 2)
                               .arg(c.msUniform, 0, 'f', 2));
    m_paintedText->setText(tr("Painted map: RMSE near the light %1, frame %2 ms (%3× the 1× frame)")
                               .arg(c.rmseNearPainted, 0, 'f', 2)
                               .arg(c.msPainted, 0, 'f', 2)
                               .arg(c.msPainted / c.msUniform, 0, 'f', 2));
    m_summary->setText(tr("Against the %1-sample reference (8-bit RMSE) over the %2 pixels nearest the light "
                          "(surface within %3 mm of it) and over all %4 drawn pixels: uniform %5, painted %6. %7")
                           .arg(render::SamplingSettings{}.referenceSamples)
                           .arg(c.nearPixels)
                           .arg(c.nearDistance * 1000.0, 0, 'f', 0)
                           .arg(c.drawnPixels)
                           .arg(c.rmseUniform, 0, 'f', 2)
                           .arg(c.rmsePainted, 0, 'f', 2)
                           .arg(o.device));
}

} // namespace viscera::studio
