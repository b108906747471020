// PNG through libpng's simplified API (png_image): no setjmp, any colour type expanded to RGBA8.
#include "io/png_io.h"

#include <png.h>

#include <cstring>
#include <filesystem>

#include "io/io_internal.h"
#include "util/atomic_file.h"

namespace vs {

void writePng(const RgbaImage& image, const std::string& path) {
  VS_REQUIRE(image.width > 0 && image.height > 0, "writePng: image is empty");
  VS_REQUIRE(image.pixels.size() == static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 4,
             "writePng: pixel buffer size does not match width x height x 4");
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = static_cast<png_uint_32>(image.width);
  img.height = static_cast<png_uint_32>(image.height);
  img.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&img, nullptr, &size, 0, image.pixels.data(), 0, nullptr))
    throw IoError(path + ": PNG encoding failed: " + img.message);
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&img, bytes.data(), &size, 0, image.pixels.data(), 0, nullptr))
    throw IoError(path + ": PNG encoding failed: " + img.message);
  bytes.resize(size);
  writeFileAtomically(path, bytes);
}

RgbaImage readPng(const std::string& path) {
  const std::string bytes = io_detail::readFileBytes(path, false);
  if (bytes.size() < 8 || std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) != 0)
    throw IoError(path + ": wrong magic, not a PNG file");
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size()))
    throw IoError(path + ": cannot read PNG: " + img.message);
  if (img.width == 0 || img.height == 0 || img.width > 65536 || img.height > 65536) {
    png_image_free(&img);
    throw IoError(path + ": absurd PNG size " + std::to_string(img.width) + "x" + std::to_string(img.height));
  }
  img.format = PNG_FORMAT_RGBA;
  RgbaImage out(static_cast<int>(img.width), static_cast<int>(img.height));
  if (!png_image_finish_read(&img, nullptr, out.pixels.data(), 0, nullptr)) {
    const std::string msg = img.message;
    png_image_free(&img);
    throw IoError(path + ": cannot decode PNG (truncated or corrupt): " + msg);
  }
  return out;
}

}  // namespace vs
