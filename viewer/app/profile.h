// The profile of a traced tree in the viewer (issue 24), GL-free: the core's quantification
// (quantify/quantify.h measureTree, called, never copied) of the trace tool's tree, the path
// selected for the profile plot (diameter against arc length) and the cross-section selected on
// it (by the plot, a script, or the mouse near a centreline). The window draws it
// (window/profile_panel.h); the script commands `measure`, `profile-path K`, `profile-arc MM`
// call the functions below; `color-by diameter|none` colours the tree by the measured diameter.
#pragma once
#include <string>
#include <vector>

#include "quantify/quantify.h"
#include "render/colour_legend.h"

namespace vs::viewer {

class ViewerApp;

class ProfileView {
 public:
  // Measures `tree` in `volume` with the core's defaults (as `volscissors measure`); selects the
  // first path and no section. Throws the core's errors (DataError: the tree is not this volume's).
  void measure(const VolumeF32& volume, const Tree& tree);
  void clear();
  bool has() const { return has_; }
  // Whether the measurement was made on this tree (the trace changed otherwise: measure again).
  bool measuredFrom(const Tree& tree) const;
  const TreeMeasurement& measurement() const { return m_; }
  int path() const { return path_; }
  void selectPath(int path);  // InvalidArgument outside 0..paths-1 or without a measurement
  // The selected section: an index into the selected path's profile (PathMeasure::sections), -1 none.
  int section() const { return section_; }
  void selectSection(int profileIndex);  // -1 clears; InvalidArgument outside the profile
  // Selects the profile point of the selected path nearest `arcMm` (from the root).
  void selectArc(double arcMm);
  // Selects the section whose centre is nearest `worldMm` within maxDistanceMm (any path; its path
  // becomes the selected one, the one already selected preferred); false when none is that near.
  bool selectNear(const Vec3& worldMm, double maxDistanceMm);
  const CrossSection* selected() const;  // nullptr when none
  double selectedArcMm() const;          // NaN when none
  // The selected path's profile as plot data: arc (mm from the root) and equivalent diameter (mm,
  // NaN where the section is flagged).
  void plotData(std::vector<double>& arcMm, std::vector<double>& diameterMm) const;

  // Colouring the tree by the measured diameter (`render --color-by diameter`'s rule, called: the
  // core's colourByDiameter of treeWithMeasuredRadii, flagged sections grey). On: InvalidArgument
  // without a measurement, DataError when no section was measured. Kept across measurements.
  void setColourByDiameter(bool on);
  bool colourByDiameter() const { return colourBy_; }
  // The measured tree's pieces with their colours and the legend's range: null when the colouring
  // is off or there is no measurement.
  const ColouredPieces* colouredTree() const { return colourBy_ && has_ && coloured_ ? &pieces_ : nullptr; }

 private:
  bool has_ = false;
  Tree input_;
  TreeMeasurement m_;
  int path_ = 0, section_ = -1;
  bool colourBy_ = false, coloured_ = false;
  ColouredPieces pieces_;
};

// The script's and the panel's actions: measure the trace tool's tree (InvalidArgument without
// one), select a section and move the linked cursor (the slice views) to its centre.
void measureTraceProfile(ViewerApp& app);
void selectProfileArc(ViewerApp& app, double arcMm);
// The script's `color-by diameter|none` (UsageError for another word).
void setTreeColouring(ViewerApp& app, const std::string& by);

}  // namespace vs::viewer
