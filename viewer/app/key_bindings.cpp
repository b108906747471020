#include "app/key_bindings.h"

#include <algorithm>

#include "app/script.h"

namespace vs::viewer {

const std::vector<KeyBinding>& keyBindings() {
  static const std::vector<KeyBinding> table = {
      {"1", "tool livewire", "live-wire tool"},
      {"2", "tool trace", "trace tool"},
      {"3", "tool surface", "surface tool"},
      {"4", "tool cut", "cut tool"},
      {"0", "tool none", "no tool"},
      {"Esc", "tool none", "no tool"},
      {"z", "undo", nullptr},
      {"Shift+z", "redo", nullptr},
      {"y", "redo", nullptr},
      {"c", "close", nullptr},
      {"Enter", "run", "run trace/surface/cut"},
      {"PgUp", "slice+1", "next axial slice", true},
      {"PgDn", "slice-1", "previous axial slice", true},
      {"m", "next-mode", "next 3D display mode"},
      {"s", "next-stereo", "next stereo mode"},
      {"r", "reset-view", "reset the 3D and slice views"},
      {"h", "help", "show/hide this help"},
  };
  return table;
}

const std::vector<std::string>& windowKeyActions() {
  static const std::vector<std::string> actions = {"run",         "slice+1", "slice-1",   "next-mode",
                                                   "next-stereo", "help",    "reset-view"};
  return actions;
}

std::string keyHelpText() {
  std::string s;
  for (const KeyBinding& b : keyBindings()) {
    std::string words = b.help ? b.help : "";
    if (!b.help) {
      const std::string action = b.action;
      const ScriptCommand* c = findScriptCommand(action.substr(0, action.find(' ')));
      words = c ? c->doc : action;
    }
    std::string key = b.key;
    key.resize(std::max<size_t>(key.size(), 8), ' ');
    s += "  " + key + " " + words + "\n";
  }
  return s;
}

}  // namespace vs::viewer
