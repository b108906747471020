// PNG images through libpng. Writes are atomic; errors are IoError naming the file.
#pragma once

#include <string>

#include "util/image.h"

namespace vs {

void writePng(const RgbaImage& image, const std::string& path);
RgbaImage readPng(const std::string& path);  // any PNG colour type, expanded to RGBA8

}  // namespace vs
