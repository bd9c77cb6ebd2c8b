#include <algorithm>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <system_error>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"

namespace ambfplus {

void write_image(const std::string& path, const void* pixels, int height, int width, int channels,
                 PixelType type, std::size_t row_stride) {
  if (channels != 1 && channels != 3 && channels != 4) {
    throw ConfigError(path, "cannot write an image with " + std::to_string(channels) +
                                " channels: expected 1, 3 or 4");
  }
  const int depth = type == PixelType::kUInt8 ? CV_8U : CV_16U;
  const cv::Mat view(height, width, CV_MAKETYPE(depth, channels), const_cast<void*>(pixels),
                     row_stride == 0 ? static_cast<std::size_t>(cv::Mat::AUTO_STEP) : row_stride);
  // OpenCV writes BGR(A); our images are RGB(A).
  cv::Mat ordered;
  if (channels == 3) {
    cv::cvtColor(view, ordered, cv::COLOR_RGB2BGR);
  } else if (channels == 4) {
    cv::cvtColor(view, ordered, cv::COLOR_RGBA2BGRA);
  } else {
    ordered = view;
  }
  bool ok = false;
  std::string reason = "the format is unknown or the folder is not writable";
  try {
    ok = cv::imwrite(path, ordered);
  } catch (const cv::Exception& e) {
    reason = e.what();
  }
  if (!ok) throw ConfigError(path, "cannot write image: " + reason);
}

RgbaImage read_image_rgba(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw AssetNotFound(path, "image");
  cv::Mat in;
  try {
    in = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw ConfigError(path, std::string("cannot read image: ") + e.what());
  }
  if (in.empty()) throw ConfigError(path, "cannot read image: not a format OpenCV decodes");
  if (in.depth() == CV_16U) in.convertTo(in, CV_8U, 1.0 / 257.0);
  if (in.depth() != CV_8U) throw ConfigError(path, "image must hold 8- or 16-bit pixels");
  cv::Mat rgba;
  switch (in.channels()) {
    case 1:
      cv::cvtColor(in, rgba, cv::COLOR_GRAY2RGBA);
      break;
    case 3:
      cv::cvtColor(in, rgba, cv::COLOR_BGR2RGBA);
      break;
    case 4:
      cv::cvtColor(in, rgba, cv::COLOR_BGRA2RGBA);
      break;
    default:
      throw ConfigError(
          path, "image has " + std::to_string(in.channels()) + " channels: expected 1, 3 or 4");
  }
  RgbaImage out;
  out.width = rgba.cols;
  out.height = rgba.rows;
  out.pixels.resize(static_cast<std::size_t>(rgba.cols) * rgba.rows * 4);
  for (int r = 0; r < rgba.rows; ++r) {
    std::copy_n(rgba.ptr<std::uint8_t>(r), rgba.cols * 4,
                out.pixels.data() + static_cast<std::size_t>(r) * rgba.cols * 4);
  }
  return out;
}

}  // namespace ambfplus
