#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

/// Pixel types an image file can hold.
enum class PixelType { kUInt8, kUInt16 };

/// An image in memory: row-major with row 0 at the top, channels interleaved (1 grey, 2 grey and
/// alpha, 3 RGB, 4 RGBA), 16-bit samples in the machine's byte order, rows tightly packed.
struct AMBFPLUS_API Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  PixelType type = PixelType::kUInt8;
  std::vector<std::uint8_t> pixels;

  /// Bytes of one sample: 1 for kUInt8, 2 for kUInt16.
  int sample_bytes() const { return type == PixelType::kUInt8 ? 1 : 2; }
  /// Bytes of one row.
  std::size_t row_bytes() const { return std::size_t(width) * channels * sample_bytes(); }
  /// The first byte of row r (0 is the top).
  const std::uint8_t* row(int r) const { return pixels.data() + std::size_t(r) * row_bytes(); }
  std::uint8_t* row(int r) { return pixels.data() + std::size_t(r) * row_bytes(); }
};

/// Largest width or height read_image accepts.
inline constexpr int kMaxImageSide = 65535;
/// Most bytes of pixels read_image allocates for one image (1 GiB).
inline constexpr std::size_t kMaxImageBytes = std::size_t{1} << 30;

/// Reads a PNG or JPEG file (chosen by its first bytes, not its name). PNG: grey, grey and alpha,
/// RGB, RGBA or palette, 1 to 16 bits, interlaced or not; palettes become RGB, or RGBA when the
/// file gives transparency (tRNS), which also gives RGB images an alpha channel (a grey image's
/// transparent grey level is ignored); bit depths below 8 become 8, 16 stays 16. JPEG: 8-bit
/// grey (1 channel), or colour (YCbCr, RGB, CMYK: 3 channels, RGB). Throws AssetNotFound when the
/// file does not exist, and ConfigError naming the file and what is wrong when it is not a PNG or
/// JPEG, is truncated or corrupt (a checksum, a code or a header field), or is larger than
/// kMaxImageSide or kMaxImageBytes: never a partial image.
AMBFPLUS_API Image read_image(const std::string& path);

/// Writes a row-major image (row 0 at the top; 1 channel grey, 2 grey and alpha, 3 RGB, 4 RGBA)
/// to a file whose extension picks the format: .png (8 or 16 bits) or .jpg/.jpeg (8 bits, grey
/// or RGB, quality 95). row_stride is in bytes (0 means tightly packed). Throws ConfigError
/// naming the path when the format cannot hold the image or the file cannot be written (and
/// leaves no partial file behind).
AMBFPLUS_API void write_image(const std::string& path, const void* pixels, int height, int width,
                              int channels, PixelType type, std::size_t row_stride = 0);

/// write_image of an Image.
AMBFPLUS_API void write_image(const std::string& path, const Image& image);

}  // namespace ambfplus
