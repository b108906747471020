// `volscissors view [FILE] [--script FILE] [--size WxH] [--stereo off|anaglyph|side-by-side|quad]
//                    [--renderer auto|gpu|cpu] [--orientation CODE]`
// The interactive viewer (viewer/): GPU ray casting (the CPU renderer where OpenGL 3.3 is
// missing), linked slice views, the tool rack. Without FILE it opens the embedded head phantom.
// Exit status: 0; 1 for a script error, a file that cannot be read or no window (with --renderer
// gpu: no OpenGL 3.3 context); 2 for bad options.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "args.h"
#include "command.h"
#include "util/error.h"
#include "volume/slice.h"
#ifdef VS_HAVE_VIEWER
#include "app/script.h"
#include "app/viewer_app.h"
#include "window/viewer_window.h"
#endif

namespace {

// The script commands, listed from the interpreter itself.
std::string scriptHelp() {
  std::string text = "replay a script (one command a line: ";
#ifdef VS_HAVE_VIEWER
  for (const std::string& c : vs::viewer::scriptCommands()) {
    if (c != vs::viewer::scriptCommands().front()) text += ", ";
    text += c;
  }
#else
  text += "the viewer was not built";
#endif
  return text + ")";
}

struct Args {
  std::string file, script, size = "1440x900", stereo = "off", renderer = "auto", orientation;
};

const vs::cli::Registration reg{
    "view",
    "interactive viewer: 3D ray casting, slice views, labels; live-wire, tracking, surface and cutting tools "
    "(GLFW + OpenGL 3.3)",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option("file", a->file, "volume to open (default: the embedded head phantom)");
      sub.add_option("--script", a->script, scriptHelp());
      sub.add_option("--size", a->size, "window size WxH in pixels")->capture_default_str();
      sub.add_option("--stereo", a->stereo, "off | anaglyph | side-by-side | quad (quad needs a stereo visual)")
          ->capture_default_str();
      sub.add_option("--renderer", a->renderer,
                     "3D view: auto (the GPU ray caster, or the CPU renderer where OpenGL 3.3 core or its shaders "
                     "fail) | gpu | cpu (the CPU renderer off the UI thread, a legacy OpenGL context)")
          ->check(CLI::IsMember({"auto", "gpu", "cpu"}))
          ->capture_default_str();
      sub.add_option("--orientation", a->orientation,
                     "state where the file's axes point when its header does not say, e.g. LAS (x to patient "
                     "left, y anterior, z superior); default: the header's, else LPS with a warning");
      return [a]() -> int {
#ifdef VS_HAVE_VIEWER
        const auto [w, h] = vs::cli::parseImageSize(a->size, "--size", 8192, 320, 240);
        vs::viewer::ViewerApp app;
        app.setStereo(vs::viewer::stereoFromName(a->stereo));
        if (!a->orientation.empty()) try {
            vs::directionFromOrientationCode(a->orientation);
          } catch (const vs::InvalidArgument& e) {
            throw vs::UsageError(std::string("--orientation: ") + e.what());
          }
        if (!a->script.empty() && std::filesystem::is_directory(a->script))
          throw vs::IoError("script " + a->script + ": is a folder, not a script file");
        if (a->file.empty()) {
          if (!a->orientation.empty()) throw vs::UsageError("--orientation needs a volume file");
          app.loadHeadPhantom();
        } else {
          app.load(a->file, a->orientation);
          if (!app.orientationWarning().empty())
            std::cerr << "volscissors: warning: " << app.orientationWarning() << '\n';
        }
        vs::viewer::WindowOptions wo;
        wo.width = w;
        wo.height = h;
        wo.script = a->script;
        wo.renderer = vs::viewer::rendererFromName(a->renderer);
        return vs::viewer::runViewerWindow(app, wo);
#else
        throw vs::Error(
            "the viewer was not built (it needs libglfw3-dev, libegl-dev and libimgui-dev at configure time)");
#endif
      };
    }};

}  // namespace
