#include "app/script.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace vs::viewer {

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
    try {
      const ScriptCommand* command = findScriptCommand(cmd);
      if (!command) throw UsageError("unknown command '" + cmd + "'");
      if (command->argCount >= 0) requireArgs(cmd, args, size_t(command->argCount));
      command->action(ScriptCall{app, host, cmd, args});
      if (cmd == "quit") return true;
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
