#include "io/contour_io.h"

#include <nlohmann/json.hpp>

#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {

namespace {

using json = nlohmann::json;

json uvList(const std::vector<ContourDocument::UV>& v) {
  json a = json::array();
  for (const auto& p : v) a.push_back({p[0], p[1]});
  return a;
}

template <class V>
json tripleList(const std::vector<V>& v) {
  json a = json::array();
  for (const auto& p : v) a.push_back({p[0], p[1], p[2]});
  return a;
}

// Field access that names the field in errors instead of leaking nlohmann's messages.
struct Reader {
  const json& j;
  std::string where;
  const json& at(const std::string& key) const {
    if (!j.contains(key)) throw IoError(where + ": missing \"" + key + "\"");
    return j[key];
  }
  template <class T>
  T get(const json& v, const std::string& key) const {
    try {
      return v.get<T>();
    } catch (const json::exception&) {
      throw IoError(where + ": \"" + key + "\" has the wrong type (" + v.dump().substr(0, 40) + ")");
    }
  }
  template <class T>
  T value(const std::string& key, T fallback) const {
    return j.contains(key) ? get<T>(j[key], key) : fallback;
  }
  std::vector<ContourDocument::UV> uvs(const std::string& key) const {
    std::vector<ContourDocument::UV> out;
    if (!j.contains(key)) return out;
    for (const auto& p : get<std::vector<std::vector<int64_t>>>(j[key], key)) {
      if (p.size() != 2) throw IoError(where + ": \"" + key + "\" must hold [u,v] pairs");
      out.push_back({p[0], p[1]});
    }
    return out;
  }
};

}  // namespace

std::string contourToJson(const ContourDocument& c) {
  json j;
  j["file"] = c.file;
  j["plane"] = c.plane;
  j["slice"] = {{"axis", std::string(1, "xyz"[c.axis])},
                {"index", c.index},
                {"width", c.width},
                {"height", c.height},
                {"spacing_mm", {c.spacingU, c.spacingV}}};
  j["cost_kind"] = c.costKind;
  if (c.weights)
    j["weights"] = {{"zero_crossing", (*c.weights)[0]}, {"gradient", (*c.weights)[1]}, {"direction", (*c.weights)[2]}};
  j["gradient_quantile"] = c.gradientQuantile;
  j["connectivity"] = c.connectivity;
  j["smooth_mm"] = c.smoothMm;
  j["snap_px"] = c.snapPx;
  j["closed"] = c.closed;
  j["points"] = uvList(c.points);
  j["points_index"] = tripleList(c.pointsIndex);
  j["points_world"] = tripleList(c.pointsWorld);
  json pic = json::array();
  for (const auto& p : c.pointsPicture) pic.push_back({p[0], p[1]});
  j["points_picture"] = std::move(pic);
  j["clicks"] = uvList(c.clicks);
  j["clicks_input"] = uvList(c.clicksInput);
  j["length_mm"] = c.lengthMm;
  j["cost"] = c.cost;
  json segs = json::array();
  for (const auto& s : c.segments)
    segs.push_back({{"from", {s.from[0], s.from[1]}},
                    {"to", {s.to[0], s.to[1]}},
                    {"pixels", s.pixels},
                    {"cost", s.cost},
                    {"length_mm", s.lengthMm}});
  j["segments"] = std::move(segs);
  if (c.areaPixels) j["area_pixels"] = *c.areaPixels;
  if (c.areaMm2) j["area_mm2"] = *c.areaMm2;
  if (!c.mask.empty()) j["mask"] = c.mask;
  return j.dump(1) + "\n";
}

ContourDocument contourFromJson(const std::string& text, const std::string& where) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(where + ": malformed JSON: " + e.what());
  }
  if (!j.is_object()) throw IoError(where + ": expected a JSON object");
  const Reader r{j, where};
  ContourDocument c;
  c.file = r.value<std::string>("file", "");
  c.plane = r.value<std::string>("plane", "");
  const json& s = r.at("slice");
  if (!s.is_object()) throw IoError(where + ": \"slice\" must be an object");
  const Reader rs{s, where + ": slice"};
  const std::string axis = rs.get<std::string>(rs.at("axis"), "axis");
  if (axis != "x" && axis != "y" && axis != "z") throw IoError(where + ": slice axis must be \"x\", \"y\" or \"z\"");
  c.axis = axis[0] - 'x';
  c.index = rs.get<int64_t>(rs.at("index"), "index");
  c.width = rs.value<int64_t>("width", 0);
  c.height = rs.value<int64_t>("height", 0);
  if (s.contains("spacing_mm")) {
    const auto sp = rs.get<std::vector<double>>(s["spacing_mm"], "spacing_mm");
    if (sp.size() != 2) throw IoError(where + ": slice spacing_mm must be [su, sv]");
    c.spacingU = sp[0], c.spacingV = sp[1];
  }
  c.costKind = r.value<std::string>("cost_kind", "mb");
  if (j.contains("weights")) {
    const Reader rw{r.at("weights"), where + ": weights"};
    c.weights = std::array<double, 3>{rw.get<double>(rw.at("zero_crossing"), "zero_crossing"),
                                      rw.get<double>(rw.at("gradient"), "gradient"),
                                      rw.get<double>(rw.at("direction"), "direction")};
  }
  c.gradientQuantile = r.value<double>("gradient_quantile", 1.0);
  c.connectivity = r.value<int>("connectivity", 8);
  c.smoothMm = r.value<double>("smooth_mm", 0.0);
  c.snapPx = r.value<double>("snap_px", 0.0);
  c.closed = r.value<bool>("closed", false);
  c.points = r.uvs("points");
  c.clicks = r.uvs("clicks");
  c.clicksInput = r.uvs("clicks_input");
  for (const auto& p : r.value<std::vector<std::vector<int64_t>>>("points_index", {})) {
    if (p.size() != 3) throw IoError(where + ": \"points_index\" must hold [x,y,z] triples");
    c.pointsIndex.push_back({p[0], p[1], p[2]});
  }
  for (const auto& p : r.value<std::vector<std::vector<double>>>("points_world", {})) {
    if (p.size() != 3) throw IoError(where + ": \"points_world\" must hold [x,y,z] triples");
    c.pointsWorld.emplace_back(p[0], p[1], p[2]);
  }
  for (const auto& p : r.value<std::vector<std::vector<double>>>("points_picture", {})) {
    if (p.size() != 2) throw IoError(where + ": \"points_picture\" must hold [col,row] pairs");
    c.pointsPicture.push_back({p[0], p[1]});
  }
  c.lengthMm = r.value<double>("length_mm", 0.0);
  c.cost = r.value<double>("cost", 0.0);
  if (j.contains("segments")) {
    for (const auto& sj : r.at("segments")) {
      const Reader rg{sj, where + ": segments"};
      ContourDocument::Segment seg;
      const auto from = rg.get<std::vector<int64_t>>(rg.at("from"), "from"),
                 to = rg.get<std::vector<int64_t>>(rg.at("to"), "to");
      if (from.size() != 2 || to.size() != 2) throw IoError(where + ": segment from/to must be [u,v]");
      seg.from = {from[0], from[1]};
      seg.to = {to[0], to[1]};
      seg.pixels = rg.value<int64_t>("pixels", 0);
      seg.cost = rg.value<double>("cost", 0.0);
      seg.lengthMm = rg.value<double>("length_mm", 0.0);
      c.segments.push_back(seg);
    }
  }
  if (j.contains("area_pixels")) c.areaPixels = r.get<int64_t>(j["area_pixels"], "area_pixels");
  if (j.contains("area_mm2")) c.areaMm2 = r.get<double>(j["area_mm2"], "area_mm2");
  c.mask = r.value<std::string>("mask", "");
  if (!c.pointsIndex.empty() && c.pointsIndex.size() != c.points.size())
    throw IoError(where + ": \"points_index\" and \"points\" differ in length");
  return c;
}

void writeContour(const ContourDocument& contour, const std::string& path) {
  writeFileAtomically(path, contourToJson(contour));
}

ContourDocument readContour(const std::string& path) {
  return contourFromJson(readTextFile(path, "the contour file"), path);
}

}  // namespace vs
