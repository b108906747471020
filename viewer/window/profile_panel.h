// The profile plot of the traced tree (issue 24) in the window: diameter against arc length of
// the selected path (Dear ImGui draw list, axes labelled in mm) and the selected cross-section
// drawn on the slice views and in the 3D view. The data and the selection are the GL-free
// app/profile.h (the core's measureTree); the window calls these few functions.
#pragma once
#include <imgui.h>

#include <functional>
#include <string>

#include "app/viewer_app.h"

namespace vs::viewer {

// Colours the tests look for: the plot's line and the selected section (plot marker, contours).
constexpr int kProfileLineRgb[3] = {255, 170, 0};
constexpr int kProfileSectionRgb[3] = {0, 255, 255};

// Pixels the profile window takes at the bottom of the tool panel: 0 without a measurement. Drops
// a measurement whose tree is no longer the trace tool's (the trace changed).
float profileWindowHeight(ViewerApp& app);
// The profile window at pos/size: the path chooser, the plot (flagged sections are gaps, branch
// points' neighbour sections dots, the selected section a cyan line) and the selected section's
// numbers. A click on the plot selects the nearest section and moves the cursor to it. Errors go
// to `status`.
void profileWindow(ViewerApp& app, ImVec2 pos, ImVec2 size, std::string& status);
// The trace panel's button: measures the traced tree; once measured, the "colour by diameter" toggle.
void measureButton(ViewerApp& app, std::string& status);
// The colour bar of the tree's diameter colouring at the right edge of the 3D view (min, middle,
// max in mm: the core's colourLegendTicks and rampColour, as `render --color-by diameter`).
void drawDiameterLegend(ImDrawList* dl, ImVec2 viewMin, ImVec2 viewSize, const ColouredPieces& coloured);
constexpr int kLegendBackingRgb[3] = {20, 20, 20};
// The selected section's boundary and centre in the 3D view (project: world mm -> screen).
void drawProfileSection3D(const ViewerApp& app, ImDrawList* dl,
                          const std::function<bool(const Vec3&, ImVec2&)>& project);
// ... on the slice view across `axis` showing slice `index` (screen: in-slice voxel coordinates
// u, v -> screen), when the section's centre lies within its radius of that slice.
void drawProfileSectionOnSlice(const ViewerApp& app, ImDrawList* dl, int axis, int64_t index,
                               const std::function<ImVec2(double, double)>& screen);
// The mouse over a slice view at a voxel: selects the section whose centre is within two voxels.
void hoverProfile(ViewerApp& app, const Index3& voxel);

}  // namespace vs::viewer
