// PNG through libpng: the simplified API (png_image, any colour type expanded to RGBA8) for
// images, and the low-level API with our own error handler for volumes (grey or colour,
// 8 or 16 bit kept). ITK's PNG reader is not used: it has no libpng error handler, so a
// corrupt file aborted the process.
#include "io/png_io.h"

#include <png.h>

#include <csetjmp>
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
  try {  // before allocating: the compressed stream must be able to hold the pixels
    io_detail::checkDataCanHold(uint64_t{img.width} * img.height, bytes.size(), io_detail::kDeflateExpansion, path);
  } catch (...) {
    png_image_free(&img);
    throw;
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

namespace io_detail {

namespace {

struct PngReadState {
  const std::string* bytes;
  size_t pos = 8;     // after the signature, which the caller checked
  std::string error;  // libpng's message, kept for the exception
  std::jmp_buf jump;
};

void pngError(png_structp png, png_const_charp message) {
  auto* st = static_cast<PngReadState*>(png_get_error_ptr(png));
  st->error = message ? message : "libpng error";
  std::longjmp(st->jump, 1);  // back into readPngVolume, which throws after libpng cleanup
}

void pngWarning(png_structp, png_const_charp) {}

void pngRead(png_structp png, png_bytep out, png_size_t n) {
  auto* st = static_cast<PngReadState*>(png_get_io_ptr(png));
  if (n > st->bytes->size() - st->pos) png_error(png, "file is truncated");
  std::memcpy(out, st->bytes->data() + st->pos, n);
  st->pos += n;
}

}  // namespace

AnyVolume readPngVolume(const std::string& path, ReadInfo& info) {
  const std::string bytes = readFileBytes(path, false);
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw IoError(path + ": wrong magic, not a PNG file");
  PngReadState st;
  st.bytes = &bytes;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &st, pngError, pngWarning);
  if (!png) throw IoError(path + ": libpng initialisation failed");
  png_infop pinfo = png_create_info_struct(png);
  // Everything libpng may longjmp over is plain data owned here; the C++ objects that
  // allocate (the buffer) are created before setjmp and only filled inside.
  std::vector<unsigned char> buffer;
  std::vector<png_bytep> rows;
  png_uint_32 width = 0, height = 0;
  int depth = 0, colour = 0, channels = 0;
  volatile double spacingX = 1, spacingY = 1;  // set after setjmp
  if (setjmp(st.jump)) {
    png_destroy_read_struct(&png, &pinfo, nullptr);
    throw IoError(path + ": cannot decode PNG (truncated or corrupt): " + st.error);
  }
  if (!pinfo) png_error(png, "out of memory");
  png_set_read_fn(png, &st, pngRead);
  png_set_sig_bytes(png, 8);
  png_set_user_limits(png, 65536, 65536);
  png_read_info(png, pinfo);
  png_get_IHDR(png, pinfo, &width, &height, &depth, &colour, nullptr, nullptr, nullptr);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (depth == 16 && hostIsLittleEndian()) png_set_swap(png);
  png_read_update_info(png, pinfo);
  channels = png_get_channels(png, pinfo);
  depth = png_get_bit_depth(png, pinfo);
  {
    png_uint_32 resX = 0, resY = 0;
    int unit = 0;
    if (png_get_pHYs(png, pinfo, &resX, &resY, &unit) && unit == PNG_RESOLUTION_METER && resX > 0 && resY > 0) {
      spacingX = 1000.0 / resX;  // pixels per metre -> mm per pixel
      spacingY = 1000.0 / resY;
    }
  }
  {
    const uint64_t rowBytes = png_get_rowbytes(png, pinfo);
    const uint64_t need = rowBytes * height;
    if (rowBytes != uint64_t{width} * static_cast<uint64_t>(channels) * static_cast<uint64_t>(depth / 8) ||
        static_cast<double>(need) > static_cast<double>(bytes.size()) * kDeflateExpansion + 64.0 ||
        need > maxVolumeBytes()) {
      png_error(png, "image size does not fit the file");
    }
    buffer.resize(static_cast<size_t>(need));
    rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y) rows[y] = buffer.data() + y * rowBytes;
  }
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &pinfo, nullptr);
  Geometry g;
  g.dims = {static_cast<int64_t>(width), static_cast<int64_t>(height), 1};
  g.spacing = Vec3(double(spacingX), double(spacingY), 1.0);
  const Comp comp = depth == 16 ? Comp::UInt16 : Comp::UInt8;
  info.sourceType = compName(comp) + (channels > 1 ? cat("x", std::to_string(channels)) : std::string());
  return convertBuffer(buffer.data(), comp, channels, g, info, path);
}

}  // namespace io_detail

}  // namespace vs
