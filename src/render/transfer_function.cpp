#include "render/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>

#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {

namespace {
bool unitInterval(double x) { return std::isfinite(x) && x >= 0.0 && x <= 1.0; }
}  // namespace

TransferFunction::TransferFunction(std::vector<TfPoint> points, double unitDistance)
    : points_(std::move(points)), unitDistance_(unitDistance) {
  VS_REQUIRE(!points_.empty(), "transfer function: needs at least one point");
  VS_REQUIRE(std::isfinite(unitDistance_) && unitDistance_ > 0, "transfer function: unit_distance must be > 0");
  for (const auto& p : points_) {
    VS_REQUIRE(std::isfinite(p.value), "transfer function: point value is not finite");
    VS_REQUIRE(unitInterval(p.opacity), "transfer function: opacity " + std::to_string(p.opacity) + " at value " +
                                            std::to_string(p.value) + " is outside [0,1]");
    for (double c : p.color)
      VS_REQUIRE(unitInterval(c), "transfer function: colour component " + std::to_string(c) + " at value " +
                                      std::to_string(p.value) + " is outside [0,1]");
  }
  std::stable_sort(points_.begin(), points_.end(),
                   [](const TfPoint& a, const TfPoint& b) { return a.value < b.value; });
}

Rgba TransferFunction::evaluate(double v) const {
  Rgba out;
  if (points_.empty()) return out;
  auto set = [&](const TfPoint& p) {
    out = {static_cast<float>(p.color[0]), static_cast<float>(p.color[1]), static_cast<float>(p.color[2]),
           static_cast<float>(p.opacity)};
  };
  if (v <= points_.front().value) {
    set(points_.front());
    return out;
  }
  if (v >= points_.back().value) {
    set(points_.back());
    return out;
  }
  auto it = std::upper_bound(points_.begin(), points_.end(), v, [](double x, const TfPoint& p) { return x < p.value; });
  const TfPoint& b = *it;
  const TfPoint& a = *(it - 1);
  const double span = b.value - a.value;
  const double t = span > 0 ? (v - a.value) / span : 1.0;
  out.r = static_cast<float>(a.color[0] + t * (b.color[0] - a.color[0]));
  out.g = static_cast<float>(a.color[1] + t * (b.color[1] - a.color[1]));
  out.b = static_cast<float>(a.color[2] + t * (b.color[2] - a.color[2]));
  out.a = static_cast<float>(a.opacity + t * (b.opacity - a.opacity));
  return out;
}

std::pair<double, double> TransferFunction::opaqueRange() const {
  const double inf = std::numeric_limits<double>::infinity();
  double lo = inf, hi = -inf;
  const size_t n = points_.size();
  for (size_t i = 0; i < n; ++i) {
    const bool here = points_[i].opacity > 0;
    const bool left = i > 0 && points_[i - 1].opacity > 0;
    const bool right = i + 1 < n && points_[i + 1].opacity > 0;
    if (!(here || left || right)) continue;
    // Segments adjacent to a non-zero point carry opacity right up to the neighbouring point.
    lo = std::min(lo, (here && i == 0) ? -inf : points_[i].value);
    hi = std::max(hi, (here && i + 1 == n) ? inf : points_[i].value);
  }
  return {lo, hi};
}

std::vector<std::string> TransferFunction::presetNames() {
  return {"auto", "ct-skin", "ct-bone", "ct-lung", "ct-angio", "mri", "vessels"};
}

TransferFunction TransferFunction::preset(const std::string& name, const ValueRange& r) {
  using C = std::array<double, 3>;
  const C skin{0.85, 0.6, 0.5}, bone{1.0, 0.96, 0.88}, red{0.8, 0.12, 0.1};
  if (name == "ct-skin")
    return TransferFunction({{-1024, skin, 0.0},
                             {-600, skin, 0.0},
                             {-400, skin, 0.3},
                             {-100, C{0.9, 0.65, 0.55}, 0.6},
                             {200, C{0.95, 0.8, 0.7}, 0.7},
                             {500, bone, 0.9},
                             {3000, bone, 1.0}});
  if (name == "ct-bone")
    return TransferFunction({{-1024, C{0.7, 0.3, 0.2}, 0.0},
                             {120, C{0.7, 0.3, 0.2}, 0.0},
                             {250, C{0.9, 0.75, 0.6}, 0.3},
                             {600, bone, 0.8},
                             {3000, C{1, 1, 1}, 1.0}});
  if (name == "ct-lung")
    return TransferFunction({{-1024, C{0.6, 0.3, 0.3}, 0.0},
                             {-750, C{0.6, 0.3, 0.3}, 0.0},
                             {-600, C{0.9, 0.45, 0.35}, 0.15},
                             {-400, C{1.0, 0.7, 0.6}, 0.25},
                             {-250, C{1.0, 0.8, 0.7}, 0.01},
                             {200, C{1.0, 0.9, 0.8}, 0.005},
                             {400, bone, 0.3},
                             {3000, bone, 0.6}});
  if (name == "ct-angio")
    return TransferFunction({{-1024, red, 0.0},
                             {100, red, 0.0},
                             {180, red, 0.4},
                             {350, C{1.0, 0.35, 0.25}, 0.7},
                             {600, bone, 0.8},
                             {3000, bone, 0.9}});
  if (name == "vessels")  // identical to /work/shared/peers/raycast_vtk.py
    return TransferFunction({{0, C{0, 0, 0}, 0.0},
                             {60, C{0.6, 0.1, 0.1}, 0.0},
                             {200, C{1.0, 0.9, 0.8}, 0.8},
                             {255, C{1.0, 0.9, 0.8}, 1.0}});
  const double lo = r.min, span = r.max > r.min ? r.max - r.min : 1.0;
  auto at = [&](double f) { return lo + f * span; };
  if (name == "mri")
    return TransferFunction({{at(0.0), skin, 0.0},
                             {at(0.12), skin, 0.0},
                             {at(0.25), skin, 0.3},
                             {at(0.5), C{1.0, 0.85, 0.75}, 0.6},
                             {at(1.0), C{1, 1, 1}, 0.8}});
  if (name == "auto")
    return TransferFunction({{at(0.0), C{0.7, 0.3, 0.2}, 0.0},
                             {at(0.3), C{0.7, 0.3, 0.2}, 0.0},
                             {at(0.6), C{0.95, 0.75, 0.6}, 0.4},
                             {at(1.0), bone, 0.8}});
  std::string names;
  for (const auto& n : presetNames()) names += (names.empty() ? "" : ", ") + n;
  throw InvalidArgument("unknown transfer function preset '" + name + "' (valid: " + names + ", or a .json file)");
}

TransferFunction TransferFunction::fromFile(const std::string& path) {
  return fromJson(readTextFile(path, "the transfer function file"), path);
}

TransferFunction TransferFunction::fromJson(const std::string& text, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(source + ": malformed JSON: " + e.what());
  }
  if (!j.is_object() || !j.contains("points") || !j["points"].is_array() || j["points"].empty())
    throw IoError(source + ": expected an object with a non-empty \"points\" array");
  std::vector<TfPoint> pts;
  size_t i = 0;
  for (const auto& p : j["points"]) {
    const std::string where = source + ": points[" + std::to_string(i++) + "]";
    if (!p.is_object() || !p.contains("value") || !p["value"].is_number())
      throw IoError(where + ": needs a numeric \"value\"");
    TfPoint q;
    q.value = p["value"].get<double>();
    if (p.contains("color")) {
      const auto& c = p["color"];
      if (!c.is_array() || c.size() != 3 || !c[0].is_number() || !c[1].is_number() || !c[2].is_number())
        throw IoError(where + ": \"color\" must be [r, g, b] numbers in [0,1]");
      q.color = {c[0].get<double>(), c[1].get<double>(), c[2].get<double>()};
    }
    if (!p.contains("opacity") || !p["opacity"].is_number()) throw IoError(where + ": needs a numeric \"opacity\"");
    q.opacity = p["opacity"].get<double>();
    pts.push_back(q);
  }
  double unit = 1.0;
  if (j.contains("unit_distance")) {
    if (!j["unit_distance"].is_number()) throw IoError(source + ": \"unit_distance\" must be a number (mm)");
    unit = j["unit_distance"].get<double>();
  }
  try {
    return TransferFunction(std::move(pts), unit);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(source + ": " + e.what());
  }
}

std::string TransferFunction::toJson() const {
  nlohmann::json j;
  j["unit_distance"] = unitDistance_;
  j["points"] = nlohmann::json::array();
  for (const auto& p : points_)
    j["points"].push_back(
        {{"value", p.value}, {"color", {p.color[0], p.color[1], p.color[2]}}, {"opacity", p.opacity}});
  return j.dump(1);
}

TfTable::TfTable(const TransferFunction& tf, double lo_, double hi_, double stepMm, int size) : lo(lo_), hi(hi_) {
  VS_REQUIRE(size >= 2, "TfTable: size must be >= 2");
  VS_REQUIRE(std::isfinite(lo) && std::isfinite(hi), "TfTable: value range must be finite");
  if (!(hi > lo)) hi = lo + 1.0;
  scale = (size - 1) / (hi - lo);
  entries.resize(static_cast<size_t>(size));
  opaquePrefix.assign(static_cast<size_t>(size) + 1, 0);
  const double ratio = stepMm / tf.unitDistance();
  for (int i = 0; i < size; ++i) {
    Rgba c = tf.evaluate(lo + i / scale);
    const double a = std::clamp(static_cast<double>(c.a), 0.0, 1.0);
    c.a = a >= 1.0 ? 1.0f : static_cast<float>(1.0 - std::pow(1.0 - a, ratio));
    entries[static_cast<size_t>(i)] = c;
    opaquePrefix[static_cast<size_t>(i) + 1] = opaquePrefix[static_cast<size_t>(i)] + (c.a > 0 ? 1 : 0);
  }
}

}  // namespace vs
