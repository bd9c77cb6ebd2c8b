#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

/// Pixel types an image file can hold.
enum class PixelType { kUInt8, kUInt16 };

/// Writes a row-major image (row 0 at the top; 1 channel grey, 3 channels RGB or 4 RGBA) to a
/// file whose extension picks the format (.png, .jpg, ...). Throws ConfigError naming the path on
/// failure. row_stride is in bytes (0 means tightly packed).
AMBFPLUS_API void write_image(const std::string& path, const void* pixels, int height, int width,
                              int channels, PixelType type, std::size_t row_stride = 0);

/// An 8-bit RGBA image, row 0 at the top.
struct AMBFPLUS_API RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  ///< 4 per pixel, row-major
};

/// Reads an image file (PNG, JPEG, BMP, TGA through OpenCV; grey, RGB or RGBA, 8 or 16 bits)
/// as 8-bit RGBA. Throws AssetNotFound when the file does not exist and ConfigError naming the
/// file when it cannot be decoded.
AMBFPLUS_API RgbaImage read_image_rgba(const std::string& path);

}  // namespace ambfplus
