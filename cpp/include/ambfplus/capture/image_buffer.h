#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "ambfplus/export.h"

namespace ambfplus {

/// Row-major, tightly packed pixels of one type: either owned (allocated once, never moved, so
/// views of it stay valid) or attached to memory someone else owns.
template <typename T>
class ImageBuffer {
 public:
  ImageBuffer() = default;
  ImageBuffer(ImageBuffer&&) noexcept = default;
  ImageBuffer& operator=(ImageBuffer&&) noexcept = default;

  /// Allocates owned storage without initialising it; only valid on an empty buffer.
  void allocate(int height, int width, int channels) {
    owned_.reset(new T[static_cast<std::size_t>(height) * width * channels]);
    data_ = owned_.get();
    height_ = height;
    width_ = width;
    channels_ = channels;
  }
  /// Uses memory owned elsewhere, which must outlive every use of this buffer.
  void attach(T* data, int height, int width, int channels) {
    owned_.reset();
    data_ = data;
    height_ = height;
    width_ = width;
    channels_ = channels;
  }

  bool empty() const { return data_ == nullptr; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  int height() const { return height_; }
  int width() const { return width_; }
  int channels() const { return channels_; }
  std::size_t size() const { return static_cast<std::size_t>(height_) * width_ * channels_; }

 private:
  std::unique_ptr<T[]> owned_;
  T* data_ = nullptr;
  int height_ = 0;
  int width_ = 0;
  int channels_ = 0;
};

}  // namespace ambfplus
