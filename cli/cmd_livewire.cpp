// `volscissors livewire FILE [--slice z=K] --points "u,v;u,v;..." [--world] [--closed] [--cost mb|gradient]
//   [--snap R] [--smooth SIGMA_MM] --out contour.json [--mask mask.nii.gz]`
// 2D live-wire (thesis 2.3) on one slice of a volume, driven by a list of clicked points:
// the contour runs from each point to the next along the minimum-cost path, optionally
// closed back to the first point. Points are slice pixel coordinates (u, v), 0-based
// (axial z=K: u = x, v = y; coronal y=K: u = x, v = z; sagittal x=K: u = y, v = z).
// Output JSON: points (contour pixels), closed, length_mm, cost, slice, points_index (x,y,z),
// points_world (mm), clicks (after snapping), clicks_input, area (closed only).
// --mask writes a uint8 label volume of the full volume size with the filled slice contour = 1.
// Exit 2: bad point syntax, points outside the slice, consecutive duplicate points, slice out
// of range; exit 1: unreadable file, NaN/inf pixels in the slice.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "command.h"
#include "io/volume_io.h"
#include "scissors/live_wire.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

// Calls parse(item, stream over the item) for each non-blank item of a ';'-separated list; parse
// reads the point and throws a UsageError naming the item when it is malformed.
template <class Parse>
void forEachListItem(const std::string& text, Parse&& parse) {
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    if (item.find_first_not_of(" \t") == std::string::npos) continue;
    std::stringstream one(item);
    parse(item, one);
  }
}

// "u,v;u,v;..." integer pixel coordinates (the default).
std::vector<vs::PixelUV> parsePoints(const std::string& text) {
  std::vector<vs::PixelUV> pts;
  forEachListItem(text, [&pts](const std::string& item, std::stringstream& one) {
    long long u = 0, v = 0;
    char comma = 0;
    std::string rest;
    if (!(one >> u >> comma >> v) || comma != ',' || (one >> rest))
      throw vs::UsageError("--points: cannot parse '" + item + "' (expected \"u,v;u,v;...\" integer pixel coordinates)");
    pts.push_back({u, v});
  });
  return pts;
}

// "x,y,z;x,y,z;..." world millimetres (for --world).
std::vector<vs::Vec3> parseWorldPoints(const std::string& text) {
  std::vector<vs::Vec3> pts;
  forEachListItem(text, [&pts](const std::string& item, std::stringstream& one) {
    double x = 0, y = 0, z = 0;
    char c1 = 0, c2 = 0;
    std::string rest;
    if (!(one >> x >> c1 >> y >> c2 >> z) || c1 != ',' || c2 != ',' || (one >> rest) || !std::isfinite(x) ||
        !std::isfinite(y) || !std::isfinite(z))
      throw vs::UsageError("--points: cannot parse '" + item + "' (with --world: \"x,y,z;x,y,z;...\" in mm)");
    pts.emplace_back(x, y, z);
  });
  return pts;
}

std::string fmt(double x, int prec = 2) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(prec) << x;
  return os.str();
}

}  // namespace

namespace {
const vs::cli::Registration reg{
    "livewire", "2D live-wire (intelligent scissors) contour on one slice from clicked points",
    [](CLI::App& sub) -> vs::cli::Runner {
      struct Args {
        std::string file, slice, points, cost = "mb", out, mask;
        bool closed = false, world = false;
        double snap = 0, smooth = 0;
        double wz = 0.43, wg = 0.43, wd = 0.14;
      };
      auto a = std::make_shared<Args>();
      sub.add_option("file", a->file, "volume or 2D image (NIfTI, NRRD, MetaImage, DICOM dir, PNG...)")->required();
      sub.add_option("--slice", a->slice, "slice to work on: z=K (axial), y=K (coronal), x=K (sagittal); default: middle axial slice");
      sub.add_option("--points", a->points, "clicked points \"u,v;u,v;...\" in slice pixels (0-based)")->required();
      sub.add_flag("--world", a->world,
                   "--points are world mm \"x,y,z;...\" (LPS, as `info` reports the geometry); each must lie on the "
                   "slice (default slice: the axial one through the first point)");
      sub.add_flag("--closed", a->closed, "close the contour back to the first point (needs >= 3 points)");
      sub.add_option("--cost", a->cost, "edge cost: mb (Mortensen-Barrett, eq. 7-11) or gradient (Stalling-Hege, eq. 12)")
          ->capture_default_str();
      sub.add_option("--weights", [a](const CLI::results_t& r) {
            if (r.size() != 3) return false;
            a->wz = std::stod(r[0]), a->wg = std::stod(r[1]), a->wd = std::stod(r[2]);
            return true;
          }, "MB weights wZ wG wD (default 0.43 0.43 0.14)")->expected(3);
      sub.add_option("--snap", a->snap, "move each point to the strongest edge within this radius (pixels; 0 = off)")
          ->capture_default_str();
      sub.add_option("--smooth", a->smooth, "Gaussian pre-smoothing sigma in mm (0 = off)")->capture_default_str();
      sub.add_option("--out,--json", a->out, "contour JSON output")->required();
      sub.add_option("--mask", a->mask, "label volume output (uint8, full volume size, filled contour = 1); needs --closed");
      return [a]() -> int {
        std::vector<vs::PixelUV> input;
        std::vector<vs::Vec3> worldInput;
        if (a->world) {
          worldInput = parseWorldPoints(a->points);
          input.resize(worldInput.size());
        } else {
          input = parsePoints(a->points);
        }
        if (input.size() < 2) throw vs::UsageError("--points: need at least 2 points, got " + std::to_string(input.size()));
        if (a->closed && input.size() < 3) throw vs::UsageError("--closed needs at least 3 points");
        if (!a->mask.empty() && !a->closed) throw vs::UsageError("--mask needs --closed (an open contour has no inside)");
        if (!(a->snap >= 0) || !std::isfinite(a->snap)) throw vs::UsageError("--snap must be a radius >= 0");
        if (!(a->smooth >= 0) || !std::isfinite(a->smooth)) throw vs::UsageError("--smooth must be a sigma >= 0 mm");
        vs::LiveWireOptions opt;
        opt.cost.kind = vs::parseLiveWireCostKind(a->cost);
        opt.cost.weightZ = a->wz, opt.cost.weightG = a->wg, opt.cost.weightD = a->wd;
        opt.features.smoothSigmaMm = a->smooth;
        vs::checkOutputPath(a->out);
        if (!a->mask.empty()) vs::checkOutputPath(a->mask);

        const vs::AnyVolume vol = vs::readVolume(a->file);
        const vs::Geometry geom = vs::geometryOf(vol);
        int axis = 2;
        int64_t index = geom.dims[2] / 2;
        if (a->world && a->slice.empty()) index = vs::roundIndex(geom.worldToIndex(worldInput[0]))[2];
        if (!a->slice.empty()) std::tie(axis, index) = vs::parseSliceSpec(a->slice);
        if (a->world) {
          // World mm -> continuous index -> slice pixel (u, v); the point must lie on the slice.
          for (size_t i = 0; i < worldInput.size(); ++i) {
            const vs::Vec3 c = geom.worldToIndex(worldInput[i]);
            if (std::abs(c[axis] - static_cast<double>(index)) > 0.5 + 1e-6)
              throw vs::InvalidArgument("--points: world point " + std::to_string(i + 1) + " lies at index " +
                                        fmt(c[axis]) + " along " + "xyz"[axis] + ", not on slice " +
                                        std::string(1, "xyz"[axis]) + "=" + std::to_string(index));
            const vs::Index3 r = vs::roundIndex(c);
            input[i] = axis == 0 ? vs::PixelUV{r[1], r[2]} : axis == 1 ? vs::PixelUV{r[0], r[2]} : vs::PixelUV{r[0], r[1]};
          }
        }
        if (index < 0 || index >= geom.dims[axis])
          throw vs::UsageError("--slice " + a->slice + ": index outside 0.." + std::to_string(geom.dims[axis] - 1));
        const std::string sliceName = vs::describeSlice(axis, index);
        vs::LiveWire lw = std::visit(
            [&](const auto& v) { return vs::LiveWire::fromSlice(vs::sliceView(v, axis, index), opt, sliceName + " of " + a->file); },
            vol);

        for (const auto& p : input)
          if (!lw.contains(p))
            throw vs::InvalidArgument("--points: point (" + std::to_string(p[0]) + "," + std::to_string(p[1]) +
                                      ") is outside the " + std::to_string(lw.width()) + "x" +
                                      std::to_string(lw.height()) + " " + sliceName);
        std::vector<vs::PixelUV> clicks;
        for (const auto& p : input) clicks.push_back(a->snap > 0 ? lw.snap(p, a->snap) : p);
        for (size_t i = 1; i < clicks.size(); ++i)
          if (clicks[i] == clicks[i - 1])
            throw vs::InvalidArgument("--points: points " + std::to_string(i) + " and " + std::to_string(i + 1) +
                                      " are the same pixel (" + std::to_string(clicks[i][0]) + "," +
                                      std::to_string(clicks[i][1]) + ")" + (a->snap > 0 ? " after snapping" : "") +
                                      ": the seed equals the target");
        if (a->closed && clicks.back() == clicks.front()) clicks.pop_back();  // "closed" already says it
        if (a->closed && clicks.size() < 3) throw vs::UsageError("--closed needs at least 3 distinct points");

        lw.setSeed(clicks.front());
        for (size_t i = 1; i < clicks.size(); ++i) lw.commit(clicks[i]);
        if (a->closed) lw.close();
        const vs::LiveWireContour c = lw.contour();

        nlohmann::json j;
        auto uvList = [](const std::vector<vs::PixelUV>& px) {
          nlohmann::json arr = nlohmann::json::array();
          for (const auto& p : px) arr.push_back({p[0], p[1]});
          return arr;
        };
        j["file"] = a->file;
        j["slice"] = {{"axis", std::string(1, "xyz"[axis])}, {"index", index}, {"width", lw.width()},
                      {"height", lw.height()}, {"spacing_mm", {lw.features().spacingU, lw.features().spacingV}}};
        j["cost_kind"] = vs::liveWireCostKindName(opt.cost.kind);
        j["weights"] = {{"zero_crossing", opt.cost.weightZ}, {"gradient", opt.cost.weightG}, {"direction", opt.cost.weightD}};
        j["smooth_mm"] = opt.features.smoothSigmaMm;
        j["snap_px"] = a->snap;
        j["closed"] = c.closed;
        j["points"] = uvList(c.pixels);
        nlohmann::json idx = nlohmann::json::array(), world = nlohmann::json::array();
        for (const auto& p : c.pixels) {
          const vs::Index3 i = vs::sliceToVolumeIndex(axis, index, p);
          idx.push_back({i[0], i[1], i[2]});
          const vs::Vec3 w = geom.indexToWorld(vs::Vec3(double(i[0]), double(i[1]), double(i[2])));
          world.push_back({w.x(), w.y(), w.z()});
        }
        j["points_index"] = std::move(idx);
        j["points_world"] = std::move(world);
        j["clicks"] = uvList(clicks);
        j["clicks_input"] = uvList(input);
        j["length_mm"] = c.lengthMm;
        j["cost"] = c.cost;
        nlohmann::json segs = nlohmann::json::array();
        for (const auto& s : lw.segments())
          segs.push_back({{"from", {s.from[0], s.from[1]}}, {"to", {s.to[0], s.to[1]}}, {"pixels", s.pixels.size()},
                          {"cost", s.cost}, {"length_mm", s.lengthMm}});
        j["segments"] = std::move(segs);

        std::string summary = "livewire: " + sliceName + ", " + std::to_string(clicks.size()) + " points -> " +
                              std::to_string(c.pixels.size()) + " contour pixels" + (c.closed ? " (closed)" : "") +
                              ", length " + fmt(c.lengthMm) + " mm, cost " + fmt(c.cost, 3);
        if (c.closed) {
          const std::vector<uint8_t> mask2d = vs::fillContour(c.pixels, lw.width(), lw.height());
          int64_t area = 0;
          for (uint8_t m : mask2d) area += m;
          const double areaMm2 = static_cast<double>(area) * lw.features().spacingU * lw.features().spacingV;
          j["area_pixels"] = area;
          j["area_mm2"] = areaMm2;
          summary += ", area " + fmt(areaMm2) + " mm^2 (" + std::to_string(area) + " px)";
          if (!a->mask.empty()) {
            vs::Geometry mg = geom;
            vs::VolumeU8 label(mg, 0);
            for (int64_t v = 0; v < lw.height(); ++v)
              for (int64_t u = 0; u < lw.width(); ++u)
                if (mask2d[static_cast<size_t>(u + lw.width() * v)]) {
                  const vs::Index3 i = vs::sliceToVolumeIndex(axis, index, {u, v});
                  label(i[0], i[1], i[2]) = 1;
                }
            vs::writeVolume(vs::AnyVolume(std::move(label)), a->mask);
            j["mask"] = a->mask;
          }
        }
        vs::writeFileAtomically(a->out, j.dump(1) + "\n");
        std::cout << summary << '\n';
        return 0;
      };
    }};
}  // namespace
