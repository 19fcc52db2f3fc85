#pragma once
/// Import anatomy's second question, asked once the parts passed the import check and before
/// anything enters the model: in which length unit the files are, a uniform scale and a rotation
/// (bake::ImportPlacement, stored in the body's remesh block). The unit starts at a guess from
/// the parts' size (bake::guessLengthUnit), said as "looks like centimetres: 0.064 m long"; the
/// body's size in metres follows every change, so a file in the wrong unit is seen here and not
/// as millions of tets at meshing.
#include "bake/import.hpp"

#include <QDialog>
#include <QString>

#include <array>
#include <optional>

class QComboBox;
class QDoubleSpinBox;
class QLabel;

namespace viscera::studio {

/// The size (x, y, z extents) of the box `bounds` (file units) once placed by `p`: its corners
/// scaled and rotated. Exact for quarter turns; for other angles the box around the turned box.
Eigen::Vector3d placedSize(const std::array<Eigen::Vector3d, 2>& bounds, const bake::ImportPlacement& p);

/// "0.12 × 0.08 × 0.06 m".
QString sizeText(const Eigen::Vector3d& size);

class ImportPlacementDialog : public QDialog {
    Q_OBJECT
public:
    /// `bounds`: the parts' box in file units; `parts`: how many files.
    ImportPlacementDialog(const std::array<Eigen::Vector3d, 2>& bounds, int parts, QWidget* parent);

    bake::ImportPlacement placement() const;
    /// The guess the dialog opened with.
    bake::LengthUnit guessedUnit() const { return m_guess; }

private:
    void updateSize();

    std::array<Eigen::Vector3d, 2> m_bounds;
    bake::LengthUnit m_guess;
    QComboBox* m_unit = nullptr;
    QDoubleSpinBox* m_scale = nullptr;
    std::array<QDoubleSpinBox*, 3> m_rotation{};
    QLabel* m_size = nullptr;
};

} // namespace viscera::studio
