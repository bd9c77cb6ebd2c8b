#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "ambfplus/io/image.h"

namespace ambfplus::image_codecs {

/// Pixels to write: row r starts at pixels + r * row_stride.
struct ImageView {
  const std::uint8_t* pixels = nullptr;
  int width = 0;
  int height = 0;
  int channels = 0;
  PixelType type = PixelType::kUInt8;
  std::size_t row_stride = 0;
};

/// Each codec reads or writes an open file and throws ConfigError naming `path` on any failure.
/// Decoders check sizes against kMaxImageSide and kMaxImageBytes before allocating.
Image read_png(const std::string& path, std::FILE* file);
Image read_jpeg(const std::string& path, std::FILE* file);
void write_png(const std::string& path, std::FILE* file, const ImageView& image);
void write_jpeg(const std::string& path, std::FILE* file, const ImageView& image);

/// Checks a decoded size against kMaxImageSide and kMaxImageBytes; throws ConfigError if over.
void check_image_size(const std::string& path, const char* format, std::uint64_t width,
                      std::uint64_t height, int channels, int sample_bytes);

/// An image of the given layout with room for its pixels; ConfigError when memory runs out.
Image allocate_image(const std::string& path, int width, int height, int channels, PixelType type);

}  // namespace ambfplus::image_codecs
