// ambfplus/io: images.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

template <typename T>
void write(const std::string& path, py::array_t<T, py::array::c_style> a, PixelType type) {
  if (a.ndim() != 2 && a.ndim() != 3) {
    throw ArgumentError("write_image: expected an (H, W) or (H, W, C) array, got " +
                        std::to_string(a.ndim()) + " dimensions");
  }
  const int h = static_cast<int>(a.shape(0)), w = static_cast<int>(a.shape(1));
  const int c = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  const T* data = a.data();
  py::gil_scoped_release release;
  write_image(path, data, h, w, c, type);
}

}  // namespace

void declare_io(py::module_&) {}

void define_io(py::module_& m) {
  m.def(
      "write_image",
      [](const std::string& path, py::array array) {
        if (array.dtype().is(py::dtype::of<std::uint8_t>())) {
          write<std::uint8_t>(path, array, PixelType::kUInt8);
        } else if (array.dtype().is(py::dtype::of<std::uint16_t>())) {
          write<std::uint16_t>(path, array, PixelType::kUInt16);
        } else {
          throw ArgumentTypeError("write_image: expected a uint8 or uint16 array, got " +
                                  py::str(array.dtype()).cast<std::string>());
        }
      },
      py::arg("path"), py::arg("image"),
      "Writes an (H, W) grey, (H, W, 3) RGB or (H, W, 4) RGBA uint8/uint16 image; the extension "
      "picks the format (.png keeps uint16).");
}

}  // namespace ambfplus::bindings
