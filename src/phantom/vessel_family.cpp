// The randomised vessel family (phantom.h: makeVesselFamilyCase): the vessel tree with drawn
// radii, contrast falloff, spacing and branch angles, then bias, polarity and Rician noise.
#include <cmath>
#include <cstdio>

#include "phantom/phantom.h"

namespace vs {

std::string VesselFamilyCase::describe() const {
  char buf[200];
  std::snprintf(buf, sizeof buf, "seed %llu: %s, spacing %.2f,%.2f,%.2f, falloff %.2f, bias %.2f, rician %.1f",
                static_cast<unsigned long long>(truth.seed), dark ? "dark" : "bright", truth.spacing[0],
                truth.spacing[1], truth.spacing[2], falloff, bias, rician);
  return buf;
}

VesselFamilyCase makeVesselFamilyCase(uint64_t seed, const Index3& dims) {
  PhantomRng rng(PhantomRng::derive(seed, 0xfa11));
  VesselFamilyCase out;
  const double s = rng.uniform(0.6, 1.0);
  out.anisotropy = rng.uniform(1.0, 3.0);
  out.falloff = rng.uniform(0.3, 0.6);
  out.bias = rng.uniform(0.0, 0.4);
  out.rician = rng.uniform(5.0, 15.0);
  out.dark = rng.uniform() < 0.5;
  VesselPhantomOptions o;
  o.seed = seed;
  o.dims = dims;
  o.spacing = Vec3(s, s, s * out.anisotropy);
  o.noiseSigma = 0;
  // Radii in the generator's unit (the largest spacing): 4 -> 0.8 voxels of the smallest spacing.
  o.minRadius = std::max(0.5, 0.8 / out.anisotropy);
  o.rootRadius = std::max(o.minRadius, 4.0 / out.anisotropy);
  o.minTerminals = 4;
  o.maxTerminals = 8;
  o.contrastFalloff = out.falloff;
  o.branchAngleMinDeg = 10;
  o.branchAngleMaxDeg = 60;
  const VesselPhantom ph = makeVesselPhantom(o);
  out.truth = ph.truth;
  out.volume = toFloat(AnyVolume(ph.volume));
  // Bias: 1 + bias * f, f in [-1/2, 1/2], a smooth wave along a random direction.
  Vec3 dir(rng.normal(), rng.normal(), rng.normal());
  dir.normalize();
  const double phase = rng.uniform(0.0, 2 * M_PI);
  const Geometry& g = out.volume.geometry();
  const double extent = (g.spacing.cwiseProduct(Vec3(double(dims[0]), double(dims[1]), double(dims[2])))).norm();
  PhantomRng noise(PhantomRng::derive(seed, 0x51c3));
  const double fg = o.foreground, bg = o.background;
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) {
        const Vec3 p = g.spacing.cwiseProduct(Vec3(double(x), double(y), double(z)));
        const double f = 0.5 * std::sin(phase + 2 * M_PI * p.dot(dir) / extent);
        double v = out.volume(x, y, z);
        if (out.dark) v = fg + bg - v;
        v *= 1.0 + out.bias * f;
        const double a = v + noise.normal(0, out.rician), b = noise.normal(0, out.rician);
        out.volume(x, y, z) = static_cast<float>(std::sqrt(a * a + b * b));
      }
  return out;
}

}  // namespace vs
