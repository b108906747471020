// Filters over one scale's blocks of the local background (auto_cost_blocks.cpp; blockBackground in auto_cost.cpp).
#pragma once

#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

// Blocks without background of their own (NaN) borrow, wave by wave, the most lumen-like value of their 26 neighbours
// that have one; the window's far edge `edge` where none has any.
void borrowBackground(const BlockGrid& grid, std::vector<float>& raw, float edge, bool bright);

// grid.value: the most lumen-like of each block and its 26 neighbours; grid.spread: the median spread of those that
// have one (rawSpread < 0: none; 0 where none has).
void neighbourFilter(BlockGrid& grid, const std::vector<float>& raw, const std::vector<float>* rawSpread, bool bright);

}  // namespace vs
