// OpenGL 3.3 core entry points. Debian's libglvnd exports every core function from libOpenGL
// (and libGL), for GLX (window) and EGL (offscreen) contexts alike, so no loader is needed.
#pragma once
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
