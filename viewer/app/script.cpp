#include "app/script.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "render/window_level.h"

namespace vs::viewer {

namespace {

std::vector<double> numbers(const std::string& text, const std::string& what, size_t count) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw UsageError(what + ": cannot read '" + item + "' as a number");
    out.push_back(v);
  }
  if (count && out.size() != count)
    throw UsageError(what + ": expected " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  return out;
}

int64_t integer(double v, const std::string& what) {
  if (v != std::floor(v)) throw UsageError(what + ": " + std::to_string(v) + " is not an integer index");
  return static_cast<int64_t>(v);
}

double number(const std::string& text, const std::string& what) { return numbers(text, what, 1)[0]; }

}  // namespace

const std::vector<std::string>& scriptCommands() {
  static const std::vector<std::string> names = {
      "load",          "mode",           "tf",           "view",       "zoom",           "window",
      "planes",        "stereo",         "tool",         "slice",      "snap",           "hover",
      "point",         "close",          "undo",         "redo",       "auto-terminals", "trace-cost",
      "surface-level", "surface-closed", "run",          "save",       "session-save",   "session-load",
      "screenshot",    "wait",           "quit",         "cut-iso",    "labels",         "opacity",
      "label",         "tf-save",        "overlay",      "pan",        "pick",           "interact",
      "slice-planes",  "measure",        "profile-path", "profile-arc"};
  return names;
}

bool runScript(ViewerApp& app, std::istream& in, ScriptHost* host, const std::string& name) {
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream ls(line);
    std::string cmd;
    if (!(ls >> cmd)) continue;
    std::vector<std::string> args;
    for (std::string a; ls >> a;) args.push_back(a);
    auto need = [&](size_t n) {
      if (args.size() != n)
        throw UsageError("'" + cmd + "' takes " + std::to_string(n) + " argument" + (n == 1 ? "" : "s") + ", got " +
                         std::to_string(args.size()));
    };
    try {
      if (cmd == "load") {
        need(1);
        app.load(args[0]);
      } else if (cmd == "mode") {
        need(1);
        app.setMode(renderModeFromName(args[0]));
      } else if (cmd == "tf") {
        need(1);
        app.setTransferFunction(args[0]);
      } else if (cmd == "tf-save") {
        need(1);
        app.saveTransferFunction(args[0]);
      } else if (cmd == "view") {
        need(2);
        app.setOrbit(number(args[0], "view azimuth"), number(args[1], "view elevation"));
      } else if (cmd == "zoom") {
        need(1);
        app.setZoom(number(args[0], "zoom"));
      } else if (cmd == "pan") {
        need(2);
        app.setPan(number(args[0], "pan right (mm)"), number(args[1], "pan up (mm)"));
      } else if (cmd == "window") {
        if (args.size() == 1) {  // a preset (render/window_level.h windowPresets)
          std::string names;
          for (const auto& p : windowPresets()) {
            if (args[0] == p.name) {
              app.setWindow(p.wl.window, p.wl.level);
              names.clear();
              break;
            }
            names += std::string(names.empty() ? "" : ", ") + p.name;
          }
          if (!names.empty()) throw UsageError("window: unknown preset '" + args[0] + "' (" + names + ", or W L)");
        } else {
          need(2);
          app.setWindow(number(args[0], "window width"), number(args[1], "window level"));
        }
      } else if (cmd == "planes") {
        need(1);
        const auto v = numbers(args[0], "planes", 3);
        app.setCursor({integer(v[0], "planes"), integer(v[1], "planes"), integer(v[2], "planes")});
      } else if (cmd == "stereo") {
        need(1);
        app.setStereo(stereoFromName(args[0]));
      } else if (cmd == "tool") {
        need(1);
        app.setTool(toolFromName(args[0]));
      } else if (cmd == "slice") {
        need(1);
        const auto [axis, index] = parseSliceSpec(args[0]);
        app.setLiveWireSlice(axis, index);
      } else if (cmd == "snap") {
        need(1);
        app.setSnap(number(args[0], "snap radius"));
      } else if (cmd == "hover" || cmd == "point") {
        need(1);
        const auto v = numbers(args[0], cmd, 0);
        if (v.size() == 2 && (cmd == "hover" || app.tool() == ToolKind::LiveWire)) {
          const PixelUV p{integer(v[0], cmd), integer(v[1], cmd)};
          if (cmd == "hover") {
            if (app.tool() != ToolKind::LiveWire) throw UsageError("hover u,v needs the live-wire tool");
            app.liveWire().hover(p);
          } else {
            app.point2(p);
          }
        } else if (v.size() == 3 && cmd == "point") {
          app.point3({integer(v[0], cmd), integer(v[1], cmd), integer(v[2], cmd)});
        } else {
          throw UsageError("'" + cmd + " " + args[0] + "': give u,v (live-wire, on its slice) or x,y,z (3D tools)");
        }
      } else if (cmd == "close") {
        need(0);
        app.closeContour();
      } else if (cmd == "undo" || cmd == "redo") {
        need(0);
        const bool did = cmd == "undo" ? app.undo() : app.redo();
        if (!did) throw InvalidArgument("nothing to " + cmd + " for the " + toolName(app.tool()) + " tool");
      } else if (cmd == "auto-terminals") {
        need(1);
        app.trace().setAutoTerminals(static_cast<int>(integer(number(args[0], cmd), cmd)));
      } else if (cmd == "trace-cost") {
        if (args.size() != 1 && args.size() != 2) throw UsageError("'trace-cost' takes KIND [bright|dark]");
        if (args.size() == 2 && args[1] != "bright" && args[1] != "dark")
          throw UsageError("trace-cost polarity must be bright or dark");
        app.trace().setCost(args[0], args.size() == 2 && args[1] == "dark" ? TubePolarity::Dark : TubePolarity::Bright);
      } else if (cmd == "surface-level") {
        need(1);
        app.surface().setLevel(static_cast<int>(integer(number(args[0], cmd), cmd)));
      } else if (cmd == "surface-closed") {
        need(1);
        if (args[0] != "on" && args[0] != "off") throw UsageError("surface-closed takes on or off");
        app.surface().setClosed(args[0] == "on");
      } else if (cmd == "cut-iso") {
        need(1);
        app.setCutIso(args[0] == "auto" ? std::nullopt : std::optional<double>(number(args[0], "cut iso-value")));
      } else if (cmd == "labels") {
        need(1);
        app.loadLabels(args[0]);
      } else if (cmd == "overlay") {
        need(1);
        if (args[0] == "clear")
          app.clearOverlays();
        else
          app.addOverlay(args[0]);
      } else if (cmd == "opacity") {
        need(2);
        const double a = number(args[1], "opacity");
        if (args[0] == "labels")
          app.setLabelOpacity(a);
        else if (args[0] == "overlays")
          app.setOverlayOpacity(a);
        else
          throw UsageError("opacity takes labels|overlays A");
      } else if (cmd == "label") {
        need(2);
        if (args[1] != "on" && args[1] != "off") throw UsageError("label N takes on or off");
        app.setLabelVisible(static_cast<int>(integer(number(args[0], "label"), "label")), args[1] == "on");
      } else if (cmd == "run") {
        need(0);
        app.run(/*wait=*/false);
        if (host)
          host->waitForJob(app.job());
        else
          app.job().wait();
        app.finishJob();
      } else if (cmd == "wait") {
        need(0);
        if (host)
          host->waitForJob(app.job());
        else
          app.job().wait();
        app.finishJob();
      } else if (cmd == "save") {
        need(1);
        app.save(args[0]);
      } else if (cmd == "session-save") {
        need(1);
        app.saveSession(args[0]);
      } else if (cmd == "session-load") {
        need(1);
        app.loadSession(args[0]);
      } else if (cmd == "screenshot") {
        need(1);
        if (!host) throw InvalidArgument("screenshot needs a window");
        host->screenshot(args[0]);
      } else if (cmd == "pick") {
        // The stylus in the 3D view at pixel PX,PY (of the window's 3D view, or of a view of
        // WxH pixels): the first visible point, snapped, given to the current 3D tool.
        if (args.size() != 1 && args.size() != 2) throw UsageError("'pick' takes PX,PY [WxH]");
        const auto p = numbers(args[0], "pick", 2);
        std::array<int, 2> size{0, 0};
        if (args.size() == 2) {
          const auto x = args[1].find('x');
          if (x == std::string::npos) throw UsageError("pick: view size '" + args[1] + "' is not WxH");
          size = {int(integer(number(args[1].substr(0, x), "pick width"), "pick")),
                  int(integer(number(args[1].substr(x + 1), "pick height"), "pick"))};
        } else if (host) {
          size = host->view3DSize();
        } else {
          throw InvalidArgument("pick PX,PY needs a window or a view size (pick PX,PY WxH)");
        }
        app.stylusClick(p[0], p[1], size[0], size[1]);
      } else if (cmd == "slice-planes") {
        need(1);
        if (args[0] != "on" && args[0] != "off") throw UsageError("slice-planes takes on or off");
        app.setSlicePlanesIn3D(args[0] == "on");
      } else if (cmd == "measure") {  // the trace's tree measured (app/profile.h)
        need(0);
        measureTraceProfile(app);
      } else if (cmd == "profile-path") {
        need(1);
        app.profile().selectPath(static_cast<int>(integer(number(args[0], cmd), cmd)));
      } else if (cmd == "profile-arc") {
        need(1);
        selectProfileArc(app, number(args[0], "profile-arc (mm)"));
      } else if (cmd == "interact") {
        need(1);
        if (!host) throw InvalidArgument("interact needs a window");
        host->interact(args[0]);
      } else if (cmd == "quit") {
        need(0);
        return true;
      } else {
        throw UsageError("unknown command '" + cmd + "'");
      }
      if (host) host->frame();
    } catch (const Error& e) {
      throw ScriptError(name + ":" + std::to_string(lineNo) + ": " + cmd + ": " + e.what());
    } catch (const std::exception& e) {
      throw ScriptError(name + ":" + std::to_string(lineNo) + ": " + cmd + ": " + e.what());
    }
  }
  return false;
}

bool runScriptFile(ViewerApp& app, const std::string& path, ScriptHost* host) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError("script " + path + ": is a folder, not a script file");
  std::ifstream in(path);
  if (!in) throw IoError("script " + path + ": cannot open");
  return runScript(app, in, host, path);
}

}  // namespace vs::viewer
