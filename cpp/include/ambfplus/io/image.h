#pragma once

#include <cstdint>
#include <string>

#include "ambfplus/export.h"

namespace ambfplus {

/// Pixel types an image file can hold.
enum class PixelType { kUInt8, kUInt16 };

/// Writes a row-major image (row 0 at the top; 1 channel grey, 3 channels RGB or 4 RGBA) to a
/// file whose extension picks the format (.png, .jpg, ...). Throws ConfigError naming the path on
/// failure. row_stride is in bytes (0 means tightly packed).
AMBFPLUS_API void write_image(const std::string& path, const void* pixels, int height, int width,
                              int channels, PixelType type, std::size_t row_stride = 0);

}  // namespace ambfplus
