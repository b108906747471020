// The viewer's keys, one table (issue 23: the script commands, the key bindings, the help text
// and the panel were four hand-kept lists of the same actions). Each row is a key, the action it
// runs and the line the help panel shows. An action is a command line of the script's command
// table (script.h: "tool trace", "undo", "close"), run through that table, or one of the few
// window actions that have no script command (windowKeyActions: the help panel, the view reset,
// the next display or stereo mode, the axial slice, a run that does not wait).
#pragma once
#include <string>
#include <vector>

namespace vs::viewer {

struct KeyBinding {
  const char* key;      // "1", "Esc", "z", "Shift+z", "Enter", "PgUp": a letter, a digit or a named key
  const char* action;   // a script command line, or a window action
  const char* help;     // the help panel's words for it (null: the script command's own doc)
  bool repeat = false;  // fires again while the key is held
};

// The table, in the order the help panel lists it.
const std::vector<KeyBinding>& keyBindings();
// The actions only a window runs (not script commands).
const std::vector<std::string>& windowKeyActions();
// The help panel's "Keys" section, generated from the table: one "  KEY  words" line a row.
std::string keyHelpText();

}  // namespace vs::viewer
