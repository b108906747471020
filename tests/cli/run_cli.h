// Runs the volscissors CLI built for the tests (VS_CLI_PATH) and collects its exit status and
// its output (stdout and stderr together), for the CLI tests that check both.
#pragma once
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace vs::testing {

struct CliResult {
  int status = -1;
  std::string output;
};

inline CliResult runCli(const std::string& args) {
  CliResult r;
  const std::string cmd = std::string(VS_CLI_PATH) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) r.output += buf;
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace vs::testing
