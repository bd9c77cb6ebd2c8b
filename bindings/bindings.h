#pragma once

#include <pybind11/pybind11.h>

namespace ambfplus::bindings {

// One registration function per area, called once from module.cpp in dependency order.
void register_errors(pybind11::module_& m);
void register_io(pybind11::module_& m);
void register_render(pybind11::module_& m);
void register_capture(pybind11::module_& m);
void register_scene(pybind11::module_& m);

}  // namespace ambfplus::bindings

namespace ambfplus {
class Camera;
}

namespace ambfplus::bindings {

/// Camera.capture(out=None): renders with the GIL released. out may be None (a new Frame), a Frame
/// (refilled in place) or a dict of preallocated arrays {"rgb": ..., "depth": ...}.
pybind11::object capture(Camera& camera, pybind11::object out);

}  // namespace ambfplus::bindings
