// `volscissors phantom vessels|head|shapes2d`: writes a synthetic volume (or 2D image)
// and its ground truth as JSON. Deterministic for a given --seed.
//   vessels  : uint8 tree of bright tubes on a dark noisy background
//   head     : int16 HU-like nested ellipsoids (skin, skull, brain) with a nose
//   shapes2d : uint8 2D image (dims X,Y,1) of blurred noisy shapes (+ optional --labels)
// Exit status: 2 for bad options (size, spacing, noise, kind), 1 for I/O errors.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "command.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

constexpr int64_t kMaxDim = 8192;

std::vector<std::string> splitCommas(const std::string& s) {
  std::vector<std::string> parts;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) parts.push_back(item);
  if (!s.empty() && s.back() == ',') parts.push_back("");
  return parts;
}

// "X,Y,Z" (or "X,Y" when allow2D) of positive integers.
vs::Index3 parseSize(const std::string& text, bool allow2D) {
  const auto parts = splitCommas(text);
  if (parts.size() != 3 && !(allow2D && parts.size() == 2))
    throw vs::UsageError("--size '" + text + "': expected X,Y,Z" + std::string(allow2D ? " or X,Y" : ""));
  vs::Index3 d{1, 1, 1};
  for (size_t i = 0; i < parts.size(); ++i) {
    int64_t v = 0;
    const char* b = parts[i].data();
    const char* e = b + parts[i].size();
    const auto r = std::from_chars(b, e, v);
    if (parts[i].empty() || r.ec != std::errc() || r.ptr != e)
      throw vs::UsageError("--size '" + text + "': '" + parts[i] + "' is not an integer");
    if (v < 1 || v > kMaxDim)
      throw vs::UsageError("--size '" + text + "': every size must be in 1.." + std::to_string(kMaxDim));
    d[i] = v;
  }
  return d;
}

vs::Vec3 parseSpacing(const std::string& text) {
  const auto parts = splitCommas(text);
  if (parts.size() != 3 && parts.size() != 2) throw vs::UsageError("--spacing '" + text + "': expected sx,sy,sz");
  vs::Vec3 s(1, 1, 1);
  for (size_t i = 0; i < parts.size(); ++i) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(parts[i], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (parts[i].empty() || used != parts[i].size() || !std::isfinite(v) || v <= 0 || v > 1000)
      throw vs::UsageError("--spacing '" + text + "': '" + parts[i] + "' is not a spacing in (0, 1000] mm");
    s[static_cast<int>(i)] = v;
  }
  return s;
}

void checkVolumeExtension(const std::string& path) {
  const std::string ext = vs::fileExtension(path);
  for (const char* ok : {".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd"})
    if (ext == ok) return;
  throw vs::UsageError("--out '" + path + "': unsupported extension '" + ext +
                       "' (use .nii, .nii.gz, .nrrd, .nhdr, .mha or .mhd)");
}

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
  const vs::Index3 dims = parseSize(a.size.empty() ? (is2D ? "256,256,1" : "128,128,128") : a.size, is2D);
  const vs::Vec3 spacing = a.spacing.empty() ? vs::Vec3(1, 1, 1) : parseSpacing(a.spacing);
  if (is2D && dims[2] != 1) throw vs::UsageError("--size: shapes2d makes a 2D image, Z must be 1");
  if (a.noiseGiven && (!std::isfinite(a.noise) || a.noise < 0 || a.noise > 1000))
    throw vs::UsageError("--noise must be a finite sigma in [0, 1000]");
  const size_t bytesPerVoxel = a.kind == "head" ? 2 : 1;
  uint64_t total = bytesPerVoxel;
  for (int64_t d : dims) total *= static_cast<uint64_t>(d);
  if (total > vs::maxVolumeBytes() / 4)
    throw vs::UsageError("--size " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                         std::to_string(dims[2]) + " is too large for this machine");
  checkVolumeExtension(a.out);
  if (!a.labels.empty() && !is2D) throw vs::UsageError("--labels is only available for shapes2d");
  if (!a.labels.empty()) checkVolumeExtension(a.labels);
  std::vector<std::string> outputs{a.out};
  if (!a.truth.empty()) outputs.push_back(a.truth);
  if (!a.labels.empty()) outputs.push_back(a.labels);
  for (size_t i = 0; i < outputs.size(); ++i)
    for (size_t j = i + 1; j < outputs.size(); ++j)
      if (std::filesystem::absolute(outputs[i]) == std::filesystem::absolute(outputs[j]))
        throw vs::UsageError("output files must differ: '" + outputs[i] + "'");
  for (const auto& o : outputs) vs::checkOutputPath(o);  // before any work: IoError -> exit 1

  vs::AnyVolume volume;
  std::optional<vs::AnyVolume> labels;
  nlohmann::json truth;
  std::string summary;
  if (a.kind == "vessels") {
    vs::VesselPhantomOptions o;
    o.seed = a.seed;
    o.dims = dims;
    o.spacing = spacing;
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeVesselPhantom(o);
    summary = std::to_string(ph.truth.branches.size()) + " branches, " +
              std::to_string(ph.truth.terminalVoxels.size()) + " terminals, " +
              std::to_string(ph.truth.branchPoints.size()) + " branch points";
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.volume);
  } else if (a.kind == "head") {
    vs::HeadPhantomOptions o;
    o.seed = a.seed;
    o.dims = dims;
    o.spacing = spacing;
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeHeadPhantom(o);
    std::ostringstream s;
    s << "iso skin " << ph.truth.isoSkin << " HU, iso bone " << ph.truth.isoBone << " HU";
    summary = s.str();
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.volume);
  } else {
    vs::Shapes2DOptions o;
    o.seed = a.seed;
    o.width = dims[0];
    o.height = dims[1];
    o.spacing = vs::Vec2(spacing[0], spacing[1]);
    if (a.noiseGiven) o.noiseSigma = a.noise;
    auto ph = vs::makeShapes2DPhantom(o);
    summary = std::to_string(ph.truth.shapes.size()) + " shapes";
    truth = vs::toJson(ph.truth);
    volume = std::move(ph.image);
    if (!a.labels.empty()) labels = std::move(ph.labels);
  }

  // Write everything or nothing: remove earlier outputs if a later one fails.
  std::vector<std::string> written;
  try {
    vs::writeVolume(volume, a.out);
    written.push_back(a.out);
    if (!a.truth.empty()) {
      vs::writeTruthFile(truth, a.truth);
      written.push_back(a.truth);
    }
    if (labels) vs::writeVolume(*labels, a.labels);
  } catch (...) {
    std::error_code ec;
    for (const auto& w : written) std::filesystem::remove(w, ec);
    throw;
  }
  const vs::Geometry& g = vs::geometryOf(volume);
  std::cout << a.kind << " " << g.describe() << " " << vs::voxelTypeName(vs::voxelType(volume)) << ", seed " << a.seed
            << ": " << summary << " -> " << a.out << (a.truth.empty() ? "" : " (truth " + a.truth + ")") << "\n";
  return 0;
}

const vs::cli::Registration reg{
    "phantom", "write a synthetic test volume (vessels, head, shapes2d) and its ground truth",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option("kind", a->kind, "vessels | head | shapes2d")
          ->required()
          ->check(CLI::IsMember({"vessels", "head", "shapes2d"}));
      sub.add_option("--seed", a->seed, "random seed, >= 0 (same seed -> identical output)")
          ->check(CLI::NonNegativeNumber)
          ->capture_default_str();
      sub.add_option("--size", a->size, "X,Y,Z voxels (default 128,128,128; shapes2d: X,Y[,1], default 256,256)");
      sub.add_option("--spacing", a->spacing, "sx,sy,sz mm per voxel (default 1,1,1)");
      CLI::Option* noise = sub.add_option("--noise", a->noise,
                     "Gaussian noise sigma in grey levels / HU (default: vessels 10, head 10, shapes2d 8)");
      sub.add_option("--out", a->out, "output volume (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd)")->required();
      sub.add_option("--truth", a->truth, "ground truth JSON (voxel index coordinates x,y,z)");
      sub.add_option("--labels", a->labels, "shapes2d only: label image (0 background, 1..n shapes)");
      return [a, noise] {
        a->noiseGiven = noise->count() > 0;
        return run(*a);
      };
    }};

}  // namespace
