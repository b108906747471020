#include "gl/raycaster.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "gl/gl.h"
#include "util/error.h"

namespace vs::viewer {

namespace {

const char* kVertexShader = R"(#version 330 core
// One triangle covering the viewport.
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
uniform sampler3D volumeTex;
uniform sampler1D tfTex;
uniform mat4 invViewProj;      // clip -> world (mm)
uniform mat4 worldToIndex;     // world (mm) -> continuous voxel index
uniform mat3 indexAxesT;       // transpose of the direction matrix: world -> index-axes frame
uniform vec4 viewport;         // x, y, w, h
uniform vec3 dims;
uniform vec3 spacing;
uniform float dt;              // sample step, mm
uniform float tfLo, tfScale;
uniform int tfSize;
uniform int mode;              // 0 full, 1 cut box, 2 triplanar, 3 monoplanar, 4 MIP
uniform vec3 boxLo, boxHi;
uniform vec3 planes;           // triplanar indices (monoplanar: only planeAxis is used)
uniform int planeAxis;         // -1: all three
uniform vec2 windowLevel;      // width, centre
uniform int shading;
uniform int jitter;
uniform float earlyTermination;
uniform vec4 light;            // ambient, diffuse, specular, power
uniform vec3 background;
uniform usampler3D labelTex;   // labels (nearest), when hasLabels
uniform sampler1D paletteTex;  // label colour; alpha 0: hidden
uniform int hasLabels;
uniform float labelOpacity;
out vec4 fragColor;

// The palette entry of the label at p (nearest voxel, as the CPU renderer): alpha -1 for no label,
// 0 for a hidden one, 1 for a shown one.
vec4 labelAt(vec3 p) {
  if (hasLabels == 0) return vec4(0.0, 0.0, 0.0, -1.0);
  int l = int(texture(labelTex, (p + 0.5) / dims).r);
  if (l == 0) return vec4(0.0, 0.0, 0.0, -1.0);
  int size = textureSize(paletteTex, 0);
  return texelFetch(paletteTex, l < size ? l : (l - 1) % 12 + 1, 0);
}
vec3 withLabel(vec3 c, vec4 l) { return l.a > 0.0 ? mix(c, l.rgb, labelOpacity) : c; }

float sampleAt(vec3 p) { return texture(volumeTex, (p + 0.5) / dims).r; }
float grey(float v) { return clamp((v - (windowLevel.y - 0.5 * windowLevel.x)) / windowLevel.x, 0.0, 1.0); }
vec4 tf(float v) { return texelFetch(tfTex, clamp(int((v - tfLo) * tfScale + 0.5), 0, tfSize - 1), 0); }

bool box(vec3 o, vec3 d, vec3 lo, vec3 hi, out float t0, out float t1) {
  t0 = 0.0; t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (abs(d[a]) < 1e-12) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    float ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
  }
  return t1 >= t0;
}

void main() {
  vec2 ndc = (gl_FragCoord.xy - viewport.xy) / viewport.zw * 2.0 - 1.0;
  vec4 a = invViewProj * vec4(ndc, -1.0, 1.0), b = invViewProj * vec4(ndc, 1.0, 1.0);
  vec3 ow = a.xyz / a.w, dw = normalize(b.xyz / b.w - ow);
  vec3 o = (worldToIndex * vec4(ow, 1.0)).xyz, d = mat3(worldToIndex) * dw;  // index per mm
  vec3 C = vec3(0.0);
  float A = 0.0;
  vec3 hi = dims - 1.0;
  float t0, t1;
  if (mode == 2 || mode == 3) {
    // Every plane hit, nearest first; with more than one, a plane pixel darker than 0.05 in every
    // channel (air, background, unlabelled) is nearly clear (opacity 0.15), as in the CPU renderer.
    float ts[3] = float[3](0.0, 0.0, 0.0);
    vec3 qs[3] = vec3[3](vec3(0.0), vec3(0.0), vec3(0.0));
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      if (planeAxis >= 0 && k != planeAxis) continue;
      if (abs(d[k]) < 1e-12) continue;
      float t = (planes[k] - o[k]) / d[k];
      if (t <= 0.0) continue;
      vec3 q = o + t * d;
      bool inside = true;
      for (int c = 0; c < 3; ++c)
        if (c != k) inside = inside && q[c] >= -1e-4 && q[c] <= hi[c] + 1e-4;
      if (inside) {
        int h = n;
        n += 1;
        while (h > 0 && ts[h - 1] > t) { ts[h] = ts[h - 1]; qs[h] = qs[h - 1]; h -= 1; }
        ts[h] = t;
        qs[h] = q;
      }
    }
    for (int h = 0; h < n; ++h) {
      vec3 c = withLabel(vec3(grey(sampleAt(qs[h]))), labelAt(qs[h]));
      float op = (n > 1 && max(c.r, max(c.g, c.b)) < 0.05) ? 0.15 : 1.0;
      C += (1.0 - A) * op * c;
      A += (1.0 - A) * op;
    }
  } else if (mode == 4) {
    if (box(o, d, vec3(0.0), hi, t0, t1)) {
      float vmax = -1e30;
      int n = int(floor((t1 - t0) / dt));
      for (int k = 0; k <= n; ++k) vmax = max(vmax, sampleAt(o + (t0 + float(k) * dt) * d));
      float floorV = windowLevel.y - 0.5 * windowLevel.x;
      if (vmax > floorV) { C = vec3(grey(vmax)); A = 1.0; }
    }
  } else if (box(o, d, mode == 1 ? boxLo : vec3(0.0), mode == 1 ? boxHi : hi, t0, t1)) {
    bool faceOnly = false;
    if (mode == 1) { vec3 q = o + t0 * d; C = withLabel(vec3(grey(sampleAt(q))), labelAt(q)); A = 1.0; faceOnly = true; }
    if (!faceOnly) {
      if (jitter != 0) {
        float h = fract(sin(dot(gl_FragCoord.xy, vec2(12.9898, 78.233))) * 43758.5453);
        t0 += h * dt;
      }
      vec3 L = normalize(indexAxesT * -dw);
      int n = int(floor((t1 - t0) / dt));
      for (int k = 0; k <= n; ++k) {
        vec3 p = o + (t0 + float(k) * dt) * d;
        vec4 e = tf(sampleAt(p));
        if (e.a <= 0.0) continue;
        vec4 lab = labelAt(p);
        if (lab.a == 0.0) continue;  // a hidden part is not drawn
        vec3 c = withLabel(e.rgb, lab);
        if (shading != 0) {
          vec3 g = vec3(sampleAt(p + vec3(1, 0, 0)) - sampleAt(p - vec3(1, 0, 0)),
                        sampleAt(p + vec3(0, 1, 0)) - sampleAt(p - vec3(0, 1, 0)),
                        sampleAt(p + vec3(0, 0, 1)) - sampleAt(p - vec3(0, 0, 1))) / (2.0 * spacing);
          float n2 = dot(g, g), diff = 1.0, spec = 0.0;
          if (n2 > 1e-6) {
            float ndl = abs(dot(g, L)) / sqrt(n2);
            diff = ndl;
            spec = pow(ndl, light.w);
          }
          c = c * (light.x + light.y * diff) + light.z * spec;
        }
        float w = (1.0 - A) * e.a;
        C += w * c;
        A += w;
        if (A >= earlyTermination) break;
      }
    }
  }
  fragColor = vec4(C + (1.0 - A) * background, 1.0);
}
)";

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    throw Error(std::string("GPU ray caster: shader does not compile: ") + log);
  }
  return s;
}

}  // namespace

struct GpuRayCaster::Impl {
  GLuint program = 0, vao = 0, volumeTex = 0, tfTex = 0, labelTex = 0, paletteTex = 0;
  bool haveLabels = false;
  Geometry geom;
  ValueRange range;
  TransferFunction tf;
  double tableStep = -1;  // the TF table is corrected for this step (mm)
  bool haveVolume = false;
  GLint loc(const char* name) const { return glGetUniformLocation(program, name); }
};

GpuRayCaster::GpuRayCaster() : impl_(std::make_unique<Impl>()) {
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  if (!version) throw Error("GPU ray caster: no current OpenGL context");
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  auto& I = *impl_;
  I.program = glCreateProgram();
  glAttachShader(I.program, vs);
  glAttachShader(I.program, fs);
  glLinkProgram(I.program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(I.program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(I.program, sizeof log, nullptr, log);
    throw Error(std::string("GPU ray caster: shaders do not link: ") + log);
  }
  glGenVertexArrays(1, &I.vao);
  glGenTextures(1, &I.volumeTex);
  glGenTextures(1, &I.tfTex);
  glGenTextures(1, &I.labelTex);
  glGenTextures(1, &I.paletteTex);
  setLabelPalette({});
}

GpuRayCaster::~GpuRayCaster() {
  auto& I = *impl_;
  glDeleteTextures(1, &I.volumeTex);
  glDeleteTextures(1, &I.tfTex);
  glDeleteTextures(1, &I.labelTex);
  glDeleteTextures(1, &I.paletteTex);
  glDeleteVertexArrays(1, &I.vao);
  glDeleteProgram(I.program);
}

void GpuRayCaster::setVolume(const AnyVolume& volume) {
  auto& I = *impl_;
  const VolumeF32 f = toFloat(volume);
  I.geom = f.geometry();
  I.range = valueRange(volume);
  GLint maxSide = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &maxSide);
  for (int a = 0; a < 3; ++a)
    if (I.geom.dims[a] > maxSide)
      throw DataError("GPU ray caster: the volume " + I.geom.describe() + " exceeds the GPU's 3D texture limit of " +
                      std::to_string(maxSide) + " voxels per side");
  glBindTexture(GL_TEXTURE_3D, I.volumeTex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, static_cast<GLsizei>(I.geom.dims[0]), static_cast<GLsizei>(I.geom.dims[1]),
               static_cast<GLsizei>(I.geom.dims[2]), 0, GL_RED, GL_FLOAT, f.data());
  if (glGetError() == GL_OUT_OF_MEMORY)
    throw DataError("GPU ray caster: not enough GPU memory for " + I.geom.describe());
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
    glTexParameteri(GL_TEXTURE_3D, w, GL_CLAMP_TO_EDGE);
  I.haveVolume = true;
  I.tableStep = -1;
  if (I.tf.empty()) I.tf = TransferFunction::preset("auto", I.range);
}

void GpuRayCaster::setLabels(const VolumeU16* labels) {
  auto& I = *impl_;
  I.haveLabels = false;
  if (!labels) return;
  VS_REQUIRE(I.haveVolume && labels->dims() == I.geom.dims,
             "GPU ray caster: the labels " + labels->geometry().describe() + " do not match the volume");
  glBindTexture(GL_TEXTURE_3D, I.labelTex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const Index3& d = labels->dims();
  glTexImage3D(GL_TEXTURE_3D, 0, GL_R16UI, static_cast<GLsizei>(d[0]), static_cast<GLsizei>(d[1]),
               static_cast<GLsizei>(d[2]), 0, GL_RED_INTEGER, GL_UNSIGNED_SHORT, labels->data());
  if (glGetError() == GL_OUT_OF_MEMORY) throw DataError("GPU ray caster: not enough GPU memory for the labels");
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);  // integer textures are never filtered
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
    glTexParameteri(GL_TEXTURE_3D, w, GL_CLAMP_TO_EDGE);
  I.haveLabels = true;
}

void GpuRayCaster::setLabelPalette(const OverlaySettings& overlays) {
  auto& I = *impl_;
  std::vector<float> rgba(4 * kLabelPaletteSize, 0.f);
  for (int l = 1; l < kLabelPaletteSize; ++l) {
    const auto c = labelColor(l);
    std::copy(c.begin(), c.end(), rgba.begin() + 4 * l);
    rgba[size_t(4 * l + 3)] = overlays.labelVisible(l) ? 1.f : 0.f;
  }
  glBindTexture(GL_TEXTURE_1D, I.paletteTex);
  glTexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, kLabelPaletteSize, 0, GL_RGBA, GL_FLOAT, rgba.data());
  glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

void GpuRayCaster::setTransferFunction(const TransferFunction& tf) {
  impl_->tf = tf;
  impl_->tableStep = -1;
}

void GpuRayCaster::draw(const EyeView& eye, int x, int y, int w, int h, const RayCastSettings& s) {
  auto& I = *impl_;
  VS_REQUIRE(I.haveVolume, "GPU ray caster: no volume");
  VS_REQUIRE(w > 0 && h > 0, "GPU ray caster: empty viewport");
  VS_REQUIRE(s.window.window > 0, "GPU ray caster: window width must be > 0");
  VS_REQUIRE(s.sampleStep > 0.01 && s.sampleStep <= 16, "GPU ray caster: sample step must be in (0.01, 16] voxels");
  const double dt = s.sampleStep * I.geom.spacing.minCoeff();
  const TfTable table(I.tf, I.range.min, I.range.max, dt);
  if (dt != I.tableStep) {
    std::vector<float> rgba(table.entries.size() * 4);
    for (size_t i = 0; i < table.entries.size(); ++i) {
      rgba[4 * i] = table.entries[i].r;
      rgba[4 * i + 1] = table.entries[i].g;
      rgba[4 * i + 2] = table.entries[i].b;
      rgba[4 * i + 3] = table.entries[i].a;
    }
    glBindTexture(GL_TEXTURE_1D, I.tfTex);
    glTexImage1D(GL_TEXTURE_1D, 0, GL_RGBA32F, static_cast<GLsizei>(table.entries.size()), 0, GL_RGBA, GL_FLOAT,
                 rgba.data());
    glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    I.tableStep = dt;
  }
  const Eigen::Matrix4d invVP = (eye.projection * eye.view).inverse();
  const Eigen::Matrix3d M = I.geom.direction * I.geom.spacing.asDiagonal();
  Eigen::Matrix4d w2i = Eigen::Matrix4d::Identity();
  w2i.topLeftCorner<3, 3>() = M.inverse();
  w2i.topRightCorner<3, 1>() = -M.inverse() * I.geom.origin;
  const Eigen::Matrix4f invVPf = invVP.cast<float>(), w2if = w2i.cast<float>();
  const Eigen::Matrix3f axesT = I.geom.direction.transpose().cast<float>();

  glUseProgram(I.program);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_3D, I.volumeTex);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_1D, I.tfTex);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_3D, I.labelTex);
  glActiveTexture(GL_TEXTURE3);
  glBindTexture(GL_TEXTURE_1D, I.paletteTex);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(I.loc("volumeTex"), 0);
  glUniform1i(I.loc("tfTex"), 1);
  glUniform1i(I.loc("labelTex"), 2);
  glUniform1i(I.loc("paletteTex"), 3);
  glUniform1i(I.loc("hasLabels"), I.haveLabels ? 1 : 0);
  glUniform1f(I.loc("labelOpacity"), float(s.labelOpacity));
  glUniformMatrix4fv(I.loc("invViewProj"), 1, GL_FALSE, invVPf.data());  // Eigen is column-major, as GL
  glUniformMatrix4fv(I.loc("worldToIndex"), 1, GL_FALSE, w2if.data());
  glUniformMatrix3fv(I.loc("indexAxesT"), 1, GL_FALSE, axesT.data());
  glUniform4f(I.loc("viewport"), float(x), float(y), float(w), float(h));
  const Index3& d = I.geom.dims;
  glUniform3f(I.loc("dims"), float(d[0]), float(d[1]), float(d[2]));
  glUniform3f(I.loc("spacing"), float(I.geom.spacing.x()), float(I.geom.spacing.y()), float(I.geom.spacing.z()));
  glUniform1f(I.loc("dt"), float(dt));
  glUniform1f(I.loc("tfLo"), float(table.lo));
  glUniform1f(I.loc("tfScale"), float(table.scale));
  glUniform1i(I.loc("tfSize"), static_cast<GLint>(table.entries.size()));
  const int modeCode = s.mode == RenderMode::Full         ? 0
                       : s.mode == RenderMode::CutBox     ? 1
                       : s.mode == RenderMode::Triplanar  ? 2
                       : s.mode == RenderMode::Monoplanar ? 3
                                                          : 4;
  glUniform1i(I.loc("mode"), modeCode);
  const double hi[3] = {double(d[0] - 1), double(d[1] - 1), double(d[2] - 1)};
  const bool wholeBox = s.box[3] < s.box[0];
  float lo3[3], hi3[3];
  for (int a = 0; a < 3; ++a) {
    lo3[a] = wholeBox ? 0.f : float(std::clamp(s.box[static_cast<size_t>(a)], 0.0, hi[a]));
    hi3[a] = wholeBox ? float(hi[a]) : float(std::clamp(s.box[static_cast<size_t>(a) + 3], 0.0, hi[a]));
  }
  glUniform3f(I.loc("boxLo"), lo3[0], lo3[1], lo3[2]);
  glUniform3f(I.loc("boxHi"), hi3[0], hi3[1], hi3[2]);
  float pl[3];
  for (int a = 0; a < 3; ++a) {
    const double v = s.mode == RenderMode::Monoplanar ? (a == s.planeAxis ? s.planeIndex : -1) : s.planes[a];
    pl[a] = float(v >= 0 ? v : std::floor(hi[a] / 2));
  }
  glUniform3f(I.loc("planes"), pl[0], pl[1], pl[2]);
  glUniform1i(I.loc("planeAxis"), s.mode == RenderMode::Monoplanar ? s.planeAxis : -1);
  glUniform2f(I.loc("windowLevel"), float(s.window.window), float(s.window.level));
  glUniform1i(I.loc("shading"), s.shading ? 1 : 0);
  glUniform1i(I.loc("jitter"), s.jitter ? 1 : 0);
  glUniform1f(I.loc("earlyTermination"), float(s.earlyTermination));
  glUniform4f(I.loc("light"), float(s.ambient), float(s.diffuse), float(s.specular), float(s.specularPower));
  glUniform3f(I.loc("background"), s.background[0], s.background[1], s.background[2]);
  glViewport(x, y, w, h);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBindVertexArray(I.vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glUseProgram(0);
}

RgbaImage readFramebuffer(int x, int y, int w, int h) {
  RgbaImage img(w, h);
  std::vector<uint8_t> rows(static_cast<size_t>(w) * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(x, y, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  const size_t stride = static_cast<size_t>(w) * 4;
  for (int r = 0; r < h; ++r)
    std::copy_n(rows.data() + static_cast<size_t>(h - 1 - r) * stride, stride, img.pixels.data() + r * stride);
  for (size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 255;
  return img;
}

RgbaImage GpuRayCaster::renderImage(const EyeView& eye, int w, int h, const RayCastSettings& s) {
  GLuint fbo = 0, rb = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
  RgbaImage img;
  try {
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("GPU ray caster: offscreen framebuffer incomplete");
    draw(eye, 0, 0, w, h, s);
    img = readFramebuffer(0, 0, w, h);
  } catch (...) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteRenderbuffers(1, &rb);
    glDeleteFramebuffers(1, &fbo);
    throw;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteRenderbuffers(1, &rb);
  glDeleteFramebuffers(1, &fbo);
  return img;
}

}  // namespace vs::viewer
