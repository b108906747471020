// Collapses a (possibly multi-line) library message into one line: runs of white space
// become one blank. Eigen- and ITK-free so that itk_bridge.cpp can use it too.
#pragma once

#include <string>

namespace vs::io_detail {

std::string oneLine(const std::string& s);

}  // namespace vs::io_detail
