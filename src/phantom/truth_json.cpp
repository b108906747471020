// Phantom truth <-> JSON. Coordinates are written as [x, y, z] (or [x, y]) arrays.
#include <nlohmann/json.hpp>

#include "phantom/phantom.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {

using nlohmann::json;

namespace {

json vec(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }
json vec(const Vec2& v) { return json::array({v[0], v[1]}); }
json idx(const Index3& v) { return json::array({v[0], v[1], v[2]}); }

// Field access with messages naming the field; nlohmann's own errors become IoError.
const json& field(const json& j, const char* name) {
  if (!j.is_object() || !j.contains(name)) throw IoError(std::string("phantom truth: missing field '") + name + "'");
  return j.at(name);
}
template <class T>
T get(const json& j, const char* name) {
  try {
    return field(j, name).get<T>();
  } catch (const json::exception& e) {
    throw IoError(std::string("phantom truth: field '") + name + "': " + e.what());
  }
}
Vec3 toVec3(const json& a, const char* name) {
  if (!a.is_array() || a.size() != 3)
    throw IoError(std::string("phantom truth: '") + name + "' is not an [x,y,z] array");
  try {
    return Vec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  } catch (const json::exception& e) {
    throw IoError(std::string("phantom truth: '") + name + "': " + e.what());
  }
}
Vec2 toVec2(const json& a, const char* name) {
  if (!a.is_array() || a.size() != 2) throw IoError(std::string("phantom truth: '") + name + "' is not an [x,y] array");
  try {
    return Vec2(a[0].get<double>(), a[1].get<double>());
  } catch (const json::exception& e) {
    throw IoError(std::string("phantom truth: '") + name + "': " + e.what());
  }
}
Index3 toIndex3(const json& a, const char* name) {
  const Vec3 v = toVec3(a, name);
  return {static_cast<int64_t>(v[0]), static_cast<int64_t>(v[1]), static_cast<int64_t>(v[2])};
}
void checkKind(const json& j, const std::string& kind) {
  const std::string k = get<std::string>(j, "kind");
  if (k != kind) throw IoError("phantom truth: kind is '" + k + "', expected '" + kind + "'");
}
json header(const std::string& kind, uint64_t seed, const Index3& dims, const Vec3& spacing) {
  return json{{"kind", kind},
              {"format_version", 1},
              {"seed", seed},
              {"dims", idx(dims)},
              {"spacing", vec(spacing)},
              {"coordinates", "0-based voxel index (x, y, z); radii and *_mm fields in mm"}};
}

json ellipsoidJson(const Ellipsoid& e, const Vec3& spacing) {
  return json{{"name", e.name},
              {"center", vec(e.centerIndex(spacing))},
              {"center_mm", vec(e.centerMm)},
              {"semi_axes_mm", vec(e.semiAxesMm)},
              {"value", e.value}};
}
Ellipsoid ellipsoidFrom(const json& j) {
  Ellipsoid e;
  e.name = get<std::string>(j, "name");
  e.centerMm = toVec3(field(j, "center_mm"), "center_mm");
  e.semiAxesMm = toVec3(field(j, "semi_axes_mm"), "semi_axes_mm");
  e.value = get<double>(j, "value");
  return e;
}

json readJsonFile(const std::string& path) {
  const std::string text = readTextFile(path, "the phantom truth file");
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(path + ": not valid JSON: " + e.what());
  }
}

template <class F>
auto withPath(const std::string& path, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const IoError& e) {
    throw IoError(path + ": " + e.what());
  }
}

}  // namespace

// ---------------------------------------------------------------------------- vessels
json toJson(const VesselTruth& t) {
  json j = header("vessels", t.seed, t.dims, t.spacing);
  j["voxel_type"] = "uint8";
  j["background"] = t.background;
  j["foreground"] = t.foreground;
  j["noise_sigma"] = t.noiseSigma;
  j["iso"] = t.iso;
  j["radius_unit_mm"] = t.radiusUnitMm;
  j["clearance_mm"] = t.clearanceMm;
  j["root_voxel"] = idx(t.rootVoxel);
  json branches = json::array();
  for (size_t i = 0; i < t.branches.size(); ++i) {
    const VesselBranch& b = t.branches[i];
    json pts = json::array();
    for (const Vec3& p : b.points) pts.push_back(vec(p));
    branches.push_back(json{{"id", i},
                            {"parent", b.parent},
                            {"children", b.children},
                            {"depth", b.depth},
                            {"points", pts},
                            {"radii_mm", b.radiiMm}});
  }
  j["branches"] = branches;
  json terms = json::array();
  for (size_t i = 0; i < t.terminalVoxels.size(); ++i)
    terms.push_back(json{{"voxel", idx(t.terminalVoxels[i])}, {"branch", t.terminalBranches[i]}});
  j["terminals"] = terms;
  json bps = json::array();
  for (const VesselBranchPoint& bp : t.branchPoints)
    bps.push_back(json{
        {"position", vec(bp.position)}, {"voxel", idx(bp.voxel)}, {"parent", bp.parent}, {"children", bp.children}});
  j["branch_points"] = bps;
  return j;
}

VesselTruth vesselTruthFromJson(const json& j) {
  checkKind(j, "vessels");
  VesselTruth t;
  t.seed = get<uint64_t>(j, "seed");
  t.dims = toIndex3(field(j, "dims"), "dims");
  t.spacing = toVec3(field(j, "spacing"), "spacing");
  t.background = get<double>(j, "background");
  t.foreground = get<double>(j, "foreground");
  t.noiseSigma = get<double>(j, "noise_sigma");
  t.iso = get<double>(j, "iso");
  t.radiusUnitMm = get<double>(j, "radius_unit_mm");
  t.clearanceMm = get<double>(j, "clearance_mm");
  t.rootVoxel = toIndex3(field(j, "root_voxel"), "root_voxel");
  const json& branches = field(j, "branches");
  if (!branches.is_array()) throw IoError("phantom truth: 'branches' is not an array");
  for (const json& b : branches) {
    VesselBranch vb;
    vb.parent = get<int>(b, "parent");
    vb.children = get<std::vector<int>>(b, "children");
    vb.depth = get<int>(b, "depth");
    for (const json& p : field(b, "points")) vb.points.push_back(toVec3(p, "points"));
    vb.radiiMm = get<std::vector<double>>(b, "radii_mm");
    if (vb.radiiMm.size() != vb.points.size()) throw IoError("phantom truth: branch radii and points differ in length");
    t.branches.push_back(std::move(vb));
  }
  const int nb = static_cast<int>(t.branches.size());
  for (const VesselBranch& b : t.branches) {
    if (b.parent < -1 || b.parent >= nb) throw IoError("phantom truth: branch parent index out of range");
    for (int c : b.children)
      if (c < 0 || c >= nb) throw IoError("phantom truth: branch child index out of range");
  }
  for (const json& term : field(j, "terminals")) {
    t.terminalVoxels.push_back(toIndex3(field(term, "voxel"), "voxel"));
    t.terminalBranches.push_back(get<int>(term, "branch"));
  }
  for (const json& bp : field(j, "branch_points")) {
    VesselBranchPoint p;
    p.position = toVec3(field(bp, "position"), "position");
    p.voxel = toIndex3(field(bp, "voxel"), "voxel");
    p.parent = get<int>(bp, "parent");
    p.children = get<std::vector<int>>(bp, "children");
    t.branchPoints.push_back(std::move(p));
  }
  return t;
}

// ------------------------------------------------------------------------------- head
json toJson(const HeadTruth& t) {
  json j = header("head", t.seed, t.dims, t.spacing);
  j["voxel_type"] = "int16";
  j["noise_sigma"] = t.noiseSigma;
  j["values"] = json{{"air", t.air}, {"soft_tissue", t.softTissue}, {"bone", t.bone}, {"brain", t.brain}};
  j["iso_skin"] = t.isoSkin;
  j["iso_bone"] = t.isoBone;
  j["ellipsoids"] = json::array({ellipsoidJson(t.skin, t.spacing), ellipsoidJson(t.skullOuter, t.spacing),
                                 ellipsoidJson(t.skullInner, t.spacing), ellipsoidJson(t.nose, t.spacing)});
  j["nose_box"] = json{{"min", idx(t.noseBoxMin)}, {"max", idx(t.noseBoxMax)}};
  j["face_direction"] = vec(t.faceDirection);
  return j;
}

HeadTruth headTruthFromJson(const json& j) {
  checkKind(j, "head");
  HeadTruth t;
  t.seed = get<uint64_t>(j, "seed");
  t.dims = toIndex3(field(j, "dims"), "dims");
  t.spacing = toVec3(field(j, "spacing"), "spacing");
  t.noiseSigma = get<double>(j, "noise_sigma");
  const json& v = field(j, "values");
  t.air = get<double>(v, "air");
  t.softTissue = get<double>(v, "soft_tissue");
  t.bone = get<double>(v, "bone");
  t.brain = get<double>(v, "brain");
  t.isoSkin = get<double>(j, "iso_skin");
  t.isoBone = get<double>(j, "iso_bone");
  bool seen[4] = {false, false, false, false};
  for (const json& e : field(j, "ellipsoids")) {
    Ellipsoid el = ellipsoidFrom(e);
    const char* names[4] = {"skin", "skull_outer", "skull_inner", "nose"};
    Ellipsoid* slots[4] = {&t.skin, &t.skullOuter, &t.skullInner, &t.nose};
    for (int i = 0; i < 4; ++i)
      if (el.name == names[i]) {
        *slots[i] = el;
        seen[i] = true;
      }
  }
  for (bool s : seen)
    if (!s) throw IoError("phantom truth: head ellipsoids incomplete (need skin, skull_outer, skull_inner, nose)");
  const json& box = field(j, "nose_box");
  t.noseBoxMin = toIndex3(field(box, "min"), "nose_box.min");
  t.noseBoxMax = toIndex3(field(box, "max"), "nose_box.max");
  t.faceDirection = toVec3(field(j, "face_direction"), "face_direction");
  return t;
}

// --------------------------------------------------------------------------- shapes2d
json toJson(const Shapes2DTruth& t) {
  json j = header("shapes2d", t.seed, t.dims, t.spacing);
  j["coordinates"] = "pixel (x, y), 0-based; boundary polygons are closed (last vertex not repeated)";
  j["voxel_type"] = "uint8";
  j["background"] = t.background;
  j["noise_sigma"] = t.noiseSigma;
  j["blur_sigma"] = t.blurSigma;
  json shapes = json::array();
  for (const Shape2D& s : t.shapes) {
    json js{{"label", s.label},
            {"kind", shapeKindName(s.kind)},
            {"value", s.value},
            {"iso", s.iso},
            {"center", vec(s.center)}};
    switch (s.kind) {
      case ShapeKind::Disc:
        js["radius"] = s.radius;
        break;
      case ShapeKind::Ellipse:
        js["semi_axes"] = vec(s.semiAxes);
        js["angle"] = s.angle;
        break;
      case ShapeKind::RoundedRect:
        js["semi_axes"] = vec(s.semiAxes);
        js["corner_radius"] = s.cornerRadius;
        js["angle"] = s.angle;
        break;
      case ShapeKind::Star:
        js["radius"] = s.radius;
        js["amplitude"] = s.amplitude;
        js["lobes"] = s.lobes;
        js["phase"] = s.phase;
        break;
    }
    json poly = json::array();
    for (const Vec2& p : s.boundary) poly.push_back(vec(p));
    js["boundary"] = poly;
    json pix = json::array();
    for (const Index2& p : s.boundaryPixels) pix.push_back(json::array({p[0], p[1]}));
    js["boundary_pixels"] = pix;
    shapes.push_back(js);
  }
  j["shapes"] = shapes;
  return j;
}

Shapes2DTruth shapes2DTruthFromJson(const json& j) {
  checkKind(j, "shapes2d");
  Shapes2DTruth t;
  t.seed = get<uint64_t>(j, "seed");
  t.dims = toIndex3(field(j, "dims"), "dims");
  t.spacing = toVec3(field(j, "spacing"), "spacing");
  t.background = get<double>(j, "background");
  t.noiseSigma = get<double>(j, "noise_sigma");
  t.blurSigma = get<double>(j, "blur_sigma");
  for (const json& js : field(j, "shapes")) {
    Shape2D s;
    s.label = get<int>(js, "label");
    try {
      s.kind = shapeKindFromName(get<std::string>(js, "kind"));
    } catch (const InvalidArgument& e) {
      throw IoError(std::string("phantom truth: ") + e.what());
    }
    s.value = get<double>(js, "value");
    s.iso = get<double>(js, "iso");
    s.center = toVec2(field(js, "center"), "center");
    auto opt = [&](const char* name, double& dst) {
      if (js.contains(name)) dst = get<double>(js, name);
    };
    opt("radius", s.radius);
    opt("angle", s.angle);
    opt("corner_radius", s.cornerRadius);
    opt("amplitude", s.amplitude);
    opt("phase", s.phase);
    if (js.contains("lobes")) s.lobes = get<int>(js, "lobes");
    if (js.contains("semi_axes")) s.semiAxes = toVec2(js.at("semi_axes"), "semi_axes");
    for (const json& p : field(js, "boundary")) s.boundary.push_back(toVec2(p, "boundary"));
    if (s.boundary.size() < 3) throw IoError("phantom truth: shape boundary has fewer than 3 vertices");
    for (const json& p : field(js, "boundary_pixels")) {
      const Vec2 v = toVec2(p, "boundary_pixels");
      s.boundaryPixels.push_back({static_cast<int64_t>(v[0]), static_cast<int64_t>(v[1])});
    }
    t.shapes.push_back(std::move(s));
  }
  return t;
}

// ------------------------------------------------------------------------------ files
void writeTruthFile(const json& j, const std::string& path) { writeFileAtomically(path, j.dump(1) + "\n"); }

VesselTruth readVesselTruth(const std::string& path) {
  const json j = readJsonFile(path);
  return withPath(path, [&] { return vesselTruthFromJson(j); });
}
HeadTruth readHeadTruth(const std::string& path) {
  const json j = readJsonFile(path);
  return withPath(path, [&] { return headTruthFromJson(j); });
}
Shapes2DTruth readShapes2DTruth(const std::string& path) {
  const json j = readJsonFile(path);
  return withPath(path, [&] { return shapes2DTruthFromJson(j); });
}

}  // namespace vs
