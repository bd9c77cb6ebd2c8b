#pragma once

// The capture passes: one table that the engine, the bindings and Python all read.

#include <array>
#include <string>

#include "ambfplus/export.h"

namespace ambfplus {

/// The images a capture can make; a camera makes the ones asked for and only those.
enum CapturePass : unsigned {
  kPassRgb = 1u << 0,       ///< lit colour
  kPassDepth = 1u << 1,     ///< metric z
  kPassLabel = 1u << 2,     ///< volume label ids
  kPassInstance = 1u << 3,  ///< object ids
  kPassVoxel = 1u << 4,     ///< volume voxel indices
  /// Flat colours as AMBF's preprocessing shaders draw them: the camera's preprocessing shader
  /// where one is set, else the engine's equivalent (material ambient x light ambient for
  /// meshes, label colours for volumes).
  kPassSegmentation = 1u << 5,
  /// The organised point cloud in the camera frame, computed from depth and the intrinsics of
  /// the same capture (depth is rendered for it when not asked for).
  kPassPoints = 1u << 6,
};

/// Number of capture passes; pass i is the bit 1 << i.
inline constexpr int kPassCount = 7;
/// Passes 0 .. kRenderedPassCount - 1 are drawn by the GPU (pass i into attachment i); the
/// others follow from them.
inline constexpr int kRenderedPassCount = 6;
inline constexpr unsigned kRenderedPasses = (1u << kRenderedPassCount) - 1;
/// Every pass.
inline constexpr unsigned kAllPasses = (1u << kPassCount) - 1;
/// What a camera makes unless asked otherwise: colour, depth and the anatomy label.
inline constexpr unsigned kDefaultPasses = kPassRgb | kPassDepth | kPassLabel;

/// One row of the pass table.
struct PassInfo {
  const char* name;  ///< as users write it: "rgb", "depth", ...
  CapturePass bit;
  const char* dtype;        ///< NumPy's name of the element type: "uint8", "float32", ...
  int channels;             ///< 1: an (H, W) image; 3: (H, W, 3)
  bool rendered;            ///< drawn by the GPU (else computed from other passes)
  const char* description;  ///< one sentence: units, frame, what 0 means
};

/// The pass table, in bit order.
AMBFPLUS_API const std::array<PassInfo, kPassCount>& capture_passes();
/// A pass's name ("rgb" ... "points"), "?" for an index outside the table.
AMBFPLUS_API const char* pass_name(int index);
/// The bit of a pass name; throws ArgumentError naming every pass for an unknown one.
AMBFPLUS_API CapturePass parse_pass(const std::string& name);
/// The names of a set of pass bits, comma separated in table order ("rgb, depth").
AMBFPLUS_API std::string pass_names(unsigned passes);

}  // namespace ambfplus
