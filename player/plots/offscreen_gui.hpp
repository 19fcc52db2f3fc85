#pragma once
/// An offscreen QGuiApplication (fonts for QPainter on a QImage) when the process has none.
namespace viscera::player {

/// Makes one on first call, kept for the life of the process; no display is needed.
void ensureOffscreenGui();

} // namespace viscera::player
