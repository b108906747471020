#include "output_guard.h"

#include <map>
#include <set>
#include <vector>

#include "util/atomic_file.h"

namespace vs::cli {

namespace {

// Option names (as CLI11's get_name() reports them) that are files the command writes.
const std::set<std::string>& outputOptions(const std::string& command) {
  static const std::map<std::string, std::set<std::string>> table = {
      {"convert", {"output"}},
      {"cut", {"--labels", "--cut-surface", "--contour", "--json"}},  // --parts is a prefix
      {"info", {"--json"}},
      {"livewire", {"--out", "--mask"}},
      {"measure", {"--csv", "--json", "--out"}},
      {"phantom", {"--out", "--truth", "--labels"}},
      {"render", {"--out", "--json"}},
      {"surface", {"--out", "--json"}},
      {"trace", {"--out", "--json", "--labels", "--vtk", "--measure"}},
  };
  static const std::set<std::string> fallback = {"--out", "--json", "output"};
  auto it = table.find(command);
  return it == table.end() ? fallback : it->second;
}

}  // namespace

void checkCommandOutputs(const std::string& command, const CLI::App& sub) {
  const auto& outNames = outputOptions(command);
  std::vector<std::string> inputs, outputs;
  for (const CLI::Option* opt : sub.get_options()) {
    if (opt->count() == 0) continue;
    const bool isOutput = outNames.count(opt->get_name()) > 0;
    for (const std::string& value : opt->results()) (isOutput ? outputs : inputs).push_back(value);
  }
  vs::checkOutputs(inputs, outputs);
}

}  // namespace vs::cli
