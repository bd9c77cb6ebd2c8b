// JPEG through libjpeg(-turbo). Its errors end in error_exit, which must not return: ours
// longjmps back. Every function that calls setjmp below holds only trivially destructible
// locals, so the jump skips no destructor; buffers are made before and freed after, in the
// callers.
#include <cstddef>
#include <cstdio>
// clang-format off: jpeglib.h needs size_t and FILE declared first.
#include <jerror.h>
#include <jpeglib.h>
// clang-format on

#include <csetjmp>
#include <vector>

#include "ambfplus/errors.h"
#include "io/image_codecs.h"

namespace ambfplus::image_codecs {
namespace {

constexpr int kJpegQuality = 95;
// A progressive file may hold any number of scans, each a pass over the whole image; real
// encoders write a dozen at most, a hostile file millions.
constexpr int kMaxJpegScans = 500;

// libjpeg's error manager, first so that libjpeg's pointer to it is a pointer to all of it.
struct JpegErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void on_error(j_common_ptr info) {
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}

// Warnings (level -1) mean corrupt data that libjpeg would paper over with grey or repeated
// blocks: they fail the read, except those about metadata that leave every pixel intact.
void on_message(j_common_ptr info, int level) {
  if (level >= 0) return;
  const int code = info->err->msg_code;
  if (code == JWRN_JFIF_MAJOR || code == JWRN_BOGUS_ICC) return;
  on_error(info);
}

struct JpegProgress {
  jpeg_progress_mgr base;
};

void on_progress(j_common_ptr info) {
  if (!info->is_decompressor) return;
  if (reinterpret_cast<j_decompress_ptr>(info)->input_scan_number <= kMaxJpegScans) return;
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  std::snprintf(errors->message, sizeof errors->message, "more than %d progressive scans",
                kMaxJpegScans);
  std::longjmp(errors->jump, 1);
}

void use_errors(JpegErrors* errors) {
  jpeg_std_error(&errors->base);
  errors->base.error_exit = on_error;
  errors->base.emit_message = on_message;
  errors->message[0] = '\0';
}

bool read_header(jpeg_decompress_struct* info, JpegErrors* errors, JpegProgress* progress,
                 std::FILE* file) {
  if (setjmp(errors->jump)) return false;
  jpeg_create_decompress(info);
  progress->base.progress_monitor = on_progress;
  info->progress = &progress->base;
  // libjpeg's own working memory (a progressive image's coefficients), bounded like the pixels.
  info->mem->max_memory_to_use = static_cast<long>(kMaxImageBytes);
  jpeg_stdio_src(info, file);
  jpeg_read_header(info, TRUE);
  switch (info->jpeg_color_space) {
    case JCS_GRAYSCALE:
      info->out_color_space = JCS_GRAYSCALE;
      break;
    case JCS_CMYK:
    case JCS_YCCK:
      info->out_color_space = JCS_CMYK;  // libjpeg gives no RGB from these: converted below
      break;
    default:
      info->out_color_space = JCS_RGB;
  }
  jpeg_calc_output_dimensions(info);
  return true;
}

bool read_rows(jpeg_decompress_struct* info, JpegErrors* errors, std::uint8_t* pixels,
               std::size_t row_bytes) {
  if (setjmp(errors->jump)) return false;
  jpeg_start_decompress(info);
  while (info->output_scanline < info->output_height) {
    JSAMPROW row = pixels + std::size_t(info->output_scanline) * row_bytes;
    jpeg_read_scanlines(info, &row, 1);
  }
  jpeg_finish_decompress(info);
  return true;
}

bool write_rows(jpeg_compress_struct* info, JpegErrors* errors, std::FILE* file,
                const ImageView* image) {
  if (setjmp(errors->jump)) return false;
  jpeg_create_compress(info);
  jpeg_stdio_dest(info, file);
  info->image_width = static_cast<JDIMENSION>(image->width);
  info->image_height = static_cast<JDIMENSION>(image->height);
  info->input_components = image->channels;
  info->in_color_space = image->channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(info);
  jpeg_set_quality(info, kJpegQuality, TRUE);
  jpeg_start_compress(info, TRUE);
  while (info->next_scanline < info->image_height) {
    // libjpeg reads the rows it is given without writing to them.
    JSAMPROW row =
        const_cast<JSAMPROW>(image->pixels + std::size_t(info->next_scanline) * image->row_stride);
    jpeg_write_scanlines(info, &row, 1);
  }
  jpeg_finish_compress(info);
  return true;
}

// CMYK as Adobe writes it (inverted: 255 is no ink) to RGB, in place: each colour times black.
void cmyk_to_rgb(Image& image) {
  const std::size_t n = std::size_t(image.width) * image.height;
  std::uint8_t* px = image.pixels.data();
  for (std::size_t i = 0; i < n; ++i) {
    const int c = px[4 * i], m = px[4 * i + 1], y = px[4 * i + 2], k = px[4 * i + 3];
    px[3 * i] = static_cast<std::uint8_t>(k - (((255 - c) * k) >> 8));
    px[3 * i + 1] = static_cast<std::uint8_t>(k - (((255 - m) * k) >> 8));
    px[3 * i + 2] = static_cast<std::uint8_t>(k - (((255 - y) * k) >> 8));
  }
  image.channels = 3;
  image.pixels.resize(n * 3);
}

}  // namespace

Image read_jpeg(const std::string& path, std::FILE* file) {
  JpegErrors errors;
  JpegProgress progress{};
  jpeg_decompress_struct info{};
  info.err = &errors.base;
  use_errors(&errors);
  struct Guard {
    jpeg_decompress_struct* info;
    ~Guard() { jpeg_destroy_decompress(info); }
  } guard{&info};
  if (!read_header(&info, &errors, &progress, file)) {
    throw ConfigError(path, std::string("cannot decode the JPEG image: ") + errors.message);
  }
  const int channels = info.output_components;
  check_image_size(path, "JPEG", info.output_width, info.output_height, channels, 1);
  Image image = allocate_image(path, static_cast<int>(info.output_width),
                               static_cast<int>(info.output_height), channels, PixelType::kUInt8);
  if (!read_rows(&info, &errors, image.pixels.data(), image.row_bytes())) {
    throw ConfigError(path, std::string("cannot decode the JPEG image: ") + errors.message);
  }
  if (info.out_color_space == JCS_CMYK) cmyk_to_rgb(image);
  return image;
}

void write_jpeg(const std::string& path, std::FILE* file, const ImageView& image) {
  JpegErrors errors;
  jpeg_compress_struct info{};
  info.err = &errors.base;
  use_errors(&errors);
  struct Guard {
    jpeg_compress_struct* info;
    ~Guard() { jpeg_destroy_compress(info); }
  } guard{&info};
  if (!write_rows(&info, &errors, file, &image)) {
    throw ConfigError(path, std::string("cannot write the JPEG image: ") + errors.message);
  }
}

}  // namespace ambfplus::image_codecs
