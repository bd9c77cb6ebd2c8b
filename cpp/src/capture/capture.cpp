// Captures: the pass table, capturing a camera's view, and the passes computed from others.

#include <stdexcept>
#include <string>
#include <vector>

#include "ambfplus/capture/capture.h"
#include "ambfplus/capture/frame.h"
#include "ambfplus/capture/points.h"
#include "ambfplus/errors.h"
#include "ambfplus/render/renderer.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

const std::array<PassInfo, kPassCount>& capture_passes() {
  static const std::array<PassInfo, kPassCount> kPasses = {{
      {"rgb", kPassRgb, "uint8", 3, true, "lit colour, RGB, row 0 at the top"},
      {"depth", kPassDepth, "float32", 1, true,
       "metric z along the optical axis (m), 0 where nothing was hit"},
      {"label", kPassLabel, "uint16", 1, true,
       "the volume label id seen (the volume's label table), 0 elsewhere"},
      {"instance", kPassInstance, "int32", 1, true,
       "the id of the object seen (meshes and volumes; the legend names it), 0 where nothing "
       "was hit"},
      {"voxel", kPassVoxel, "int32", 1, true,
       "linear index i + nx (j + ny k) of the volume voxel whose label the pixel shows, -1 "
       "elsewhere"},
      {"segmentation", kPassSegmentation, "uint8", 3, true,
       "flat RGB colours as AMBF's preprocessing shaders draw them"},
      {"points", kPassPoints, "float32", 3, false,
       "camera-frame points (m; x right, y down, z forward) of the pixel centres at their "
       "depth, (0, 0, 0) where nothing was hit"},
  }};
  return kPasses;
}

const char* pass_name(int index) {
  return index >= 0 && index < kPassCount ? capture_passes()[index].name : "?";
}

std::string pass_names(unsigned passes) {
  std::string out;
  for (const PassInfo& p : capture_passes()) {
    if ((passes & p.bit) == 0) continue;
    out += (out.empty() ? "" : ", ") + std::string(p.name);
  }
  return out;
}

CapturePass parse_pass(const std::string& name) {
  for (const PassInfo& p : capture_passes()) {
    if (name == p.name) return p.bit;
  }
  throw ArgumentError("unknown pass '" + name + "': expected one of " + pass_names(kAllPasses));
}

unsigned CaptureBuffers::passes() const {
  return (rgb ? kPassRgb : 0u) | (depth ? kPassDepth : 0u) | (label ? kPassLabel : 0u) |
         (instance ? kPassInstance : 0u) | (voxel ? kPassVoxel : 0u) |
         (segmentation ? kPassSegmentation : 0u) | (points ? kPassPoints : 0u);
}

Frame capture_frame(const Camera& camera, const PoseRequest& poses) {
  Frame frame;
  capture_into(camera, frame, poses);
  return frame;
}

void allocate_frame(const Camera& camera, Frame& frame, unsigned passes) {
  const int h = camera.height(), w = camera.width();
  if (passes & kPassRgb) frame.rgb.allocate(h, w, 3);
  if (passes & kPassDepth) frame.depth.allocate(h, w, 1);
  if (passes & kPassLabel) frame.label.allocate(h, w, 1);
  if (passes & kPassInstance) frame.instance.allocate(h, w, 1);
  if (passes & kPassVoxel) frame.voxel.allocate(h, w, 1);
  if (passes & kPassSegmentation) frame.segmentation.allocate(h, w, 3);
  if (passes & kPassPoints) frame.points.allocate(h, w, 3);
}

void capture_into(const Camera& camera, Frame& frame, const PoseRequest& poses) {
  const int h = camera.height(), w = camera.width();
  auto check = [&](const auto& buffer, int want_c, const char* what) {
    if (!buffer.empty() &&
        (buffer.height() != h || buffer.width() != w || buffer.channels() != want_c)) {
      throw ArgumentError("camera '" + camera.name() + "': the frame's " + what + " is " +
                          std::to_string(buffer.height()) + "x" + std::to_string(buffer.width()) +
                          "x" + std::to_string(buffer.channels()) + ", the camera makes " +
                          std::to_string(h) + "x" + std::to_string(w) + "x" +
                          std::to_string(want_c));
    }
  };
  check(frame.rgb, 3, "rgb");
  check(frame.depth, 1, "depth");
  check(frame.label, 1, "label");
  check(frame.instance, 1, "instance");
  check(frame.voxel, 1, "voxel");
  check(frame.segmentation, 3, "segmentation");
  check(frame.points, 3, "points");
  // A new frame gets the camera's passes; a used one keeps its own.
  const bool fresh = frame.rgb.empty() && frame.depth.empty() && frame.label.empty() &&
                     frame.instance.empty() && frame.voxel.empty() && frame.segmentation.empty() &&
                     frame.points.empty();
  if (fresh) allocate_frame(camera, frame, camera.passes());
  CaptureBuffers buffers;
  buffers.rgb = frame.rgb.data();
  buffers.depth = frame.depth.data();
  buffers.label = frame.label.data();
  buffers.instance = frame.instance.data();
  buffers.voxel = frame.voxel.data();
  buffers.segmentation = frame.segmentation.data();
  buffers.points = frame.points.data();
  capture_into(camera, buffers, frame, poses);
}

void capture_into(const Camera& camera, const CaptureBuffers& buffers, Frame& frame,
                  const PoseRequest& poses) {
  if ((buffers.passes() & kAllPasses) == 0) {
    throw ArgumentError("camera '" + camera.name() + "': a capture needs at least one pass");
  }
  const int h = camera.height(), w = camera.width();
  // Points follow from depth: render it into scratch memory when not asked for.
  CaptureBuffers drawn = buffers;
  std::vector<float> depth;
  if (buffers.points != nullptr && buffers.depth == nullptr) {
    depth.resize(static_cast<std::size_t>(w) * h);
    drawn.depth = depth.data();
  }
  drawn.points = nullptr;
  render::renderer_of(camera.world()).render(camera, drawn, poses, frame);
  if (buffers.points != nullptr) {
    capture::points_from_depth(drawn.depth, frame.intrinsics, w, h, buffers.points);
  }
}

}  // namespace ambfplus
