// SPDX-License-Identifier: Apache-2.0
#include "cellmap/sensor/depth_io.hpp"

#include <png.h>
#include <tiffio.h>

#include <pcl/io/lzf_image_io.h>

#include <csetjmp>
#include <cstring>
#include <filesystem>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/config/yaml_map.hpp"

namespace cellmap {
namespace {

// libtiff reports through handlers; these keep the first message for our Error instead of printing it.
int keep_tiff_message(TIFF*, void* user_data, const char*, const char* format, va_list args) {
  auto* message = static_cast<std::string*>(user_data);
  if (message->empty()) {
    char text[512];
    std::vsnprintf(text, sizeof text, format, args);
    *message = single_line(text);  // libtiff splits some messages over lines
  }
  return 1;  // handled: do not call the global handler (it would print to stderr)
}
int ignore_tiff_message(TIFF*, void*, const char*, const char*, va_list) {
  return 1;
}

// Why an image of `width` × `height` cannot be read ("" if it can): more than kMaxDepthPixels.
std::string size_problem(const std::string& path, std::uint64_t width, std::uint64_t height) {
  if (width * height <= kMaxDepthPixels) return "";
  return path + ": " + std::to_string(width) + " x " + std::to_string(height) +
         " pixels is more than a depth image may have (" + std::to_string(kMaxDepthPixels) + ")";
}

RawDepth read_tiff(const std::string& path) {
  std::string message;
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  TIFFOpenOptionsSetErrorHandlerExtR(options, keep_tiff_message, &message);
  TIFFOpenOptionsSetWarningHandlerExtR(options, ignore_tiff_message, nullptr);
  TIFF* tiff = TIFFOpenExt(path.c_str(), "r", options);
  TIFFOpenOptionsFree(options);
  if (!tiff) throw Error(path + ": cannot read TIFF" + (message.empty() ? "" : ": " + message));
  std::uint32_t width = 0, height = 0;
  std::uint16_t bits = 0, samples = 1, format = SAMPLEFORMAT_UINT;
  TIFFGetField(tiff, TIFFTAG_IMAGEWIDTH, &width);
  TIFFGetField(tiff, TIFFTAG_IMAGELENGTH, &height);
  TIFFGetField(tiff, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tiff, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tiff, TIFFTAG_SAMPLEFORMAT, &format);
  if (bits != 16 || samples != 1 || format != SAMPLEFORMAT_UINT || width == 0 || height == 0) {
    TIFFClose(tiff);
    throw Error(path + ": not a single-channel 16-bit unsigned TIFF (" + std::to_string(samples) + " x " +
                std::to_string(bits) + " bits)");
  }
  if (const std::string problem = size_problem(path, width, height); !problem.empty()) {
    TIFFClose(tiff);
    throw Error(problem);
  }
  RawDepth image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.depth.resize(static_cast<std::size_t>(width) * height);
  for (std::uint32_t row = 0; row < height; ++row) {
    if (TIFFReadScanline(tiff, image.depth.data() + static_cast<std::size_t>(row) * width, row, 0) < 0) {
      TIFFClose(tiff);
      throw Error(path + ": cannot read TIFF row " + std::to_string(row) +
                  (message.empty() ? "" : ": " + message));
    }
  }
  TIFFClose(tiff);
  return image;
}

// libpng reports errors through a callback that must not return; it longjmps back to the setjmp in the
// caller. No C++ object is created between the setjmp and a libpng call, so the jump skips no destructor.
struct PngContext {
  std::string message;
  const std::string* input = nullptr;
  std::size_t offset = 0;
  std::string* output = nullptr;
};

void png_fail(png_structp png, png_const_charp text) {
  auto* context = static_cast<PngContext*>(png_get_error_ptr(png));
  if (context->message.empty()) context->message = text;
  png_longjmp(png, 1);
}
void png_warn(png_structp, png_const_charp) {}

void png_read_memory(png_structp png, png_bytep data, png_size_t length) {
  auto* context = static_cast<PngContext*>(png_get_io_ptr(png));
  if (context->offset + length > context->input->size()) png_error(png, "file is truncated");
  std::memcpy(data, context->input->data() + context->offset, length);
  context->offset += length;
}
void png_write_memory(png_structp png, png_bytep data, png_size_t length) {
  auto* context = static_cast<PngContext*>(png_get_io_ptr(png));
  context->output->append(reinterpret_cast<const char*>(data), length);
}
void png_flush_memory(png_structp) {}

RawDepth read_png(const std::string& path) {
  const std::string bytes = read_file(path);
  PngContext context;
  context.input = &bytes;
  RawDepth image;
  std::vector<png_bytep> rows;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &context, png_fail, png_warn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path + ": cannot allocate a PNG reader");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path + ": cannot read PNG: " + context.message);
  }
  png_set_read_fn(png, &context, png_read_memory);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  const int bits = png_get_bit_depth(png, info);
  const int color = png_get_color_type(png, info);
  if (bits != 16 || color != PNG_COLOR_TYPE_GRAY) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path + ": not a single-channel 16-bit grayscale PNG (bit depth " + std::to_string(bits) +
                ", color type " + std::to_string(color) + ")");
  }
  if (const std::string problem = size_problem(path, width, height); !problem.empty()) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(problem);
  }
  png_set_swap(png);  // PNG stores 16-bit samples big-endian
  png_read_update_info(png, info);
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.depth.resize(static_cast<std::size_t>(width) * height);
  rows.resize(height);
  for (png_uint_32 row = 0; row < height; ++row) {
    rows[row] = reinterpret_cast<png_bytep>(image.depth.data() + static_cast<std::size_t>(row) * width);
  }
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

// Exposes the depth scale PCL's reader parsed (it keeps it in a protected member without an accessor).
class PclDepthParameters : public pcl::io::LZFDepth16ImageReader {
 public:
  [[nodiscard]] double z_multiplication_factor() const { return z_multiplication_factor_; }
};

}  // namespace

RawDepth read_depth_image(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".png") return read_png(path);
  if (ext == ".tif" || ext == ".tiff") return read_tiff(path);
  throw Error(path + ": unknown depth image type '" + ext + "' (expected .png, .tif or .tiff)");
}

void write_depth_png(const std::string& path, const RawDepth& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.depth.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw Error(path + ": depth image size " + std::to_string(image.depth.size()) + " disagrees with " +
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  std::string bytes;
  PngContext context;
  context.output = &bytes;
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
  for (int row = 0; row < image.height; ++row) {
    // libpng does not write through row pointers; the cast only drops const for its API.
    rows[row] = reinterpret_cast<png_bytep>(const_cast<std::uint16_t*>(image.depth.data()) +
                                            static_cast<std::size_t>(row) * image.width);
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &context, png_fail, png_warn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw Error(path + ": cannot allocate a PNG writer");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error(path + ": cannot encode PNG: " + context.message);
  }
  png_set_write_fn(png, &context, png_write_memory, png_flush_memory);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 16,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_swap(png);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  write_file_atomically(path, bytes);
}

PinholeIntrinsics read_pcl_intrinsics_xml(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path + ": no such intrinsics file");
  PclDepthParameters reader;
  bool ok = false;
  try {
    ok = reader.readParameters(path);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot parse intrinsics XML: " + e.what());
  }
  const pcl::io::CameraParameters parameters = reader.getParameters();
  if (!ok || !(parameters.focal_length_x > 0) || !(parameters.focal_length_y > 0)) {
    throw Error(path + ": no <depth> focal_length_x/y, principal_point_x/y in intrinsics XML");
  }
  PinholeIntrinsics intrinsics;
  intrinsics.fx = parameters.focal_length_x;
  intrinsics.fy = parameters.focal_length_y;
  intrinsics.cx = parameters.principal_point_x;
  intrinsics.cy = parameters.principal_point_y;
  intrinsics.depth_scale = reader.z_multiplication_factor();
  if (!(intrinsics.depth_scale > 0)) throw Error(path + ": z_multiplication_factor must be > 0");
  return intrinsics;
}

PinholeIntrinsics read_intrinsics_yaml(const std::string& path) {
  YamlMap map = YamlMap::load(path);
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"}) {
    if (!map.has(key)) map.fail(key, "is required");
  }
  PinholeIntrinsics k;
  k.width = static_cast<int>(map.integer("width", 0, 1, 100000));
  k.height = static_cast<int>(map.integer("height", 0, 1, 100000));
  k.fx = map.number("fx", 0, 1e-9, 1e9);
  k.fy = map.number("fy", 0, 1e-9, 1e9);
  k.cx = map.number("cx", 0, -1e9, 1e9);
  k.cy = map.number("cy", 0, -1e9, 1e9);
  k.depth_scale = map.number("depth_scale", 0.001, 1e-9, 1e3);
  k.min_range = map.number("min_range", 0.0, 0.0, 1e3);
  k.max_range = map.number("max_range", 10.0, 1e-9, 1e3);
  k.max_depth_jump = map.number("max_depth_jump", kDefaultMaxDepthJump, 0.0, 10.0);
  k.smoothing_radius = static_cast<int>(map.integer("smoothing_radius", 0, 0, kMaxSmoothingRadius));
  map.expect_all_read();
  try {
    k.validate();
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  return k;
}

}  // namespace cellmap
