// Self-registering subcommands: each cli/cmd_<name>.cpp defines one command with
//   static const vs::cli::Registration reg{"name", "one-line help", setup};
// where setup(CLI::App& sub) adds the options and returns the function that runs it.
// main.cpp builds the CLI11 app from the registry, so adding a command touches one file.
// Commands hold no algorithm: they parse, call the core, and print or save.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace vs::cli {

using Runner = std::function<int()>;
using Setup = std::function<Runner(CLI::App& sub)>;

struct CommandSpec {
  std::string name;
  std::string help;
  Setup setup;
};

std::vector<CommandSpec>& registry();

struct Registration {
  Registration(std::string name, std::string help, Setup setup) {
    registry().push_back({std::move(name), std::move(help), std::move(setup)});
  }
};

// Shared conventions for all commands.
// Prints a one-line status message on stderr unless --quiet was given.
// --quiet: only results and errors (no notes, no progress line).
void note(const std::string& message);
bool quiet();
bool& quietFlag();  // set by main() from --quiet
// "volscissors: warning: MESSAGE" on stderr unless --quiet.
void warn(const std::string& message);

}  // namespace vs::cli
