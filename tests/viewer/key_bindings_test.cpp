// Tests for app/key_bindings: every key runs a command of the script's table or a window action,
// no key is bound twice, the help text is generated from the table, and a key's script command
// does what the script does.
#include "app/key_bindings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "app/script.h"

using namespace vs;
using namespace vs::viewer;

TEST(KeyBindings, EveryKeyRunsACommandOfTheTableOrAWindowAction) {
  std::set<std::string> keys;
  const auto& window = windowKeyActions();
  for (const KeyBinding& b : keyBindings()) {
    EXPECT_TRUE(keys.insert(b.key).second) << b.key << " is bound twice";
    const std::string action = b.action;
    const bool windowAction = std::find(window.begin(), window.end(), action) != window.end();
    const ScriptCommand* c = findScriptCommand(action.substr(0, action.find(' ')));
    EXPECT_TRUE(windowAction || c) << b.key << ": '" << action << "' is neither a script command nor a window action";
    if (!windowAction && c) {
      EXPECT_EQ(c->argCount, action.find(' ') == std::string::npos ? 0 : 1) << b.key << ": " << action;
    }
  }
  EXPECT_GE(keys.size(), 15u);
}

TEST(KeyBindings, HelpListsEveryKeyWithItsWords) {
  const std::string help = keyHelpText();
  for (const KeyBinding& b : keyBindings()) {
    EXPECT_NE(help.find("  " + std::string(b.key) + " "), std::string::npos) << b.key << "\n" << help;
    if (b.help) {
      EXPECT_NE(help.find(b.help), std::string::npos) << b.help;
    }
  }
  // Rows without words of their own show the command table's doc.
  EXPECT_NE(help.find(findScriptCommand("undo")->doc), std::string::npos) << help;
}

TEST(KeyBindings, AKeysScriptCommandDoesWhatTheScriptDoes) {
  ViewerApp app;
  app.loadHeadPhantom(32);
  for (const KeyBinding& b : keyBindings()) {
    const std::string action = b.action;
    if (action.rfind("tool ", 0) != 0) continue;
    const std::string name = "tool";
    const std::vector<std::string> args{action.substr(5)};
    findScriptCommand(name)->action(ScriptCall{app, nullptr, name, args});
    EXPECT_EQ(toolName(app.tool()), args[0]) << b.key;
  }
}
