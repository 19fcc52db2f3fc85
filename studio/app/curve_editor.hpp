#pragma once
/// Editor of one Valanis–Landel response curve (f′, g′ or h′) [A §4.3.3, Fig. 4.7]: the curve
/// and its control points on a grid, in data units (x: stretch or stretch product, y: Pa).
///
/// Mouse and keys: a left click on a point selects it and a drag moves it (free: the neighbours it
/// would pass are pushed along, so the curve stays valid instead of the point stopping); a left click near
/// the curve (within kPickPixels) inserts a point there, on the curve; Delete removes the
/// selected point (not an end point, not the rest point); Ctrl during a drag snaps to the grid;
/// Home frames all points; the wheel zooms about the cursor; a middle drag pans.
///
/// The editor never changes the model: it asks (signals) and the owner pushes undo commands,
/// then shows the result with setCurve(). What it asks for already obeys the shape rule: x
/// strictly increasing and, on a strictly increasing curve, y too; the rest point x = 1 is pinned
/// (its value f′(1), g′(1) or h′(1) is what keeps the stress at rest zero, §4.3.3). A drag
/// (dragged()) moves the point where the mouse is and pushes the neighbours it would pass, from
/// the curve as it was when the drag began (moving back restores them); only the rest point
/// stops it. A typed value (constrain()) must lie between its neighbours.
#include "sim/material/curve.hpp"

#include <QPointF>
#include <QRectF>
#include <QString>
#include <QWidget>

#include <optional>
#include <vector>

namespace viscera::studio {

class CurveEditor : public QWidget {
    Q_OBJECT
public:
    static constexpr double kPickPixels = 7.0;

    explicit CurveEditor(QWidget* parent = nullptr);
    /// 240 × 160 wanted; 240 × 110 at least, so the main window with every dock open fits a
    /// 1920 × 1080 screen.
    QSize sizeHint() const override { return {240, 160}; }

    /// Shows `points` (x strictly increasing). Keeps the selection when the count is unchanged
    /// and the view when `frame` is false.
    void setCurve(const QString& name, const std::vector<sim::CurvePoint>& points, bool strictlyIncreasing,
                  bool frame = false);
    /// No curve (the term is absent or the material has no curves): shows `message`.
    void clearCurve(const QString& name, const QString& message);

    const QString& name() const { return m_name; }
    const std::vector<sim::CurvePoint>& points() const { return m_points; }
    bool strictlyIncreasing() const { return m_strict; }
    bool hasCurve() const { return !m_points.empty(); }
    int selected() const { return m_selected; }
    void setSelected(int index);

    /// The point at x = 1 (rest) is pinned.
    static bool isRestPoint(const sim::CurvePoint& p) { return p.x == 1.0; }
    bool removable(int index) const;
    /// The position nearest to `want` that point `index` may take by the shape rule, its
    /// neighbours staying where they are.
    QPointF constrain(int index, QPointF want) const;
    /// The curve `base` after point `index` moved as near `want` as the shape rule allows, the
    /// neighbours it would pass pushed along (a gap of 1e-6 relative); the pinned rest point stays
    /// and bounds the move. x stays at least 0.01 (stretches and volume ratios are positive).
    static std::vector<sim::CurvePoint> dragged(const std::vector<sim::CurvePoint>& base, int index, QPointF want,
                                                bool strictlyIncreasing);

    void frameAll();
    QRectF view() const { return m_view; } ///< data rectangle shown
    QPointF toWidget(QPointF data) const;
    QPointF toData(QPointF widget) const;
    /// Grid spacing in data units (what Ctrl snaps to).
    double gridStepX() const;
    double gridStepY() const;
    /// The curve's value at x (the interpolant of the points), NaN without a curve.
    double curveValue(double x) const;

signals:
    void selectionChanged(int index);
    /// A drag begins on point `index` (the owner starts one undo step).
    void dragStarted(int index);
    /// The curve should become `points` (point `index` dragged, its neighbours pushed; valid).
    void curveDragged(int index, const std::vector<sim::CurvePoint>& points);
    void dragFinished(int index);
    void insertRequested(double x, double y);
    void removeRequested(int index);

protected:
    void paintEvent(QPaintEvent*) override;
    void mousePressEvent(QMouseEvent*) override;
    void mouseMoveEvent(QMouseEvent*) override;
    void mouseReleaseEvent(QMouseEvent*) override;
    void wheelEvent(QWheelEvent*) override;
    void keyPressEvent(QKeyEvent*) override;
    void resizeEvent(QResizeEvent*) override;

private:
    QRectF plotArea() const;
    /// Every point lies in the view.
    bool inView() const;
    int pointAt(QPointF widgetPos) const;
    static double niceStep(double range);

    QString m_name, m_message;
    std::vector<sim::CurvePoint> m_points;
    std::vector<sim::CurvePoint> m_dragBase; ///< the curve when the drag began
    std::optional<sim::MonotoneCurve> m_curve;
    bool m_strict = true;
    int m_selected = -1;
    int m_dragging = -1;
    bool m_panning = false;
    QPointF m_panStart;
    QRectF m_panView;
    QRectF m_view{0.0, -1.0, 3.0, 2.0};
};

} // namespace viscera::studio
