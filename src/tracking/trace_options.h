// The policies of `trace` that every front end shares (the CLI's defaults and --help read them
// from here): which cost by default, how much the intensity cost smooths, how far roots and
// targets snap, how centrelines are refined, how automatic terminals are chosen.
#pragma once

#include <string>

#include "tracking/auto_cost.h"
#include "tracking/centreline.h"
#include "tracking/tracker.h"

namespace vs {

struct TraceOptions {
  std::string cost = "auto";       // auto | gradient | vesselness | intensity | given
  AutoCostOptions autoCost;        // cost "auto" (its smoothMm also smooths the other kinds' refinement)
  double intensitySmoothMm = 1.0;  // cost "intensity": Gaussian pre-smoothing sigma (mm)
  double snapMm = 2.0;             // roots and targets outside the lumen move to the nearest lumen voxel within this
  bool refine = true;              // sub-voxel centring and radii (centreline.h)
  CentrelineOptions centreline;
  AutoTerminalOptions autoTerminals;
  TrackerOptions tracker;
};

}  // namespace vs
