// volscissors <command> [options]
// Exit status: 0 success, 2 usage error (bad option, bad coordinates, bad syntax),
// 1 data or I/O error (missing/corrupt file, NaN voxels, unwritable output), 130 cancelled.
#include <algorithm>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "command.h"
#include "output_guard.h"
#include "signals.h"
#include "util/atomic_file.h"
#include "util/error.h"

int main(int argc, char** argv) {
  vs::cli::installSignalHandlers();  // first: Ctrl-C during start-up must already cancel cleanly
  using namespace vs::cli;
  CLI::App app{"volscissors: Intelligent Scissors segmentation and visualization of medical volumes"};
  app.require_subcommand(1);
  app.add_flag("-q,--quiet", vs::cli::quietFlag(), "only print results and errors (no notes, no progress line)");
  app.fallthrough();  // --quiet is accepted after the command name too
  app.set_version_flag("--version", "volscissors 0.1.0");

  auto commands = registry();
  std::sort(commands.begin(), commands.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, Runner> runners;
  for (auto& c : commands) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    runners[sub] = c.setup(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // Parse errors look like every other error of the tool, and name the command to ask.
    std::string cmd;
    for (const CLI::App* sub : app.get_subcommands()) cmd = " " + sub->get_name();
    std::cerr << "volscissors: error: " << e.what() << "\n(run 'volscissors" << cmd << " --help' for the options)\n";
    return 2;
  } catch (const std::exception& e) {  // a conversion inside an option callback (std::stod & co.)
    std::cerr << "volscissors: error: bad option value: " << e.what() << '\n';
    return 2;
  }

  vs::protectInputs(true);  // a one-shot command never overwrites a file it read
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) {
        vs::cli::checkCommandOutputs(sub->get_name(), *sub);
        return run();
      }
    return 2;
  } catch (const vs::UsageError& e) {
    std::cerr << "volscissors: error: " << e.what() << '\n';
    return 2;
  } catch (const vs::InvalidArgument& e) {
    std::cerr << "volscissors: error: " << e.what() << '\n';
    return 2;
  } catch (const vs::Cancelled& e) {
    std::cerr << "volscissors: cancelled\n";
    return 130;
  } catch (const vs::Error& e) {
    std::cerr << "volscissors: error: " << e.what() << '\n';
    return 1;
  } catch (const nlohmann::json::exception& e) {  // a JSON input with a wrong field type
    std::cerr << "volscissors: error: malformed JSON input: " << e.what() << '\n';
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "volscissors: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "volscissors: internal error: " << e.what() << '\n';
    return 1;
  }
}
