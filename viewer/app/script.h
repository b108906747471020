// Script replay (`volscissors view --script FILE`): one command a line, `#` starts a comment.
// Every command calls the same ViewerApp method as the mouse or the panel does, so a script is a
// reproducible session (demos, tests). Coordinates are 0-based voxel indices (x,y,z) or, for the
// live-wire, pixels (u,v) of its slice.
//   load PATH | mode full|cutbox|triplanar|monoplanar|mip | tf PRESET|FILE | tf-save FILE | view AZ EL | zoom Z
//   pan X Y (the 3D picture moved X mm right, Y mm up at the volume's centre; 0 0 centres it)
//   window W L|ct-brain|ct-subdural|ct-abdomen|ct-lung|ct-bone | planes x,y,z | stereo off|anaglyph|side-by-side|quad |
//   tool livewire|trace|surface|cut|none surface-level N | surface-closed on|off | cut-iso V|auto labels PATH | overlay
//   PATH|clear | opacity labels|overlays A | label N on|off slice z=K (x=, y=) | snap R | hover u,v | point u,v | point
//   x,y,z | close | undo | redo auto-terminals N | trace-cost auto|gradient|vesselness|intensity [bright|dark] | run |
//   save PATH | session-save PATH | session-load PATH | screenshot PATH (.png) | wait (for the running job) | quit pick
//   PX,PY [WxH] (the stylus at a pixel of the 3D view: a point for the trace, surface or cut tool) interact KEY (real
//   input events until KEY, e.g. F12, is pressed)
//   measure (the traced tree's cross-sections, quantify/quantify.h) | profile-path K (the path the profile
//   plot shows) | profile-arc MM (the section nearest MM from the root on it: highlighted, the cursor moved there) |
//   color-by diameter|none (the tree coloured by the measured diameter, with a legend) | cut-weights
//   KEY=V ...|defaults (the cut's weights wg wc wp wd contour-wg contour-wn contour-wl)
//   anchor-insert u,v | anchor-move K u,v | anchor-delete K | livewire-cooling N (live-wire anchor edits and path
//   cooling) | surface-corner +x|-x|+y|-y|+z|-z x,y,z|clear | surface-side NAME | surface-via x,y,z|clear (the
//   surface's corners and a side's via points for the next run) | mono-plane x|y|z[=K] (the monoplanar plane)
// An unknown or failed command stops the script: ScriptError "NAME:LINE: message".
#pragma once
#include <array>
#include <istream>
#include <string>
#include <vector>

#include "app/viewer_app.h"
#include "util/error.h"

namespace vs::viewer {

class ScriptError : public Error {
 public:
  using Error::Error;
};

// What only a window can do. Without a host, `screenshot` is an error.
class ScriptHost {
 public:
  virtual ~ScriptHost() = default;
  virtual void screenshot(const std::string& path) = 0;
  virtual void frame() {}  // draws one frame after every command
  // Waits for the background job; a window keeps drawing frames meanwhile.
  virtual void waitForJob(BackgroundJob& job) { job.wait(); }
  // The 3D view's size in pixels (what `pick PX,PY` refers to).
  virtual std::array<int, 2> view3DSize() const = 0;
  // Hands the window to real input events (mouse, keys) until KEY (F1..F12, a letter or a
  // digit) is pressed; then the script goes on. Every event before KEY has been processed.
  virtual void interact(const std::string& key) = 0;
};

// What a command's action gets: the app, the window (null without one), the command's name and
// its arguments.
struct ScriptCall {
  ViewerApp& app;
  ScriptHost* host;
  const std::string& cmd;
  const std::vector<std::string>& args;
};

// One row of the command table (script_commands.cpp): name, arguments, what it does, how many
// arguments it takes (-1: the action checks them) and the action.
struct ScriptCommand {
  const char* name;
  const char* args;
  const char* doc;
  int argCount;
  void (*action)(ScriptCall);
};

// The command table, in the order `view --help` lists it.
const std::vector<ScriptCommand>& scriptCommandTable();
// The row named `name`, or null.
const ScriptCommand* findScriptCommand(const std::string& name);
// The command names, for help texts and tests.
const std::vector<std::string>& scriptCommands();
// UsageError "'CMD' takes N argument(s), got M" unless args has n items.
void requireArgs(const std::string& cmd, const std::vector<std::string>& args, size_t n);

// Runs the script; returns true if it ended with `quit`. Throws ScriptError naming the line.
bool runScript(ViewerApp& app, std::istream& in, ScriptHost* host, const std::string& name);
// Reads the file and runs it; an unreadable file is an IoError.
bool runScriptFile(ViewerApp& app, const std::string& path, ScriptHost* host);

}  // namespace vs::viewer
