// An offscreen OpenGL 3.3 core context on EGL without any window or display server (Mesa's
// surfaceless platform, or the default display), for image tests and headless renders.
#pragma once
#include <memory>
#include <string>

namespace vs::viewer {

class EglContext {
 public:
  // Creates the context and makes it current on this thread; throws vs::Error with the reason
  // (no EGL, no OpenGL 3.3 core) so callers can skip or fall back.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vs::viewer
