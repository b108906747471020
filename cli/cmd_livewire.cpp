// `volscissors livewire FILE [--slice z=K] --points "u,v;u,v;..." [--picture | --world] [--closed]
//   [--cost mb|gradient] [--weights wZ wG wD] [--connectivity 4|8] [--gradient-quantile Q]
//   [--snap R] [--smooth SIGMA_MM] --out contour.json [--mask mask.nii.gz]`
// 2D live-wire (thesis 2.3) on one slice of a volume, driven by a list of clicked points: the
// contour runs from each point to the next along the minimum-cost path, optionally closed back
// to the first point. Points are slice pixels (u, v) (volume/slice.h), voxel indices x,y,z on
// the slice, picture pixels (col, row) of `render --mode slice --voxel-pixels` (--picture), or
// world mm (--world). The document is written by io/contour_io; --mask writes a uint8 label
// volume of the full volume size with the filled slice contour = 1.
// Exit 2: bad point syntax, points outside the slice or off its plane, duplicate consecutive
// points, slice out of range, options that do not apply; exit 1: unreadable file, NaN pixels.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "args.h"
#include "command.h"
#include "io/contour_io.h"
#include "io/volume_io.h"
#include "scissors/live_wire.h"
#include "scissors/live_wire_document.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/text.h"
#include "volume/slice.h"

namespace {

std::string fmt(double x, int decimals = 2) { return vs::fixedText(x, decimals); }
using vs::numberText;

struct Args {
  std::string file, slice, points, cost, out, mask;
  bool closed = false, world = false, picture = false;
  double snap = 0;
  vs::LiveWireOptions opt;
  std::vector<double> weights;
};

int run(Args& a) {
  if (a.world && a.picture) throw vs::UsageError("--world and --picture exclude each other");
  const std::vector<size_t> accepted = a.world     ? std::vector<size_t>{3}
                                       : a.picture ? std::vector<size_t>{2}
                                                   : std::vector<size_t>{2, 3};
  const auto raw = vs::cli::parsePointList(a.points, "--points", accepted, !a.world);
  if (raw.size() < 2) throw vs::UsageError("--points: need at least 2 points, got " + std::to_string(raw.size()));
  const bool triples = raw[0].size() == 3;
  for (const auto& p : raw)
    if (p.size() != raw[0].size())
      throw vs::UsageError("--points: mix of u,v pixels and x,y,z voxels; give all points the same way");
  if (a.closed && raw.size() < 3) throw vs::UsageError("--closed needs at least 3 points");
  if (!a.mask.empty() && !a.closed) throw vs::UsageError("--mask needs --closed (an open contour has no inside)");
  if (!(a.snap >= 0) || !std::isfinite(a.snap)) throw vs::UsageError("--snap must be a radius >= 0");
  a.opt.cost.kind = vs::parseLiveWireCostKind(a.cost);
  const bool mb = a.opt.cost.kind == vs::LiveWireCostKind::MortensenBarrett;
  if (!a.weights.empty()) {
    if (!mb) throw vs::UsageError("--weights apply to --cost mb only (the gradient cost has no weights)");
    a.opt.cost.weightZ = a.weights[0], a.opt.cost.weightG = a.weights[1], a.opt.cost.weightD = a.weights[2];
  }
  vs::OutputSet outputs;  // contour and mask together or nothing
  outputs.add(a.out);
  if (!a.mask.empty()) {
    vs::cli::requireExtension(a.mask, "--mask", vs::cli::volumeOutputExtensions());
    outputs.add(a.mask);
  }

  const vs::AnyVolume vol = vs::readVolume(a.file);
  const vs::Geometry geom = vs::geometryOf(vol);
  // Points as continuous voxel indices where given so (index triples, world mm).
  std::vector<vs::Vec3> given;
  if (triples)
    for (const auto& p : raw)
      given.push_back(a.world ? geom.worldToIndex(vs::Vec3(p[0], p[1], p[2])) : vs::Vec3(p[0], p[1], p[2]));
  int axis = 2;
  int64_t index = geom.dims[2] / 2;
  if (triples && a.slice.empty()) index = vs::roundIndex(given[0])[2];  // the axial slice through the first point
  if (!a.slice.empty()) std::tie(axis, index) = vs::parseSliceSpec(a.slice);
  if (index < 0 || index >= geom.dims[static_cast<size_t>(axis)])
    throw vs::UsageError(
        (a.slice.empty() ? "the first point's axial slice " + vs::sliceName(axis, index) : "--slice " + a.slice) +
        " is outside the volume (0.." + std::to_string(geom.dims[static_cast<size_t>(axis)] - 1) + ")");
  const vs::SliceFrame frame = vs::sliceFrame(geom, axis, index);
  const std::string sliceName = vs::describeSlice(axis, index);
  const auto [ua, va] = vs::sliceInPlaneAxes(axis);

  std::vector<vs::PixelUV> input;
  for (size_t i = 0; i < raw.size(); ++i) {
    vs::Vec3 c;
    if (triples) {
      c = given[i];
      if (std::abs(c[axis] - static_cast<double>(index)) > 0.5 + 1e-6)
        throw vs::InvalidArgument("--points: point " + std::to_string(i + 1) + " (" + (a.world ? "world " : "voxel ") +
                                  numberText(raw[i][0]) + "," + numberText(raw[i][1]) + "," + numberText(raw[i][2]) +
                                  ") lies at " + std::string(1, "xyz"[axis]) + "=" + fmt(c[axis]) + ", not on slice " +
                                  vs::sliceName(axis, index) + " (" + vs::anatomicalPlaneName(frame.plane) + ")");
    } else if (a.picture) {
      c = frame.indexOf(raw[i][0], raw[i][1]);
    } else {
      c[ua] = raw[i][0];
      c[va] = raw[i][1];
    }
    const vs::Index3 r = vs::roundIndex(c);
    input.push_back({r[static_cast<size_t>(ua)], r[static_cast<size_t>(va)]});
  }

  vs::LiveWire lw = vs::liveWireOnSlice(vol, axis, index, a.opt, sliceName + " of " + a.file);
  for (size_t i = 0; i < input.size(); ++i)
    if (!lw.contains(input[i])) {
      const std::string how = a.picture ? "picture pixel (" + numberText(raw[i][0]) + "," + numberText(raw[i][1]) + ")"
                                        : "point " + std::to_string(i + 1);
      throw vs::InvalidArgument("--points: " + how + " is outside the " + std::to_string(lw.width()) + "x" +
                                std::to_string(lw.height()) + " " + sliceName + " (slice pixel " +
                                std::to_string(input[i][0]) + "," + std::to_string(input[i][1]) + ")");
    }
  std::vector<vs::PixelUV> clicks;
  for (const auto& p : input) clicks.push_back(a.snap > 0 ? lw.snap(p, a.snap) : p);
  for (size_t i = 1; i < clicks.size(); ++i)
    if (clicks[i] == clicks[i - 1])
      throw vs::InvalidArgument("--points: points " + std::to_string(i) + " and " + std::to_string(i + 1) +
                                " are the same pixel (" + std::to_string(clicks[i][0]) + "," +
                                std::to_string(clicks[i][1]) + ")" + (a.snap > 0 ? " after snapping" : "") +
                                ": the seed equals the target");
  if (a.closed && clicks.back() == clicks.front()) clicks.pop_back();  // "closed" already says it
  if (a.closed && clicks.size() < 3) throw vs::UsageError("--closed needs at least 3 distinct points");

  lw.setSeed(clicks.front());
  for (size_t i = 1; i < clicks.size(); ++i) lw.commit(clicks[i]);
  if (a.closed) lw.close();
  const vs::LiveWireContour c = lw.contour();
  vs::ContourDocument doc = vs::contourDocument(lw, geom, axis, index, {input, clicks, a.snap}, a.file);

  std::string summary = "livewire: " + sliceName + " (" + doc.plane + "), " + std::to_string(clicks.size()) +
                        " points -> " + std::to_string(c.pixels.size()) + " contour pixels" +
                        (c.closed ? " (closed)" : "") + ", length " + fmt(c.lengthMm) + " mm, cost " + fmt(c.cost, 3);
  if (c.closed) {
    summary += ", area " + fmt(*doc.areaMm2) + " mm^2 (" + std::to_string(*doc.areaPixels) + " px)";
    if (!a.mask.empty()) {
      const std::vector<uint8_t> mask2d = vs::fillContour(c.pixels, lw.width(), lw.height());
      const vs::VolumeU8 label = vs::sliceMaskVolume(geom, axis, index, mask2d, lw.width(), lw.height());
      outputs.write(a.mask, [&](const std::string& t) { vs::writeVolume(vs::AnyVolume(label), t); });
      doc.mask = a.mask;
    }
  }
  outputs.write(a.out, [&](const std::string& t) { vs::writeContour(doc, t); });
  outputs.commit();
  std::cout << summary << '\n';
  return 0;
}

const vs::cli::Registration reg{
    "livewire", "2D live-wire (intelligent scissors) contour on one slice from clicked points",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      a->cost = vs::liveWireCostKindName(a->opt.cost.kind);
      sub.add_option("file", a->file, "volume or 2D image (NIfTI, NRRD, MetaImage, DICOM dir, PNG...)")->required();
      sub.add_option("--slice", a->slice,
                     "slice to work on: z=K, y=K or x=K (index axes; `info` tells which anatomical plane each is); "
                     "default: the middle z slice, or the z slice through the first x,y,z point");
      sub.add_option("--points", a->points,
                     "clicked points, ';'-separated: \"u,v;...\" slice pixels (x=K: u=y, v=z; y=K: u=x, v=z; z=K: u=x, "
                     "v=y; 0-based), or \"x,y,z;...\" voxel indices on the slice")
          ->required();
      sub.add_flag("--picture", a->picture,
                   "--points are \"col,row;...\" pixels of the slice picture `render --mode slice --plane AXIS=K "
                   "--voxel-pixels` writes (anatomical orientation, one pixel per voxel)");
      sub.add_flag(
          "--world", a->world,
          "--points are world mm \"x,y,z;...\" (LPS, as `info` reports the geometry); each must lie on the slice");
      sub.add_flag("--closed", a->closed, "close the contour back to the first point (needs >= 3 points)");
      sub.add_option("--cost", a->cost,
                     "edge cost: mb (Mortensen-Barrett, eq. 7-11) or gradient (Stalling-Hege, eq. 12)")
          ->capture_default_str();
      sub.add_option("--weights", a->weights,
                     "mb weights wZ wG wD (default " + numberText(a->opt.cost.weightZ) + " " +
                         numberText(a->opt.cost.weightG) + " " + numberText(a->opt.cost.weightD) + ")")
          ->expected(3);
      sub.add_option("--connectivity", a->opt.connectivity, "pixel neighbourhood of the path: 4 or 8")
          ->check(CLI::IsMember({4, 8}))
          ->capture_default_str();
      sub.add_option("--gradient-quantile", a->opt.cost.gradientReferenceQuantile,
                     "gradient magnitude that counts as a full edge, as a quantile of the slice's magnitudes in (0, 1] "
                     "(1 = the maximum, eq. 9; e.g. 0.99 so one bright metal pixel does not flatten every cost)")
          ->capture_default_str();
      sub.add_option("--snap", a->snap, "move each point to the strongest edge within this radius (pixels; 0 = off)")
          ->capture_default_str();
      sub.add_option("--smooth", a->opt.features.smoothSigmaMm, "Gaussian pre-smoothing sigma in mm (0 = off)")
          ->capture_default_str();
      sub.add_option("--out,--json", a->out, "contour JSON output")->required();
      sub.add_option("--mask", a->mask,
                     "label volume output (uint8, full volume size, filled contour = 1); needs --closed");
      return [a] { return run(*a); };
    }};

}  // namespace
