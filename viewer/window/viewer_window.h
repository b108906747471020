// The window (layer 3 of viewer/): GLFW + OpenGL 3.3 core + Dear ImGui. A 3D view drawn by the
// GPU ray caster, three linked slice views (axial, coronal, sagittal) with window/level,
// crosshairs and anatomical labels, the tool rack, a help panel, and stereo (anaglyph,
// side-by-side; quad-buffered where the driver offers a stereo visual). Every action goes
// through ViewerApp, as the script interpreter's do.
#pragma once
#include <string>

#include "app/viewer_app.h"

namespace vs::viewer {

struct WindowOptions {
  int width = 1440, height = 900;
  std::string script;  // run after the window opened; the window stays open unless it ends with `quit`
};

// Opens the window and runs until it is closed (or the script quits). Returns the exit status:
// 0, or 1 after a script error (printed to stderr). Throws vs::Error when no window with an
// OpenGL 3.3 context can be opened (no display, old driver), with the reason.
int runViewerWindow(ViewerApp& app, const WindowOptions& options);

}  // namespace vs::viewer
