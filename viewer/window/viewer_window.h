// The window (layer 3 of viewer/): GLFW + OpenGL 3.3 core + Dear ImGui. A 3D view drawn by the
// GPU ray caster, three linked slice views (axial, coronal, sagittal) with window/level,
// crosshairs and anatomical labels, the tool rack, a help panel, and stereo (anaglyph,
// side-by-side; quad-buffered where the driver offers a stereo visual). Every action goes
// through ViewerApp, as the script interpreter's do.
// Without OpenGL 3.3 core (old drivers, remote X) or when the ray caster's shaders fail, the 3D
// view is drawn by the CPU renderer on a worker thread (app/cpu_view.h) in a legacy context with
// ImGui's OpenGL 2 backend; the slice views and tools are unchanged; a note says so in the
// window and on stderr.
#pragma once
#include <string>

#include "app/viewer_app.h"

namespace vs::viewer {

// auto: the GPU ray caster where OpenGL 3.3 core and its shaders work, else the CPU renderer;
// gpu: only the GPU (an error without it); cpu: the CPU renderer in a legacy OpenGL context.
enum class RendererChoice { Auto, Gpu, Cpu };
RendererChoice rendererFromName(const std::string& name);  // "auto", "gpu", "cpu"; UsageError otherwise

struct WindowOptions {
  int width = 1440, height = 900;
  RendererChoice renderer = RendererChoice::Auto;
  std::string script;  // run after the window opened; the window stays open unless it ends with `quit`
};

// Opens the window and runs until it is closed (or the script quits). Returns the exit status:
// 0, or 1 after a script error (printed to stderr). Throws vs::Error when no window can be
// opened (no display), or with --renderer gpu when OpenGL 3.3 core or the ray caster fails, with
// the reason.
int runViewerWindow(ViewerApp& app, const WindowOptions& options);

}  // namespace vs::viewer
