// PNG through libpng. libpng reports errors by longjmp: every function that calls setjmp below
// holds only trivially destructible locals, so the jump skips no destructor; buffers are made
// before and freed after, in the callers.
#include <png.h>
#include <zlib.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "ambfplus/errors.h"
#include "io/image_codecs.h"

namespace ambfplus::image_codecs {
namespace {

constexpr bool kLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

// What libpng's callbacks hand back to the code that called it.
struct PngState {
  std::FILE* file = nullptr;
  char error[256] = {};
  char warning[256] = {};
};

void on_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngState*>(png_get_error_ptr(png));
  std::snprintf(state->error, sizeof state->error, "%s", message);
  png_longjmp(png, 1);
}

// Keeps the first warning: libpng explains some errors ("Invalid IHDR data") in a warning first.
void on_warning(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngState*>(png_get_error_ptr(png));
  if (state->warning[0] == '\0')
    std::snprintf(state->warning, sizeof state->warning, "%s", message);
}

void on_read(png_structp png, png_bytep data, std::size_t length) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  if (std::fread(data, 1, length, state->file) == length) return;
  png_error(png, std::feof(state->file) ? "the file ends early (truncated)" : "read error");
}

void on_write(png_structp png, png_bytep data, std::size_t length) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  if (std::fwrite(data, 1, length, state->file) != length) png_error(png, std::strerror(errno));
}

void on_flush(png_structp) {}

std::string failure(const char* what, const PngState& state) {
  std::string reason = std::string(what) + ": " + state.error;
  if (state.warning[0] != '\0') reason += std::string(" (") + state.warning + ")";
  return reason;
}

// Ancillary chunks that change no pixel: skipped unread (no profile or text parsing, no warnings
// about them).
constexpr png_byte kIgnoredChunks[] = "iCCP\0iTXt\0tEXt\0zTXt\0sPLT\0eXIf\0tIME\0hIST\0pHYs\0";

// The layout after the transforms read_png asks for.
struct PngLayout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int channels = 0;
  int bit_depth = 0;
  std::size_t row_bytes = 0;
};

bool read_layout(png_structp png, png_infop info, PngLayout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, kIgnoredChunks,
                              static_cast<int>(sizeof kIgnoredChunks / 5));
  png_read_info(png, info);
  const int colour = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  // A transparent colour becomes alpha for palette and RGB images (a grey level stays grey).
  if ((colour == PNG_COLOR_TYPE_PALETTE || colour == PNG_COLOR_TYPE_RGB) &&
      png_get_valid(png, info, PNG_INFO_tRNS)) {
    png_set_tRNS_to_alpha(png);
  }
  if (depth == 16 && kLittleEndian) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->width = png_get_image_width(png, info);
  layout->height = png_get_image_height(png, info);
  layout->channels = png_get_channels(png, info);
  layout->bit_depth = png_get_bit_depth(png, info);
  layout->row_bytes = png_get_rowbytes(png, info);
  return true;
}

bool read_pixels(png_structp png, png_infop info, png_bytep* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  // Through IEND, so a file cut after its pixels or with a bad checksum there is an error too.
  png_read_end(png, nullptr);
  return true;
}

bool write_rows(png_structp png, png_infop info, const ImageView* image, png_bytep* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  static constexpr int kColourTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                         PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  const int depth = image->type == PixelType::kUInt8 ? 8 : 16;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image->width),
               static_cast<png_uint_32>(image->height), depth, kColourTypes[image->channels - 1],
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Fast rather than small: camera frames and slices are written often, read rarely.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_write_info(png, info);
  if (depth == 16 && kLittleEndian) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

// Frees libpng's structures however the work ended.
struct ReadGuard {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~ReadGuard() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

struct WriteGuard {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~WriteGuard() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

}  // namespace

Image read_png(const std::string& path, std::FILE* file) {
  PngState state;
  state.file = file;
  ReadGuard guard;
  guard.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, on_error, on_warning);
  if (guard.png != nullptr) guard.info = png_create_info_struct(guard.png);
  if (guard.info == nullptr) throw ConfigError(path, "cannot read the PNG image: out of memory");
  png_set_read_fn(guard.png, &state, on_read);

  PngLayout layout;
  if (!read_layout(guard.png, guard.info, &layout)) {
    throw ConfigError(path, failure("cannot decode the PNG image", state));
  }
  check_image_size(path, "PNG", layout.width, layout.height, layout.channels, layout.bit_depth / 8);
  Image image = allocate_image(path, static_cast<int>(layout.width),
                               static_cast<int>(layout.height), layout.channels,
                               layout.bit_depth == 16 ? PixelType::kUInt16 : PixelType::kUInt8);
  if (layout.row_bytes != image.row_bytes()) {
    throw ConfigError(path, "cannot decode the PNG image: unexpected row size " +
                                std::to_string(layout.row_bytes));
  }
  std::vector<png_bytep> rows(image.height);
  for (int r = 0; r < image.height; ++r) rows[r] = image.row(r);
  if (!read_pixels(guard.png, guard.info, rows.data())) {
    throw ConfigError(path, failure("cannot decode the PNG image", state));
  }
  return image;
}

void write_png(const std::string& path, std::FILE* file, const ImageView& image) {
  PngState state;
  state.file = file;
  WriteGuard guard;
  guard.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, on_error, on_warning);
  if (guard.png != nullptr) guard.info = png_create_info_struct(guard.png);
  if (guard.info == nullptr) throw ConfigError(path, "cannot write the PNG image: out of memory");
  png_set_write_fn(guard.png, &state, on_write, on_flush);
  // libpng copies each row before transforming it, so the caller's pixels stay untouched.
  std::vector<png_bytep> rows(image.height);
  for (int r = 0; r < image.height; ++r) {
    rows[r] = const_cast<png_bytep>(image.pixels + std::size_t(r) * image.row_stride);
  }
  if (!write_rows(guard.png, guard.info, &image, rows.data())) {
    throw ConfigError(path, failure("cannot write the PNG image", state));
  }
}

}  // namespace ambfplus::image_codecs
