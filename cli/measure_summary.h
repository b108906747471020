// The table `measure` and `trace --measure` print: one line per root->tip path.
#pragma once

#include "quantify/quantify.h"

namespace vs::cli {

void printMeasurement(const TreeMeasurement& m, double seconds);

}  // namespace vs::cli
