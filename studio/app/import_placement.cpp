#include "app/import_placement.hpp"

#include "app/number_text.hpp"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>

#include <algorithm>
#include <limits>

namespace viscera::studio {
namespace {

constexpr bake::LengthUnit kUnits[] = {bake::LengthUnit::Metre, bake::LengthUnit::Centimetre,
                                       bake::LengthUnit::Millimetre, bake::LengthUnit::Inch};

QString unitLong(bake::LengthUnit u) {
    return QString::fromUtf8(bake::unitLongName(u).data(), int(bake::unitLongName(u).size()));
}

} // namespace

Eigen::Vector3d placedSize(const std::array<Eigen::Vector3d, 2>& bounds, const bake::ImportPlacement& p) {
    const Eigen::Matrix3d r = p.rotation();
    const double s = p.metresPerFileUnit();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3d corner((c & 1 ? bounds[1] : bounds[0]).x(), (c & 2 ? bounds[1] : bounds[0]).y(),
                                     (c & 4 ? bounds[1] : bounds[0]).z());
        const Eigen::Vector3d q = r * (s * corner);
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
    return hi - lo;
}

QString sizeText(const Eigen::Vector3d& size) {
    return QStringLiteral("%1 × %2 × %3 m")
        .arg(numberText(size.x(), 3), numberText(size.y(), 3), numberText(size.z(), 3));
}

ImportPlacementDialog::ImportPlacementDialog(const std::array<Eigen::Vector3d, 2>& bounds, int parts, QWidget* parent)
    : QDialog(parent), m_bounds(bounds), m_guess(bake::guessLengthUnit((bounds[1] - bounds[0]).maxCoeff())) {
    setObjectName("importPlacementDialog");
    setWindowTitle(tr("Import anatomy: unit, scale and rotation"));
    auto* guess = new QLabel(this);
    guess->setObjectName("unitGuess");
    bake::ImportPlacement guessed;
    guessed.unit = m_guess;
    guess->setText(tr("%n part(s); the files carry no unit. Looks like %1: %2 m long", nullptr, parts)
                       .arg(unitLong(m_guess), numberText(placedSize(bounds, guessed).maxCoeff(), 3)));
    m_unit = new QComboBox(this);
    m_unit->setObjectName("importUnit");
    for (bake::LengthUnit u : kUnits)
        m_unit->addItem(QStringLiteral("%1 (%2)").arg(QString::fromUtf8(bake::unitName(u).data()), unitLong(u)));
    m_unit->setCurrentIndex(int(m_guess));
    m_scale = new QDoubleSpinBox(this);
    m_scale->setObjectName("importScale");
    m_scale->setDecimals(6);
    m_scale->setRange(1e-6, 1e6);
    m_scale->setValue(1.0);
    auto* rotationRow = new QHBoxLayout;
    const char* axes[] = {"rotationX", "rotationY", "rotationZ"};
    for (int k = 0; k < 3; ++k) {
        m_rotation[size_t(k)] = new QDoubleSpinBox(this);
        m_rotation[size_t(k)]->setObjectName(axes[k]);
        m_rotation[size_t(k)]->setRange(-360, 360);
        m_rotation[size_t(k)]->setDecimals(3);
        m_rotation[size_t(k)]->setSuffix(QStringLiteral("°"));
        rotationRow->addWidget(new QLabel(QString(QLatin1Char(char('x' + k))), this));
        rotationRow->addWidget(m_rotation[size_t(k)]);
        connect(m_rotation[size_t(k)], &QDoubleSpinBox::valueChanged, this, &ImportPlacementDialog::updateSize);
    }
    auto* yUp = new QPushButton(tr("Y-up → Z-up"), this);
    yUp->setObjectName("yUpToZUp");
    yUp->setToolTip(tr("Most modelling tools export Y up; the studio's scenes have Z up: 90° about x"));
    connect(yUp, &QPushButton::clicked, this, [this] {
        m_rotation[0]->setValue(90);
        m_rotation[1]->setValue(0);
        m_rotation[2]->setValue(0);
    });
    rotationRow->addWidget(yUp);
    m_size = new QLabel(this);
    m_size->setObjectName("importSize");
    connect(m_unit, &QComboBox::currentIndexChanged, this, &ImportPlacementDialog::updateSize);
    connect(m_scale, &QDoubleSpinBox::valueChanged, this, &ImportPlacementDialog::updateSize);
    auto* form = new QFormLayout;
    form->addRow(tr("Length unit of the files"), m_unit);
    form->addRow(tr("Uniform scale"), m_scale);
    form->addRow(tr("Rotation (about x, then y, then z)"), rotationRow);
    form->addRow(tr("The body will be"), m_size);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Cancel, this);
    QPushButton* ok = buttons->addButton(tr("Import"), QDialogButtonBox::AcceptRole);
    ok->setObjectName("importButton");
    ok->setDefault(true);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    auto* layout = new QVBoxLayout(this);
    layout->addWidget(guess);
    layout->addLayout(form);
    layout->addWidget(buttons);
    updateSize();
}

bake::ImportPlacement ImportPlacementDialog::placement() const {
    bake::ImportPlacement p;
    p.unit = kUnits[std::clamp(m_unit->currentIndex(), 0, 3)];
    p.scale = m_scale->value();
    for (int k = 0; k < 3; ++k)
        p.rotationDeg[k] = m_rotation[size_t(k)]->value();
    return p;
}

void ImportPlacementDialog::updateSize() {
    const Eigen::Vector3d size = placedSize(m_bounds, placement());
    QString text = sizeText(size);
    if (size.maxCoeff() > 1.0)
        text += tr(" — longer than any organ: is the unit right?");
    else if (size.maxCoeff() < 0.005)
        text += tr(" — smaller than 5 mm: is the unit right?");
    m_size->setText(text);
}

} // namespace viscera::studio
