// `volscissors phantom vessels|vessel-family|head|head-family|shapes2d`: writes a synthetic volume (or 2D image)
// and its ground truth as JSON. Deterministic for a given --seed.
//   vessels  : uint8 tree of bright tubes on a dark noisy background
//   vessel-family : float32 randomised vessel case (phantom.h makeVesselFamilyCase; --size only for a
//              seed that draws the thin tree: the other variants are sized to their geometry)
//   head     : int16 HU-like nested ellipsoids (skin, skull, brain) with a nose
//   head-family : int16 randomised head (head_family.h makeHeadFamilyPhantom) with --labels and the
//              loops of its nose, ear, forehead and cheek in the truth
//   shapes2d : uint8 2D image (dims X,Y,1) of blurred noisy shapes (+ optional --labels)
// Exit status: 2 for bad options (size, spacing, noise, kind), 1 for I/O errors.
#include <cmath>
#include <initializer_list>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "args.h"
#include "command.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"
#include "phantom/head_family.h"
#include "phantom/phantom.h"
#include "progress_line.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

constexpr int64_t kMaxDim = 8192;
const vs::VesselPhantomOptions kVessels;
const vs::HeadPhantomOptions kHead;
const vs::Shapes2DOptions kShapes;

std::string numberText(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
std::string listText(std::initializer_list<double> values) {
  std::string s;
  for (double v : values) s += (s.empty() ? "" : ",") + numberText(v);
  return s;
}
std::string dimsText(const vs::Index3& d) { return listText({double(d[0]), double(d[1]), double(d[2])}); }

struct Args {
  std::string kind;
  uint64_t seed = 1;
  std::string size;
  std::string spacing;
  double noise = 0;
  bool noiseGiven = false;  // otherwise the kind's default
  std::string out, truth, labels;
};

int run(const Args& a) {
  const bool is2D = a.kind == "shapes2d";
  const vs::Index3 defaultDims = a.kind == "head" ? kHead.dims
                                 : is2D           ? vs::Index3{kShapes.width, kShapes.height, 1}
                                                  : kVessels.dims;
  const vs::Index3 dims = a.size.empty() ? defaultDims : vs::cli::parseDims(a.size, "--size", kMaxDim, is2D);
  vs::Vec3 spacing = a.kind == "head" ? kHead.spacing
                     : is2D           ? vs::Vec3(kShapes.spacing[0], kShapes.spacing[1], 1)
                                      : kVessels.spacing;
  if (!a.spacing.empty()) {
    const auto sp = vs::cli::parseNumbers(a.spacing, "--spacing", 3, 2);
    for (size_t i = 0; i < sp.size(); ++i) {
      if (!(sp[i] >= 1e-4 && sp[i] <= 1000))  // the phantom generators' limits (phantom_internal.h)
        throw vs::UsageError("--spacing '" + a.spacing + "': every spacing must be in [0.0001, 1000] mm");
      spacing[static_cast<int>(i)] = sp[i];
    }
  }
  if (is2D && dims[2] != 1) throw vs::UsageError("--size: shapes2d makes a 2D image, Z must be 1");
  if (a.noiseGiven && (!std::isfinite(a.noise) || a.noise < 0 || a.noise > 1000))
    throw vs::UsageError("--noise must be a finite sigma in [0, 1000]");
  if (a.kind == "head-family" && (!a.size.empty() || !a.spacing.empty() || a.noiseGiven))
    throw vs::UsageError(
        "head-family draws its own size, spacing and noise from --seed: drop --size/--spacing/--noise");
  const size_t bytesPerVoxel = a.kind == "head" || a.kind == "head-family" ? 2 : a.kind == "vessel-family" ? 4 : 1;
  uint64_t total = bytesPerVoxel;
  for (int64_t d : dims) total *= static_cast<uint64_t>(d);
  // Vessel phantoms written as OME-Zarr are generated chunk by chunk: no memory limit.
  const bool chunked = a.kind == "vessels" && vs::isZarrPath(a.out);
  if (!chunked && total > vs::maxVolumeBytes() / 4)
    throw vs::UsageError("--size " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                         std::to_string(dims[2]) + " is too large for this machine");
  vs::cli::requireExtension(a.out, "--out", vs::cli::volumeOutputExtensions());
  if (!a.labels.empty() && !is2D && a.kind != "head-family")
    throw vs::UsageError("--labels is only available for shapes2d and head-family");
  if (!a.labels.empty()) vs::cli::requireExtension(a.labels, "--labels", vs::cli::volumeOutputExtensions());
  vs::OutputSet outputs;  // everything or nothing; paths checked before any work
  outputs.add(a.out);
  if (!a.truth.empty()) outputs.add(a.truth);
  if (!a.labels.empty()) outputs.add(a.labels);

  vs::cli::ProgressLine progressLine("phantom");
  vs::AnyVolume volume;
  std::optional<vs::AnyVolume> labels;
  nlohmann::json truth;
  std::string summary;
  if (chunked) {
    vs::VesselPhantomOptions o;
    o.seed = a.seed;
    o.dims = dims;
    o.spacing = spacing;
    if (a.noiseGiven) o.noiseSigma = a.noise;
    vs::Geometry g;
    g.dims = dims;
    g.spacing = spacing;
    vs::VesselTruth vt;
    outputs.write(a.out, [&](const std::string& t) {
      vs::ZarrWriter w(t, g, vs::VoxelType::UInt8);
      vt = vs::makeVesselPhantomChunked(
          o, w.chunkSize(), [&w](const vs::Index3& c, const float* v) { w.writeChunk(c, v); }, progressLine.progress());
      w.finish(progressLine.progress());
    });
    if (!a.truth.empty()) outputs.write(a.truth, [&](const std::string& t) { vs::writeTruthFile(vs::toJson(vt), t); });
    outputs.commit();
    progressLine.clear();
    std::cout << a.kind << " " << g.describe() << " uint8 (OME-Zarr, written chunk by chunk), seed " << a.seed << ": "
              << vt.branches.size() << " branches, " << vt.terminalVoxels.size() << " terminals, "
              << vt.branchPoints.size() << " branch points -> " << a.out
              << (a.truth.empty() ? "" : " (truth " + a.truth + ")") << "\n";
    return 0;
  }
  if (a.kind == "vessels") {
    vs::VesselPhantomOptions o;
    o.seed = a.seed;
    o.dims = dims;
    o.spacing = spacing;
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeVesselPhantom(o, progressLine.progress());
    summary = std::to_string(ph.truth.branches.size()) + " branches, " +
              std::to_string(ph.truth.terminalVoxels.size()) + " terminals, " +
              std::to_string(ph.truth.branchPoints.size()) + " branch points";
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.volume);
  } else if (a.kind == "vessel-family") {
    if (!a.spacing.empty() || a.noiseGiven)
      throw vs::UsageError("vessel-family draws its own spacing and noise from --seed: drop --spacing/--noise");
    const vs::VesselFamilyVariant variant = vs::vesselFamilyVariantOf(a.seed);
    if (!a.size.empty() && variant != vs::VesselFamilyVariant::Thin)
      throw vs::UsageError("vessel-family seed " + std::to_string(a.seed) + " draws the " +
                           vs::vesselFamilyVariantName(variant) +
                           " variant, whose volume is sized to its drawn geometry: drop --size");
    auto c = vs::makeVesselFamilyCase(a.seed, a.size.empty() ? vs::Index3{80, 80, 48} : dims);
    summary = c.describe() + ", " + std::to_string(c.truth.terminalVoxels.size()) + " terminals";
    truth = vs::toJson(c.truth);
    volume = std::move(c.volume);
  } else if (a.kind == "head") {
    vs::HeadPhantomOptions o;
    o.seed = a.seed;
    o.dims = dims;
    o.spacing = spacing;
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeHeadPhantom(o, progressLine.progress());
    std::ostringstream s;
    s << "iso skin " << ph.truth.isoSkin << " HU, iso bone " << ph.truth.isoBone << " HU";
    summary = s.str();
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.volume);
  } else if (a.kind == "head-family") {
    vs::HeadFamilyOptions o;
    o.seed = a.seed;
    auto ph = vs::makeHeadFamilyPhantom(o, progressLine.progress());
    std::ostringstream s;
    s << "iso " << ph.truth.iso << " HU, soft tissue " << ph.truth.skinMm + ph.truth.fatMm + ph.truth.muscleMm
      << " mm, skull " << ph.truth.boneMm << " mm";
    summary = s.str();
    truth = vs::toJson(ph.truth, ph.volume.geometry());
    if (!a.labels.empty()) labels = std::move(ph.labels);
    volume = std::move(ph.volume);
  } else {
    vs::Shapes2DOptions o;
    o.seed = a.seed;
    o.width = dims[0];
    o.height = dims[1];
    o.spacing = vs::Vec2(spacing[0], spacing[1]);
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeShapes2DPhantom(o, progressLine.progress());
    summary = std::to_string(ph.truth.shapes.size()) + " shapes";
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.image);
    if (!a.labels.empty()) labels = std::move(ph.labels);
  }

  outputs.write(a.out, [&](const std::string& t) { vs::writeVolume(volume, t); });
  if (!a.truth.empty()) outputs.write(a.truth, [&](const std::string& t) { vs::writeTruthFile(truth, t); });
  if (labels) outputs.write(a.labels, [&](const std::string& t) { vs::writeVolume(*labels, t); });
  outputs.commit();
  const vs::Geometry& g = vs::geometryOf(volume);
  progressLine.clear();
  std::cout << a.kind << " " << g.describe() << " " << vs::voxelTypeName(vs::voxelType(volume)) << ", seed " << a.seed
            << ": " << summary << " -> " << a.out << (a.truth.empty() ? "" : " (truth " + a.truth + ")") << "\n";
  return 0;
}

const vs::cli::Registration reg{
    "phantom", "write a synthetic test volume (vessels, head, head-family, shapes2d) and its ground truth",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option(
             "kind", a->kind,
             "vessels | vessel-family (randomised: variant - thin tree, wide lumen, kissing or parallel vessels -, "
             "spacing, radii, contrast falloff, bias, polarity, Rician noise drawn from --seed; a thin tree "
             "in 80,80,48 or --size, the others sized to their geometry) | head | head-family (randomised head for "
             "cutting: layers, skull, nose, ear, chin, spacing, noise and bias drawn from --seed; --labels "
             "writes its truth labels, --truth its loops) | shapes2d")
          ->required()
          ->check(CLI::IsMember({"vessels", "vessel-family", "head", "head-family", "shapes2d"}));
      sub.add_option("--seed", a->seed, "random seed, >= 0 (same seed -> identical output)")
          ->check(CLI::NonNegativeNumber)
          ->capture_default_str();
      sub.add_option("--size", a->size,
                     "X,Y,Z voxels (default vessels " + dimsText(kVessels.dims) + ", head " + dimsText(kHead.dims) +
                         "; shapes2d: X,Y[,1], default " + listText({double(kShapes.width), double(kShapes.height)}) +
                         ")");
      sub.add_option("--spacing", a->spacing,
                     "sx,sy,sz mm per voxel (default vessels " +
                         listText({kVessels.spacing[0], kVessels.spacing[1], kVessels.spacing[2]}) + ", head " +
                         listText({kHead.spacing[0], kHead.spacing[1], kHead.spacing[2]}) + ", shapes2d " +
                         listText({kShapes.spacing[0], kShapes.spacing[1]}) + ")");
      CLI::Option* noise = sub.add_option(
          "--noise", a->noise,
          "Gaussian noise sigma in grey levels / HU (default: vessels " + numberText(kVessels.noiseSigma) + ", head " +
              numberText(kHead.noiseSigma) + ", shapes2d " + numberText(kShapes.noiseSigma) + ")");
      sub.add_option(
             "--out", a->out,
             "output volume (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, or an OME-Zarr folder .zarr: vessels are then "
             "generated chunk by chunk, any size)")
          ->required();
      sub.add_option("--truth", a->truth, "ground truth JSON (voxel index coordinates x,y,z)");
      sub.add_option("--labels", a->labels,
                     "shapes2d: label image (0 background, 1..n shapes); head-family: label volume (0 air, 1 soft "
                     "tissue, 2 bone, 3 brain, 4 nose, 5 ear)");
      return [a, noise] {
        a->noiseGiven = noise->count() > 0;
        return run(*a);
      };
    }};

}  // namespace
