#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"
#include "io/image_codecs.h"
#include "util/files.h"
#include "util/strings.h"

namespace fs = std::filesystem;

namespace ambfplus {
namespace image_codecs {

void check_image_size(const std::string& path, const char* format, std::uint64_t width,
                      std::uint64_t height, int channels, int sample_bytes) {
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (width == 0 || height == 0) {
    throw ConfigError(path, std::string("the ") + format + " image is empty (" + size + ")");
  }
  if (width > std::uint64_t(kMaxImageSide) || height > std::uint64_t(kMaxImageSide)) {
    throw ConfigError(path, std::string("the ") + format + " image is " + size +
                                " pixels: more than the " + std::to_string(kMaxImageSide) +
                                " a side images may have");
  }
  if (width * height * std::uint64_t(channels * sample_bytes) > kMaxImageBytes) {
    throw ConfigError(path, std::string("the ") + format + " image is " + size + " pixels of " +
                                std::to_string(channels * sample_bytes) + " bytes: more than " +
                                std::to_string(kMaxImageBytes >> 20) + " MiB");
  }
}

Image allocate_image(const std::string& path, int width, int height, int channels, PixelType type) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.type = type;
  try {
    image.pixels.resize(image.row_bytes() * std::size_t(height));
  } catch (const std::bad_alloc&) {
    throw ConfigError(path, "not enough memory for a " + std::to_string(width) + "x" +
                                std::to_string(height) + " image");
  }
  return image;
}

}  // namespace image_codecs

namespace {

using FilePtr = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

enum class Format { kPng, kJpeg };

// The format an extension names, or throws ConfigError listing those write_image knows.
Format format_of_name(const std::string& path) {
  const std::string ext = to_lower(fs::path(path).extension().string());
  if (ext == ".png") return Format::kPng;
  if (ext == ".jpg" || ext == ".jpeg") return Format::kJpeg;
  throw ConfigError(path, "cannot write an image as '" + ext + "': expected .png, .jpg or .jpeg");
}

}  // namespace

Image read_image(const std::string& path) {
  require_regular_file(path, "image");
  FilePtr file(std::fopen(path.c_str(), "rb"), std::fclose);
  if (!file) throw ConfigError(path, std::string("cannot open the image: ") + std::strerror(errno));
  // The first bytes say what the file is, whatever its name.
  unsigned char magic[8] = {};
  const std::size_t got = std::fread(magic, 1, sizeof magic, file.get());
  std::rewind(file.get());
  static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got == sizeof magic && std::memcmp(magic, kPngSignature, sizeof magic) == 0) {
    return image_codecs::read_png(path, file.get());
  }
  if (got >= 3 && magic[0] == 0xff && magic[1] == 0xd8 && magic[2] == 0xff) {
    return image_codecs::read_jpeg(path, file.get());
  }
  if (got == 0) throw ConfigError(path, "cannot decode the image: the file is empty");
  throw ConfigError(path,
                    "cannot decode the image: not a PNG or JPEG file (PNG and JPEG are the "
                    "image formats read)");
}

void write_image(const std::string& path, const void* pixels, int height, int width, int channels,
                 PixelType type, std::size_t row_stride) {
  const Format format = format_of_name(path);
  if (channels < 1 || channels > 4) {
    throw ConfigError(path, "cannot write an image with " + std::to_string(channels) +
                                " channels: expected 1, 2, 3 or 4");
  }
  if (width <= 0 || height <= 0) {
    throw ConfigError(path, "cannot write an empty image (" + std::to_string(width) + "x" +
                                std::to_string(height) + ")");
  }
  if (width > kMaxImageSide || height > kMaxImageSide) {
    throw ConfigError(path, "cannot write a " + std::to_string(width) + "x" +
                                std::to_string(height) + " image: more than " +
                                std::to_string(kMaxImageSide) + " pixels a side");
  }
  if (format == Format::kJpeg && type != PixelType::kUInt8) {
    throw ConfigError(path, "JPEG holds 8-bit pixels only: write 16-bit images as .png");
  }
  if (format == Format::kJpeg && (channels == 2 || channels == 4)) {
    throw ConfigError(path, "JPEG has no alpha channel: write grey+alpha or RGBA images as .png");
  }
  image_codecs::ImageView view;
  view.pixels = static_cast<const std::uint8_t*>(pixels);
  view.width = width;
  view.height = height;
  view.channels = channels;
  view.type = type;
  const std::size_t packed = std::size_t(width) * channels * (type == PixelType::kUInt8 ? 1 : 2);
  view.row_stride = row_stride == 0 ? packed : row_stride;
  if (view.row_stride < packed) {
    throw ConfigError(path, "row stride " + std::to_string(row_stride) +
                                " is shorter than a row (" + std::to_string(packed) + " bytes)");
  }

  FilePtr file(std::fopen(path.c_str(), "wb"), std::fclose);
  if (!file) {
    throw ConfigError(path, std::string("cannot write the image: ") + std::strerror(errno));
  }
  try {
    if (format == Format::kPng) {
      image_codecs::write_png(path, file.get(), view);
    } else {
      image_codecs::write_jpeg(path, file.get(), view);
    }
    if (std::fclose(file.release()) != 0) {
      throw ConfigError(path, std::string("cannot write the image: ") + std::strerror(errno));
    }
  } catch (...) {
    // Never leave half an image behind.
    if (file) file.reset();
    std::remove(path.c_str());
    throw;
  }
}

void write_image(const std::string& path, const Image& image) {
  const bool sized =
      image.width > 0 && image.height > 0 && image.channels >= 1 && image.channels <= 4;
  if (sized && image.pixels.size() < image.row_bytes() * std::size_t(image.height)) {
    throw ConfigError(path, "cannot write the image: it holds fewer pixels than its size says");
  }
  write_image(path, image.pixels.data(), image.height, image.width, image.channels, image.type);
}

}  // namespace ambfplus
