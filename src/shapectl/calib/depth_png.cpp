#include <shapectl/calib/depth_png.hpp>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <png.h>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {

// libpng reports errors by longjmp back into the function that called it: this holds the
// message, and the bytes it reads or writes. No C++ object is made between setjmp and a call
// that may jump, so none is skipped.
struct PngStream {
  const std::string* input = nullptr;
  std::size_t position = 0;
  std::string* output = nullptr;
  std::vector<png_byte> row;  // one row's big-endian samples
  char message[256] = "";
};

PngStream& stream_of(png_structp png) { return *static_cast<PngStream*>(png_get_io_ptr(png)); }

void on_error(png_structp png, png_const_charp message) {
  PngStream* s = static_cast<PngStream*>(png_get_error_ptr(png));
  std::strncpy(s->message, message, sizeof(s->message) - 1);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // a harmless ancillary chunk: ignored

void read_bytes(png_structp png, png_bytep data, png_size_t length) {
  PngStream& s = stream_of(png);
  if (length > s.input->size() - s.position) png_error(png, "the file ends early (truncated)");
  std::memcpy(data, s.input->data() + s.position, length);
  s.position += length;
}

void write_bytes(png_structp png, png_bytep data, png_size_t length) {
  stream_of(png).output->append(reinterpret_cast<const char*>(data), length);
}

void flush(png_structp) {}

const char* colour_name(int colour_type) {
  switch (colour_type) {
    case PNG_COLOR_TYPE_GRAY: return "grayscale";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "grayscale with alpha";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    default: return "RGBA";
  }
}

// Reads into `pixels` (sized here, once the header is checked); false with s.message set on a
// problem.
bool read_png(PngStream& s, DepthPixels& pixels) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::strcpy(s.message, "out of memory");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, &s, read_bytes);
  png_set_user_limits(png, 1u << 16, 1u << 16);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info),
                    height = png_get_image_height(png, info);
  const int depth = png_get_bit_depth(png, info), colour = png_get_color_type(png, info);
  if (depth != 16 || colour != PNG_COLOR_TYPE_GRAY) {
    std::snprintf(s.message, sizeof(s.message), "expected a 16-bit grayscale PNG, got %d-bit %s",
                  depth, colour_name(colour));
  } else if (std::uint64_t(width) * height > max_depth_image_pixels) {
    std::snprintf(s.message, sizeof(s.message), "%u x %u pixels, more than the limit of %zu pixels",
                  unsigned(width), unsigned(height), max_depth_image_pixels);
  }
  if (s.message[0]) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  pixels.width = static_cast<int>(width), pixels.height = static_cast<int>(height);
  pixels.values.assign(std::size_t(width) * height, 0);
  std::vector<png_byte>& row = s.row;
  row.resize(2 * std::size_t(width));
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 v = 0; v < height; ++v) {
      std::uint16_t* out = pixels.values.data() + std::size_t(v) * width;
      // Interlaced passes fill in a row read before: start from what it holds.
      for (png_uint_32 u = 0; u < width; ++u)
        row[2 * u] = png_byte(out[u] >> 8), row[2 * u + 1] = png_byte(out[u] & 0xff);
      png_read_row(png, row.data(), nullptr);
      for (png_uint_32 u = 0; u < width; ++u)
        out[u] = static_cast<std::uint16_t>(row[2 * u] << 8 | row[2 * u + 1]);
    }
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

DepthPixels read_depth_png(const std::string& name, const std::string& bytes) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8))
    throw InputError(name, "", "expected the PNG signature (not a PNG file)");
  PngStream s;
  s.input = &bytes;
  DepthPixels pixels;
  if (!read_png(s, pixels)) throw InputError(name, "", s.message);
  return pixels;
}

std::string depth_png_bytes(const DepthPixels& pixels) {
  std::string out;
  PngStream s;
  s.output = &out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(std::string("writing a PNG: ") + s.message);
  }
  png_set_write_fn(png, &s, write_bytes, flush);
  png_set_IHDR(png, info, png_uint_32(pixels.width), png_uint_32(pixels.height), 16,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  std::vector<png_byte>& row = s.row;
  row.resize(2 * std::size_t(pixels.width));
  for (int v = 0; v < pixels.height; ++v) {
    const std::uint16_t* in = pixels.values.data() + std::size_t(v) * pixels.width;
    for (int u = 0; u < pixels.width; ++u)
      row[2 * u] = png_byte(in[u] >> 8), row[2 * u + 1] = png_byte(in[u] & 0xff);
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

}  // namespace shapectl
