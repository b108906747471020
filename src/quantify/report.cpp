#include "quantify/report.h"

#include <cmath>
#include <cstdio>

namespace vs {

namespace {
using json = nlohmann::json;
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json vec(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }
}  // namespace

json measurementToJson(const TreeMeasurement& m, const QuantifyOptions& o) {
  json j;
  j["polarity"] = lumenPolarityName(m.polarity);
  j["step_mm"] = o.stepMm;
  j["rays"] = o.rays;
  j["merged_branches"] = m.mergedBranches;
  j["nodes"] = m.tree.size();
  int leaves = 0, meets = 0, none = 0;
  for (const auto& cs : m.sections) {
    leaves += (cs.flags & kSectionLeavesVolume) != 0;
    meets += (cs.flags & kSectionMeetsBranch) != 0;
    none += (cs.flags & kSectionNoBoundary) != 0;
  }
  j["sections"] = {{"total", m.sections.size()},
                   {"measured", m.measuredSections()},
                   {"leaves_volume", leaves},
                   {"meets_branch", meets},
                   {"no_boundary", none}};
  char rule[640];
  std::snprintf(
      rule, sizeof rule,
      "per segment: 1 - d_min / d_ref(s_min), d = equivalent diameter of the measured sections, d_ref = a "
      "line fitted to the sections not narrower than %.2f x the line (iterated): the healthy lumen "
      "proximal and distal (two healthy sections on each side); reported only when the narrowed run "
      "(contiguous sections below %.2f x d_ref around the minimum) spans >= %.2f x the largest voxel "
      "spacing and <= %.1f x d_ref (focal: longer is a taper or diffuse narrowing) and d_ref - d_min >= %.2f x "
      "the healthy sections' scatter about the line (1.4826 MAD)",
      o.healthyFraction, o.healthyFraction, o.stenosisMinLengthVoxels, o.stenosisMaxLengthDiameters,
      o.stenosisSignificance);
  j["stenosis_rule"] = rule;
  json segs = json::array();
  for (size_t i = 0; i < m.segments.size(); ++i) {
    const SegmentMeasure& s = m.segments[i];
    segs.push_back({{"id", i},
                    {"parent", s.parent},
                    {"children", s.children},
                    {"generation", s.generation},
                    {"strahler", s.strahler},
                    {"first_node", s.nodes.front()},
                    {"last_node", s.nodes.back()},
                    {"length_mm", s.lengthMm},
                    {"chord_mm", s.chordMm},
                    {"distance_metric", num(s.distanceMetric)},
                    {"soam_rad_per_cm", s.sumOfAnglesRadPerCm},
                    {"sections", s.sections.size()},
                    {"measured_sections", s.measuredSections},
                    {"mean_diameter_mm", num(s.meanDiameterMm)},
                    {"min_diameter_mm", num(s.minDiameterMm)},
                    {"min_arc_mm", num(s.minArcMm)},
                    {"reference_diameter_mm", num(s.referenceDiameterMm)},
                    {"stenosis", num(s.stenosis)},
                    {"stenosis_length_mm", num(s.stenosisLengthMm)},
                    {"branch_angle_deg", num(s.branchAngleDeg)}});
  }
  j["segments"] = segs;
  json paths = json::array();
  for (const auto& p : m.paths) {
    paths.push_back({{"segments", p.segments},
                     {"tip_node", p.tipNode},
                     {"length_mm", p.lengthMm},
                     {"chord_mm", p.chordMm},
                     {"distance_metric", num(p.distanceMetric)},
                     {"soam_rad_per_cm", p.sumOfAnglesRadPerCm},
                     {"mean_diameter_mm", num(p.meanDiameterMm)},
                     {"min_diameter_mm", num(p.minDiameterMm)},
                     {"min_arc_mm", num(p.minArcMm)},
                     {"stenosis", num(p.stenosis)},
                     {"stenosis_arc_mm", num(p.stenosisArcMm)}});
  }
  j["paths"] = paths;
  json bps = json::array();
  for (const auto& b : m.branchPoints) {
    json ca = json::array(), pa = json::array();
    for (double a : b.childAnglesDeg) ca.push_back(num(a));
    for (double a : b.pairAnglesDeg) pa.push_back(num(a));
    // A neighbour section: its distance from the branch point along its segment and its numbers.
    auto neighbour = [&](int i, bool parentEnd) -> json {
      if (i < 0) return nullptr;
      const CrossSection& c = m.sections[static_cast<size_t>(i)];
      const double L = m.segments[static_cast<size_t>(c.segment)].lengthMm;
      return {{"segment", c.segment},
              {"distance_mm", parentEnd ? L - c.arcMm : c.arcMm},
              {"area_mm2", num(c.areaMm2)},
              {"eq_diameter_mm", num(c.equivalentDiameterMm)}};
    };
    json cs = json::array();
    for (int i : b.childSections) cs.push_back(neighbour(i, false));
    bps.push_back({{"node", b.node},
                   {"position_mm", vec(b.positionMm)},
                   {"parent_segment", b.parentSegment},
                   {"child_segments", b.childSegments},
                   {"child_angles_deg", ca},
                   {"pair_angles_deg", pa},
                   {"parent_section", neighbour(b.parentSection, true)},
                   {"child_sections", cs}});
  }
  j["branch_points"] = bps;
  return j;
}

std::string measurementCsv(const TreeMeasurement& m) {
  std::string out =
      "path,segment,arc_mm,segment_arc_mm,x_mm,y_mm,z_mm,area_mm2,eq_diameter_mm,min_diameter_mm,max_diameter_mm,"
      "min_dir_x,min_dir_y,min_dir_z,max_dir_x,max_dir_y,max_dir_z,lumen,wall,flags,branch_point\n";
  char buf[512];
  auto f = [](double v) {
    if (!std::isfinite(v)) return std::string();
    char b[32];
    std::snprintf(b, sizeof b, "%.4f", v);
    return std::string(b);
  };
  for (size_t p = 0; p < m.paths.size(); ++p) {
    const PathMeasure& path = m.paths[p];
    for (size_t k = 0; k < path.sections.size(); ++k) {
      const CrossSection& c = m.sections[static_cast<size_t>(path.sections[k])];
      const bool ok = c.measured();
      std::snprintf(buf, sizeof buf, "%zu,%d,%.3f,%.3f,%.4f,%.4f,%.4f,", p, c.segment, path.arcMm[k], c.arcMm,
                    c.centreMm[0], c.centreMm[1], c.centreMm[2]);
      out += buf;
      for (double v : {c.areaMm2, c.equivalentDiameterMm, c.minDiameterMm, c.maxDiameterMm}) out += f(v) + ",";
      for (const Vec3* d : {&c.minDirection, &c.maxDirection})
        for (int a = 0; a < 3; ++a) out += (ok ? f((*d)[a]) : std::string()) + ",";
      out += f(c.lumenLevel) + "," + f(c.wallLevel) + "," + crossSectionFlagsText(c.flags) + "," +
             (c.branchPoint >= 0 ? std::to_string(c.branchPoint) : std::string()) + "\n";
    }
  }
  return out;
}

}  // namespace vs
