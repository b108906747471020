#include "command.h"

#include <iostream>

#include "progress_line.h"

namespace vs::cli {

std::vector<CommandSpec>& registry() {
  static std::vector<CommandSpec> commands;
  return commands;
}

namespace {
bool gQuiet = false;
}

bool& quietFlag() { return gQuiet; }
bool quiet() { return gQuiet; }
void note(const std::string& message) {
  if (gQuiet) return;
  clearProgressLine();
  std::cerr << message << '\n';
}

void warn(const std::string& message) {
  if (gQuiet) return;
  clearProgressLine();
  std::cerr << "volscissors: warning: " << message << '\n';
}

}  // namespace vs::cli
