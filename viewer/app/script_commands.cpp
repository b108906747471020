// The script language's command table (script.h): one row per command, its arguments, what it
// does and the ViewerApp call it makes. The interpreter (script.cpp), `view --help` and the
// tests read the command names from here.
#include <array>
#include <cmath>
#include <optional>

#include "app/script.h"
#include "render/window_level.h"
#include "util/text.h"

namespace vs::viewer {

namespace {

std::vector<double> numbers(const std::string& text, const std::string& what, size_t count) {
  std::vector<double> out;
  for (const std::string& item : splitText(text, ',')) {  // the CLI's parser (util/text.h)
    double v = 0;
    if (!parseNumber(item, v)) throw UsageError(what + ": cannot read '" + item + "' as a number");
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

bool onOff(const std::string& arg, const std::string& message) {
  if (arg != "on" && arg != "off") throw UsageError(message);
  return arg == "on";
}

using Args = std::vector<std::string>;

void window(ViewerApp& app, const Args& args) {
  if (args.size() == 1) {  // a preset (render/window_level.h windowPresets)
    std::string names;
    for (const auto& p : windowPresets()) {
      if (args[0] == p.name) {
        app.setWindow(p.wl.window, p.wl.level);
        return;
      }
      names += std::string(names.empty() ? "" : ", ") + p.name;
    }
    throw UsageError("window: unknown preset '" + args[0] + "' (" + names + ", or W L)");
  }
  requireArgs("window", args, 2);
  app.setWindow(number(args[0], "window width"), number(args[1], "window level"));
}

void hoverOrPoint(ViewerApp& app, const std::string& cmd, const Args& args) {
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
}

void waitForJob(ViewerApp& app, ScriptHost* host) {
  if (host)
    host->waitForJob(app.job());
  else
    app.job().wait();
  app.finishJob();
}

// The stylus in the 3D view at pixel PX,PY (of the window's 3D view, or of a view of WxH
// pixels): the first visible point, snapped, given to the current 3D tool.
void pick(ViewerApp& app, ScriptHost* host, const Args& args) {
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
}

void opacity(ViewerApp& app, const Args& args) {
  const double a = number(args[1], "opacity");
  if (args[0] == "labels")
    app.setLabelOpacity(a);
  else if (args[0] == "overlays")
    app.setOverlayOpacity(a);
  else
    throw UsageError("opacity takes labels|overlays A");
}

void traceCost(ViewerApp& app, const Args& args) {
  if (args.size() != 1 && args.size() != 2) throw UsageError("'trace-cost' takes KIND [bright|dark]");
  if (args.size() == 2 && args[1] != "bright" && args[1] != "dark")
    throw UsageError("trace-cost polarity must be bright or dark");
  // A polarity the chosen cost does not use is an error (as the CLI's --polarity; it would change nothing).
  if (args.size() == 2 && args[0] != "vesselness" && args[0] != "intensity")
    throw UsageError("trace-cost: the polarity applies to vesselness or intensity; " + args[0] +
                     (args[0] == "auto" ? " (the default) estimates its own lumen model and" : "") +
                     " does not use it");
  app.trace().setCost(args[0], args.size() == 2 && args[1] == "dark" ? TubePolarity::Dark : TubePolarity::Bright);
}

// cut-weights KEY=V ... (any of cutWeightNames, the rest kept) or `defaults` (the core's).
void cutWeights(ViewerApp& app, const Args& args) {
  if (args.empty())
    throw UsageError("'cut-weights' takes KEY=V ... (wg wc wp wd contour-wg contour-wn contour-wl) or defaults");
  if (args.size() == 1 && args[0] == "defaults") {
    app.cut().setWeights(defaultCutWeights());
    return;
  }
  CutWeights w = app.cut().weights();
  for (const std::string& a : args) {
    const auto eq = a.find('=');
    const std::string key = a.substr(0, eq);
    const CutWeightName* name = nullptr;
    for (const CutWeightName& n : cutWeightNames())
      if (key == n.key) name = &n;
    if (eq == std::string::npos || !name)
      throw UsageError("cut-weights: '" + a +
                       "' is not KEY=V with KEY one of wg wc wp wd contour-wg contour-wn contour-wl");
    w.*name->field = number(a.substr(eq + 1), "cut-weights " + key);
  }
  app.cut().setWeights(w);
}

// anchor-insert u,v | anchor-move K u,v | anchor-delete K: the live-wire's anchor edits.
LiveWireTool& editableWire(ViewerApp& app, const std::string& cmd) {
  if (app.tool() != ToolKind::LiveWire) throw UsageError("'" + cmd + "' needs the live-wire tool (tool livewire)");
  return app.liveWire();
}

PixelUV pixel(const std::string& text, const std::string& cmd) {
  const auto v = numbers(text, cmd, 2);
  return {integer(v[0], cmd), integer(v[1], cmd)};
}

size_t anchorIndex(const std::string& text, const std::string& cmd) {
  const int64_t k = integer(number(text, cmd + " anchor"), cmd);
  if (k < 0) throw UsageError(cmd + ": anchor " + text + " is not an index 0, 1, ...");
  return size_t(k);
}

// mono-plane x|y|z[=K]: the monoplanar mode's plane across that axis, moved to index K (the
// linked cursor, which the plane goes through).
void monoPlane(ViewerApp& app, const std::string& arg) {
  const std::string axes = "xyz";
  const auto a = arg.empty() ? std::string::npos : axes.find(arg[0]);
  if (a == std::string::npos || (arg.size() > 1 && arg[1] != '='))
    throw UsageError("mono-plane takes x, y or z, optionally =K (e.g. x=40), got '" + arg + "'");
  if (arg.size() > 1) {
    Index3 c = app.view().cursor;
    c[a] = integer(number(arg.substr(2), "mono-plane index"), "mono-plane");
    app.setCursor(c);
  }
  app.setMonoAxis(int(a));
}

Index3 voxel(const std::string& text, const std::string& cmd) {
  const auto v = numbers(text, cmd, 3);
  return {integer(v[0], cmd), integer(v[1], cmd), integer(v[2], cmd)};
}

// surface-corner +x|-x|+y|-y|+z|-z x,y,z | surface-corner clear
void surfaceCorner(ViewerApp& app, const Args& args) {
  if (args.size() == 1 && args[0] == "clear") {
    app.surface().clearCorners();
    return;
  }
  if (args.size() != 2) throw UsageError("'surface-corner' takes +x|-x|+y|-y|+z|-z x,y,z, or clear");
  app.surface().setCorner(SurfaceTool::halfLineFromName(args[0]), voxel(args[1], "surface-corner"));
}

constexpr int kAnyArgs = -1;  // the action checks its own arguments

}  // namespace

void requireArgs(const std::string& cmd, const std::vector<std::string>& args, size_t n) {
  if (args.size() != n)
    throw UsageError("'" + cmd + "' takes " + std::to_string(n) + " argument" + (n == 1 ? "" : "s") + ", got " +
                     std::to_string(args.size()));
}

const std::vector<ScriptCommand>& scriptCommandTable() {
  using C = ScriptCall;
  static const std::vector<ScriptCommand> table = {
      {"load", "PATH", "open a volume file or folder", 1, [](C c) { c.app.load(c.args[0]); }},
      {"mode", "full|cutbox|triplanar|monoplanar|mip", "the 3D view's display mode", 1,
       [](C c) { c.app.setMode(renderModeFromName(c.args[0])); }},
      {"tf", "PRESET|FILE", "transfer function", 1, [](C c) { c.app.setTransferFunction(c.args[0]); }},
      {"view", "AZ EL", "orbit the camera (degrees)", 2,
       [](C c) { c.app.setOrbit(number(c.args[0], "view azimuth"), number(c.args[1], "view elevation")); }},
      {"zoom", "Z", "3D zoom factor", 1, [](C c) { c.app.setZoom(number(c.args[0], "zoom")); }},
      {"window", "W L|PRESET", "grey window width and level, or a preset", kAnyArgs,
       [](C c) { window(c.app, c.args); }},
      {"planes", "x,y,z", "the cursor (slice planes)", 1,
       [](C c) {
         const auto v = numbers(c.args[0], "planes", 3);
         c.app.setCursor({integer(v[0], "planes"), integer(v[1], "planes"), integer(v[2], "planes")});
       }},
      {"mono-plane", "x|y|z[=K]", "the monoplanar mode's plane: across axis x, y or z, at index K", 1,
       [](C c) { monoPlane(c.app, c.args[0]); }},
      {"stereo", "off|anaglyph|side-by-side|quad", "stereo mode", 1,
       [](C c) { c.app.setStereo(stereoFromName(c.args[0])); }},
      {"tool", "livewire|trace|surface|cut|none", "the current tool", 1,
       [](C c) { c.app.setTool(toolFromName(c.args[0])); }},
      {"slice", "z=K", "the live-wire's slice (x=, y=, z=)", 1,
       [](C c) {
         const auto [axis, index] = parseSliceSpec(c.args[0]);
         c.app.setLiveWireSlice(axis, index);
       }},
      {"snap", "R", "live-wire snap radius", 1, [](C c) { c.app.setSnap(number(c.args[0], "snap radius")); }},
      {"hover", "u,v", "the live-wire's live path to a pixel of its slice", 1,
       [](C c) { hoverOrPoint(c.app, c.cmd, c.args); }},
      {"point", "u,v|x,y,z", "a point of the current tool", 1, [](C c) { hoverOrPoint(c.app, c.cmd, c.args); }},
      {"close", "", "close the live-wire contour", 0, [](C c) { c.app.closeContour(); }},
      {"anchor-insert", "u,v", "live-wire: a new anchor at u,v in the contour segment passing nearest to it", 1,
       [](C c) { editableWire(c.app, c.cmd).insertAnchor(pixel(c.args[0], c.cmd)); }},
      {"anchor-move", "K u,v", "live-wire: anchor K (0 = the first) moved to u,v, its segments re-wired", 2,
       [](C c) { editableWire(c.app, c.cmd).moveAnchor(anchorIndex(c.args[0], c.cmd), pixel(c.args[1], c.cmd)); }},
      {"anchor-delete", "K", "live-wire: anchor K removed, its neighbours joined by one path", 1,
       [](C c) { editableWire(c.app, c.cmd).removeAnchor(anchorIndex(c.args[0], c.cmd)); }},
      {"livewire-cooling", "N", "live-wire path cooling: freeze what stayed the same over N mouse moves (0 = off)", 1,
       [](C c) { c.app.liveWire().setCooling(int(integer(number(c.args[0], c.cmd), c.cmd))); }},
      {"undo", "", "undo the current tool's last step", 0,
       [](C c) {
         if (!c.app.undo()) throw InvalidArgument("nothing to undo for the " + toolName(c.app.tool()) + " tool");
       }},
      {"redo", "", "redo the current tool's last undone step", 0,
       [](C c) {
         if (!c.app.redo()) throw InvalidArgument("nothing to redo for the " + toolName(c.app.tool()) + " tool");
       }},
      {"auto-terminals", "N", "trace: automatic terminals", 1,
       [](C c) { c.app.trace().setAutoTerminals(static_cast<int>(integer(number(c.args[0], c.cmd), c.cmd))); }},
      {"trace-cost", "auto|gradient|vesselness|intensity [bright|dark]", "trace: the node cost", kAnyArgs,
       [](C c) { traceCost(c.app, c.args); }},
      {"surface-level", "N", "surface: subdivision level", 1,
       [](C c) { c.app.surface().setLevel(static_cast<int>(integer(number(c.args[0], c.cmd), c.cmd))); }},
      {"surface-closed", "on|off", "surface: closed object", 1,
       [](C c) { c.app.surface().setClosed(onOff(c.args[0], "surface-closed takes on or off")); }},
      {"surface-corner", "+x|-x|+y|-y|+z|-z x,y,z|clear",
       "surface: the corner on that half-line from the centre, for the next run (clear: the defaults)", kAnyArgs,
       [](C c) { surfaceCorner(c.app, c.args); }},
      {"surface-side", "NAME", "surface: the side contour via points go to (z+x+y: plane z, x >= x0, y >= y0)", 1,
       [](C c) { c.app.surface().selectSide(c.args[0]); }},
      {"surface-via", "x,y,z|clear",
       "surface: a point the chosen side must pass through; the next run re-subdivides only its octants", 1,
       [](C c) {
         if (c.args[0] == "clear")
           c.app.surface().clearVia();
         else
           c.app.surface().addVia(voxel(c.args[0], c.cmd));
       }},
      {"run", "", "run the current tool's job and wait for it", 0,
       [](C c) {
         c.app.run(/*wait=*/false);
         waitForJob(c.app, c.host);
       }},
      {"save", "PATH", "save the current tool's result", 1, [](C c) { c.app.save(c.args[0]); }},
      {"session-save", "PATH", "save the session", 1, [](C c) { c.app.saveSession(c.args[0]); }},
      {"session-load", "PATH", "load a session", 1, [](C c) { c.app.loadSession(c.args[0]); }},
      {"screenshot", "PATH", "the window as PNG", 1,
       [](C c) {
         if (!c.host) throw InvalidArgument("screenshot needs a window");
         c.host->screenshot(c.args[0]);
       }},
      {"wait", "", "wait for the running job", 0, [](C c) { waitForJob(c.app, c.host); }},
      {"quit", "", "end the session", 0, [](C) {}},
      {"cut-iso", "V|auto", "cut: the object's iso-value", 1,
       [](C c) {
         c.app.setCutIso(c.args[0] == "auto" ? std::nullopt
                                             : std::optional<double>(number(c.args[0], "cut iso-value")));
       }},
      {"cut-weights", "KEY=V ...|defaults",
       "cut: weights wg wc wp wd (cutting surface) contour-wg contour-wn contour-wl (as cut --wg ...)", kAnyArgs,
       [](C c) { cutWeights(c.app, c.args); }},
      {"labels", "PATH", "a label volume blended into the views", 1, [](C c) { c.app.loadLabels(c.args[0]); }},
      {"opacity", "labels|overlays A", "opacity of the labels or overlays", 2, [](C c) { opacity(c.app, c.args); }},
      {"label", "N on|off", "show or hide one label", 2,
       [](C c) {
         const bool on = onOff(c.args[1], "label N takes on or off");
         c.app.setLabelVisible(static_cast<int>(integer(number(c.args[0], "label"), "label")), on);
       }},
      {"tf-save", "FILE", "save the transfer function", 1, [](C c) { c.app.saveTransferFunction(c.args[0]); }},
      {"overlay", "PATH|clear", "add an overlay file, or remove them all", 1,
       [](C c) {
         if (c.args[0] == "clear")
           c.app.clearOverlays();
         else
           c.app.addOverlay(c.args[0]);
       }},
      {"pan", "X Y", "the 3D picture moved X mm right, Y mm up (0 0 centres it)", 2,
       [](C c) { c.app.setPan(number(c.args[0], "pan right (mm)"), number(c.args[1], "pan up (mm)")); }},
      {"cut-box", "x0,y0,z0,x1,y1,z1|auto", "the cut-box mode's box (voxel index), or auto (below the cursor)", 1,
       [](C c) {
         if (c.args[0] == "auto") return c.app.setCutBox(std::nullopt);
         const auto v = numbers(c.args[0], "cut-box", 6);
         c.app.setCutBox(std::array<double, 6>{v[0], v[1], v[2], v[3], v[4], v[5]});
       }},
      {"pick", "PX,PY [WxH]", "the stylus at a pixel of the 3D view: a point for the trace, surface or cut tool",
       kAnyArgs, [](C c) { pick(c.app, c.host, c.args); }},
      {"interact", "KEY", "real input events until KEY (e.g. F12) is pressed", 1,
       [](C c) {
         if (!c.host) throw InvalidArgument("interact needs a window");
         c.host->interact(c.args[0]);
       }},
      {"slice-planes", "on|off", "the slice planes in the 3D view", 1,
       [](C c) { c.app.setSlicePlanesIn3D(onOff(c.args[0], "slice-planes takes on or off")); }},
      {"measure", "", "the traced tree's cross-sections (quantify/quantify.h) for the profile plot", 0,
       [](C c) { measureTraceProfile(c.app); }},
      {"profile-path", "K", "the path the profile plot shows", 1,
       [](C c) {
         c.app.profile().selectPath(static_cast<int>(integer(number(c.args[0], "profile-path"), "profile-path")));
       }},
      {"profile-arc", "MM", "the section nearest MM from the root on that path: highlighted, the cursor moved there", 1,
       [](C c) { selectProfileArc(c.app, number(c.args[0], "profile-arc (mm)")); }},
      {"color-by", "diameter|none",
       "the traced tree coloured by its measured diameter (as render --color-by), with a legend; none: one colour", 1,
       [](C c) { setTreeColouring(c.app, c.args[0]); }},
  };
  return table;
}

const std::vector<std::string>& scriptCommands() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const ScriptCommand& c : scriptCommandTable()) out.push_back(c.name);
    return out;
  }();
  return names;
}

const ScriptCommand* findScriptCommand(const std::string& name) {
  for (const ScriptCommand& c : scriptCommandTable())
    if (name == c.name) return &c;
  return nullptr;
}

}  // namespace vs::viewer
