#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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

}  // namespace ambfplus
