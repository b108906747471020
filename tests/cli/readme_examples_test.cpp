// Every command example in README.md's "Command line" section runs exactly as printed: the
// ```sh block is read from the README, its first line (B=...; D=...) prefixes every command,
// and each command runs with bash in a scratch folder laid out like the repository root
// (build/volscissors -> the binary under test, ../shared/data -> the shared data), in order,
// so later examples use earlier outputs. Commands that need ../shared/data skip when it is
// missing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::vector<std::string> readmeExamples(std::string& prelude) {
  std::ifstream in(std::string(VS_SOURCE_DIR) + "/README.md");
  std::string line;
  bool inSection = false, inBlock = false;
  std::vector<std::string> commands;
  std::string pending;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) inSection = line == "## Command line";
    if (!inSection) continue;
    if (line.rfind("```", 0) == 0) {
      inBlock = !inBlock && line == "```sh";
      continue;
    }
    if (!inBlock) continue;
    pending += line;
    if (!pending.empty() && pending.back() == '\\') {  // continued on the next line
      pending.pop_back();
      continue;
    }
    if (prelude.empty())
      prelude = pending;
    else
      commands.push_back(pending);
    pending.clear();
  }
  return commands;
}

}  // namespace

TEST(Readme, CommandLineExamplesRunAsPrinted) {
  std::string prelude;
  const std::vector<std::string> commands = readmeExamples(prelude);
  ASSERT_EQ(prelude.rfind("B=build/volscissors; D=../shared/data", 0), 0u) << prelude;
  ASSERT_GE(commands.size(), 5u);
  const fs::path root = fs::temp_directory_path() / ("vs_readme_" + std::to_string(::getpid()));
  const fs::path work = root / "repo";
  fs::create_directories(work / "build");
  fs::create_symlink(VS_CLI_PATH, work / "build" / "volscissors");
  const fs::path data = fs::weakly_canonical(VS_SHARED_DATA_DIR);
  const bool haveData = fs::exists(data);
  if (haveData) {
    fs::create_directories(root / "shared");
    fs::create_directory_symlink(data, root / "shared" / "data");
  }
  int ran = 0;
  for (const auto& cmd : commands) {
    if (!haveData && cmd.find("$D") != std::string::npos) continue;
    const std::string script = "cd '" + work.string() + "' && " + prelude + "\n" + cmd;
    std::ofstream(root / "cmd.sh") << script << "\n";
    const int rc =
        std::system(("bash '" + (root / "cmd.sh").string() + "' > '" + (root / "log.txt").string() + "' 2>&1").c_str());
    std::ifstream log(root / "log.txt");
    std::stringstream ss;
    ss << log.rdbuf();
    EXPECT_EQ(rc, 0) << cmd << "\n" << ss.str();
    ++ran;
  }
  fs::remove_all(root);
  if (!haveData) GTEST_SKIP() << "shared data missing: ran " << ran << " of " << commands.size() << " examples";
}
