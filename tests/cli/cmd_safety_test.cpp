// The CLI's promises under hostile use, through the real binary (VS_CLI_PATH): an output
// that is an input is refused before any work (exit 2, input intact), a missing output
// folder is refused before computing (no other output written), and SIGINT/SIGTERM during a
// long command exit 130 leaving neither outputs nor temporaries.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "io/io_test_util.h"

using namespace vs::test;

namespace {

// Runs the CLI (argv without the program), returns the exit status; -signal when killed.
int runCli(const std::vector<std::string>& args, int signalAfterMs = -1, int sig = SIGINT) {
  std::vector<char*> argv;
  std::string prog = VS_CLI_PATH;
  argv.push_back(prog.data());
  std::vector<std::string> copy = args;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGINT, SIG_DFL);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::dup2(devnull, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (signalAfterMs >= 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(signalAfterMs));
    ::kill(pid, sig);
  }
  int st = 0;
  ::waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
}

std::vector<std::string> hiddenFiles(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(".", 0) == 0) out.push_back(e.path().filename().string());
  return out;
}

}  // namespace

TEST(CliSafety, OutputEqualToAnInputIsRefusedBeforeWork) {
  TempDir dir("cli_same");
  const std::string v = dir.file("v.nii");
  ASSERT_EQ(runCli({"-q", "phantom", "vessels", "--size", "32,32,32", "--out", v}), 0);
  const std::string before = readBytes(v);
  fs::create_symlink(v, dir.file("alias.nii"));
  EXPECT_EQ(runCli({"info", v, "--json", v}), 2);
  EXPECT_EQ(runCli({"convert", v, dir.file("alias.nii")}), 2);
  EXPECT_EQ(runCli({"convert", v, dir.file("../" + dir.path.filename().string() + "/v.nii")}), 2);
  EXPECT_EQ(runCli({"render", v, "--size", "32x32", "--out", v}), 2);
  EXPECT_EQ(runCli({"trace", v, "--root", "2,2,2", "--target", "8,8,8", "--out", dir.file("t.json"), "--json",
                    dir.file("t.json")}),
            2);
  EXPECT_EQ(readBytes(v), before);
  EXPECT_FALSE(fs::exists(dir.file("t.json")));
  // A missing folder for one output: refused before computing, the other output not written.
  EXPECT_EQ(runCli({"trace", v, "--root", "2,2,2", "--target", "8,8,8", "--out", dir.file("t.swc"), "--labels",
                    dir.file("missing/l.nii.gz")}),
            1);
  EXPECT_FALSE(fs::exists(dir.file("t.swc")));
  EXPECT_TRUE(hiddenFiles(dir.path).empty());
}

TEST(CliSafety, InterruptedRunsExit130AndLeaveNothing) {
  TempDir dir("cli_signal");
  const std::string v = dir.file("big.nii");
  ASSERT_EQ(runCli({"-q", "phantom", "vessels", "--size", "160,160,128", "--out", v}), 0);
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path out = dir.path / ("out" + std::to_string(sig));
    fs::create_directories(out);
    // A full single-source search with three outputs: long enough to be interrupted. The gradient
    // cost and no snap, because the root and target lie in the background on purpose.
    const int rc = runCli({"-q", "trace", v, "--root", "3,3,3", "--target", "150,150,120", "--full", "--cost",
                           "gradient", "--snap", "0", "--out", (out / "t.swc").string(), "--json",
                           (out / "t.json").string(), "--labels", (out / "t.nii.gz").string()},
                          1500, sig);
    if (rc == 0) {  // finished before the signal (a fast machine): every output is complete
      EXPECT_TRUE(fs::exists(out / "t.swc") && fs::exists(out / "t.json") && fs::exists(out / "t.nii.gz"));
    } else {
      EXPECT_EQ(rc, 130) << "signal " << sig;
      EXPECT_FALSE(fs::exists(out / "t.swc") || fs::exists(out / "t.json") || fs::exists(out / "t.nii.gz"));
    }
    EXPECT_TRUE(hiddenFiles(out).empty()) << "leftover temporaries after signal " << sig;
  }
}
