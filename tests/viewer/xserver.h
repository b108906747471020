// An X server of the test's own (Xvfb): a display number Xvfb chose itself (-displayfd, so
// parallel tests never race for one) and an authority file with a fresh cookie, both private to
// the test. Replaces xvfb-run -a, whose display search and clean-up race with parallel tests (exit
// status 5 "problem while cleaning up temporary directory" with the viewer's own status lost).
#pragma once
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

namespace vs::viewer::testing {

class XServer {
 public:
  // Starts Xvfb with one screen of width x height x 24; ok() says whether it runs.
  XServer(const std::filesystem::path& dir, int width, int height) {
    if (std::system("command -v Xvfb > /dev/null 2>&1") != 0) {
      why_ = "Xvfb is not installed";
      return;
    }
    auth_ = (dir / "xauthority").string();
    writeAuthority();
    int fds[2];
    if (::pipe(fds) != 0) {
      why_ = "pipe failed";
      return;
    }
    const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";
    const std::string fd = std::to_string(fds[1]);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[0]);
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) ::dup2(null, STDERR_FILENO), ::dup2(null, STDOUT_FILENO);
      ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-auth", auth_.c_str(), "-screen", "0", screen.c_str(),
               "-nolisten", "tcp", "-noreset", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    // Xvfb writes its display number and a newline once it accepts clients.
    std::string number;
    char c = 0;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(fds[0]);
    if (number.empty()) {
      why_ = "Xvfb did not start";
      stop();
      return;
    }
    display_ = ":" + number;
  }
  ~XServer() { stop(); }
  XServer(const XServer&) = delete;
  XServer& operator=(const XServer&) = delete;

  bool ok() const { return !display_.empty(); }
  const std::string& why() const { return why_; }
  // The environment a client needs: "DISPLAY=:N XAUTHORITY=FILE".
  std::string env() const { return "DISPLAY=" + display_ + " XAUTHORITY=" + auth_; }
  const std::string& display() const { return display_; }
  const std::string& authority() const { return auth_; }

 private:
  // One MIT-MAGIC-COOKIE-1 entry of family FamilyWild with no display number: it matches
  // whatever number Xvfb picks (libXau), and the server loads every entry of its -auth file.
  void writeAuthority() const {
    std::random_device rd;
    std::string cookie(16, '\0');
    for (char& ch : cookie) ch = static_cast<char>(rd() & 0xff);
    std::ofstream f(auth_, std::ios::binary);
    auto field = [&](const std::string& s) {
      f.put(char((s.size() >> 8) & 0xff));
      f.put(char(s.size() & 0xff));
      f.write(s.data(), std::streamsize(s.size()));
    };
    f.put(char(0xff));
    f.put(char(0xff));  // FamilyWild
    field("");          // address
    field("");          // display number: any
    field("MIT-MAGIC-COOKIE-1");
    field(cookie);
  }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    for (int i = 0; i < 200 && ::waitpid(pid_, &status, WNOHANG) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    if (::waitpid(pid_, &status, WNOHANG) == 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status, 0);
    }
    pid_ = -1;
  }
  pid_t pid_ = -1;
  std::string display_, auth_, why_;
};

}  // namespace vs::viewer::testing
