// The progress-line contract of a long command (cli/progress_line.h), checked through the real
// binary: on a terminal (a pseudo-terminal from util-linux `script`) a redrawn "COMMAND: stage
// NN%" line that is erased again; in a pipe no progress at all; with --quiet nothing on the
// terminal but errors. Header-only, for tests/cli.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

namespace vs::test {

inline bool haveScriptCommand() { return std::system("script -qefc true /dev/null > /dev/null 2>&1") == 0; }

// Runs `VS_CLI_PATH ARGS` with stdout and stderr into `transcript`, under a pseudo-terminal
// when `terminal`; returns the exit status and the transcript's text in `text`.
inline int runCliInto(const std::string& cli, const std::string& args, const std::string& transcript, bool terminal,
                      std::string& text) {
  const std::string cmd =
      terminal ? "script -qefc '" + cli + " " + args + "' /dev/null > " + transcript + " 2>&1 < /dev/null"
               : cli + " " + args + " > /dev/null 2> " + transcript + " < /dev/null";
  const int rc = std::system(cmd.c_str());
  std::ifstream in(transcript, std::ios::binary);
  text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// `args` starts with the command name, e.g. "cut vol.nii --iso 50 ..."; the command must succeed
// (it runs three times, so its outputs must be overwritable).
inline void expectProgressOnTerminalOnly(const std::string& cli, const std::string& command, const std::string& args,
                                         const std::string& transcript) {
  std::string text;
  ASSERT_EQ(runCliInto(cli, args, transcript, true, text), 0) << text;
  EXPECT_NE(text.find(command + ": "), std::string::npos) << text;
  EXPECT_NE(text.find('%'), std::string::npos) << text;
  EXPECT_NE(text.find("\r\033[K"), std::string::npos) << text;  // redrawn in place and erased
  ASSERT_EQ(runCliInto(cli, args, transcript, false, text), 0) << text;
  EXPECT_EQ(text.find('%'), std::string::npos) << "progress in a pipe: " << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << "progress in a pipe: " << text;
  ASSERT_EQ(runCliInto(cli, "-q " + args, transcript, true, text), 0) << text;
  EXPECT_EQ(text.find('%'), std::string::npos) << "progress with --quiet: " << text;
  EXPECT_EQ(text.find(command + ": "), std::string::npos) << "notes with --quiet: " << text;
}

}  // namespace vs::test
