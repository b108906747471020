#include "gl/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "gl/gl.h"
#include "util/error.h"

namespace vs::viewer {

struct EglContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

namespace {

std::string eglError(const std::string& what) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", static_cast<unsigned>(eglGetError()));
  return "EGL: " + what + " failed (error " + buf + ")";
}

}  // namespace

EglContext::EglContext() : impl_(std::make_unique<Impl>()) {
  auto getPlatformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  EGLint major = 0, minor = 0;
  // Surfaceless first (no X server needed), then whatever the default display is.
  if (getPlatformDisplay) {
    impl_->display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (impl_->display != EGL_NO_DISPLAY && !eglInitialize(impl_->display, &major, &minor))
      impl_->display = EGL_NO_DISPLAY;
  }
  if (impl_->display == EGL_NO_DISPLAY) {
    impl_->display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (impl_->display == EGL_NO_DISPLAY || !eglInitialize(impl_->display, &major, &minor))
      throw Error(eglError("opening a display"));
  }
  if (!eglBindAPI(EGL_OPENGL_API)) throw Error(eglError("binding the OpenGL API"));
  const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  eglChooseConfig(impl_->display, configAttribs, &config, 1, &count);
  const EGLint contextAttribs[] = {
      EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  impl_->context = eglCreateContext(impl_->display, count > 0 ? config : nullptr, EGL_NO_CONTEXT, contextAttribs);
  if (impl_->context == EGL_NO_CONTEXT) {
    eglTerminate(impl_->display);
    throw Error(eglError("creating an OpenGL 3.3 core context"));
  }
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context)) {
    eglDestroyContext(impl_->display, impl_->context);
    eglTerminate(impl_->display);
    throw Error(eglError("making the context current without a surface"));
  }
}

EglContext::~EglContext() {
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(impl_->display, impl_->context);
  eglTerminate(impl_->display);
}

std::string EglContext::renderer() const {
  const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return s ? s : "";
}

}  // namespace vs::viewer
