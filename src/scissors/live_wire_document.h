// The one home of "a live-wire on a slice of a volume" for every front end (issue 23): the CLI's
// `livewire`, Python's volscissors.livewire / LiveWire and the viewer build the wire and its
// contour document here instead of each writing the conversion.
#pragma once

#include <string>
#include <vector>

#include "scissors/live_wire.h"
#include "volume/contour_document.h"
#include "volume/volume.h"

namespace vs {

// The live-wire of slice `index` along index axis `axis` of a volume of any voxel type; `what`
// names it in errors (default "slice z=40"). Throws InvalidArgument for a slice outside the volume.
LiveWire liveWireOnSlice(const AnyVolume& volume, int axis, int64_t index, const LiveWireOptions& options = {},
                         const std::string& what = {});

// The clicks behind a contour: as given, and after snapping (the seeds actually used).
struct ContourClicks {
  std::vector<PixelUV> input;
  std::vector<PixelUV> snapped;  // empty: the same as input
  double snapPx = 0;             // the snap radius used (0: none)
};

// The document of the wire's current contour on slice (axis, index) of a volume with `geometry`:
// slice pixels, voxel indices, world points (LPS mm), picture positions (volume/slice.h), the
// cost options, every committed segment, and for a closed contour the area inside (pixels and
// mm^2, boundary included). `file` names the volume; `mask` is left empty for the caller.
ContourDocument contourDocument(const LiveWire& wire, const Geometry& geometry, int axis, int64_t index,
                                const ContourClicks& clicks = {}, const std::string& file = {});

}  // namespace vs
