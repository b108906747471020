// The `trace` pipeline, one implementation for every front end (`volscissors trace`, Python's
// `volscissors.trace`): the node cost (the auto estimate at the root, or an explicit kind), the
// root and targets snapped into the lumen, one search from the root resumed for every target,
// automatic terminals, and sub-voxel centrelines with radii.
// Coordinates are 0-based voxel indices (x,y,z) of the volume given; a front end that crops a
// region of interest maps its indices in and out (volume/crop.h).
// Failures: InvalidArgument for bad options or points outside the volume; DataError for a root
// or target outside any lumen within the snap radius, an impassable root, a target snapped onto
// the root, an unreachable target (UnreachableTarget) or no automatic terminal found.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tracking/trace_options.h"
#include "util/error.h"

namespace vs {

struct TraceRequest {
  Index3 root{0, 0, 0};
  std::vector<Index3> targets;
  int autoTerminals = -1;                   // < 0: off; N >= 0: up to N terminals (0: as many as minLengthMm allows)
  bool full = false;                        // complete the single-source map first (two threads); alone: the map only
  bool labels = false;                      // also return the label volume of the paths
  std::string volumeName = "trace volume";  // names the volume in errors (a file name)
  Index3 messageOffset{0, 0, 0};            // added to indices in errors and notes (a crop's corner)
  TraceOptions options;                     // cost kind name, auto cost, snap radius, refinement, terminals, tracker
  // The explicit cost kinds (options.cost != "auto"): kind is taken from options.cost; smoothMm
  // below replaces cost.smoothMm (intensity) and smooths the refinement's intensities.
  Cost3DOptions cost;
  double smoothMm = std::numeric_limits<double>::quiet_NaN();  // NaN: options.intensitySmoothMm
                                                               // (intensity) or autoCost.smoothMm
};

// A target the root cannot reach (separate component): a DataError front ends may single out.
struct UnreachableTarget : DataError {
  using DataError::DataError;
};

struct TraceResult {
  std::string costDescription;            // e.g. "auto: intensity (dark, window -1000..-975) ..."
  std::optional<LumenEstimate> estimate;  // cost "auto": polarity, lumen, window it chose
  double smoothMm = 0;                    // the smoothing sigma used (cost and refinement)
  Index3 requestedRoot{0, 0, 0};
  Index3 root{0, 0, 0};  // used: snapped into the lumen, then to the nearest graph node
  // Per extracted path, in order (the given targets first, then automatic terminals):
  // paths[i].requested is the target as given (an automatic terminal: the node chosen),
  // paths[i].target the node reached (after snapping into the lumen and onto the graph).
  std::vector<TracedPath> paths;
  std::vector<std::vector<Vec3>> points;     // per path, per voxel: refined centreline (continuous
                                             // index); empty when not refined
  std::vector<std::vector<double>> radiiMm;  // per path, per voxel: radius (refined, else estimated)
  std::vector<Index3> branchPoints;
  Tree tree;  // world mm, refined positions and radii when refined
  std::optional<VolumeU16> labels;
  TrackerStats stats;
  double featureSeconds = 0, refineSeconds = 0;
  // CPU seconds (all threads) of the search and the refinement: on a loaded machine they differ
  // a lot from the wall seconds.
  double searchCpuSeconds = 0, refineCpuSeconds = 0;
  // Where the time went, in order: the cost's phases (TraceSession::featurePhases), "search" (root and
  // targets), "terminals" (automatic terminals), "refine".
  std::vector<PhaseTime> phases;
  bool refined = false;
  std::vector<std::string> notes;  // what was moved or found: snapped root/targets, terminals
};

// Costs that mark a lumen (auto, intensity, vesselness; not gradient or given): roots and targets
// snap into it, refined points are confined to it.
bool costMarksLumen(const std::string& cost);

TraceResult runTrace(const VolumeF32& volume, const TraceRequest& request, Progress& progress = Progress::none());

}  // namespace vs
