#pragma once

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "ambfplus/export.h"
#include "ambfplus/volume/volume_data.h"

namespace ambfplus {

/// An AMBF slice stack: images `<folder>/<prefix><index>.<format>` with the index unpadded or
/// zero-padded, tried from 0 up to `count` (inclusive; the stack may stop earlier).
///
/// Pixel (row r, column c) of slice k is voxel (i = c, j = H - 1 - r, k): rows run down the image
/// while y runs up, as AMBF reads PNGs bottom row first. RGBA slices: alpha >= alpha_threshold is
/// solid and RGB is the anatomy colour, mapped to the nearest colour of the label table; RGB
/// without alpha: any non-black colour is solid; grey slices: the grey value is the label id.
struct AMBFPLUS_API SliceStackSpec {
  std::string folder;
  std::string prefix = "plane00";
  std::string format = "png";
  int count = -1;  ///< largest index tried; -1 tries until the first missing index
  Eigen::Vector3d dimensions = Eigen::Vector3d::Ones();  ///< metres, full extents
  LabelTable labels;  ///< empty: one label per colour found, most frequent first
  int alpha_threshold = 128;
};

/// Loads a slice stack. Throws AssetNotFound (no slice at all), ConfigError naming the file for a
/// missing slice before a present one, slices of different sizes, or an unreadable image.
AMBFPLUS_API std::shared_ptr<VolumeData> load_slice_stack(const SliceStackSpec& spec);

/// Writes the labels as RGBA slices `<prefix><k>.<format>` (colours from the table, alpha 255 where
/// solid), with the row and column mapping load_slice_stack reads back.
AMBFPLUS_API void save_slice_stack(const VolumeData& volume, const std::string& folder,
                                   const std::string& prefix = "plane00",
                                   const std::string& format = "png");

/// How to read an NRRD file.
struct AMBFPLUS_API NrrdOptions {
  enum class Kind { kAuto, kLabels, kIntensity, kSegmentation };
  Kind kind = Kind::kAuto;
  /// For intensity data: voxels with intensity >= threshold get label 1 ("Segmented").
  std::optional<double> threshold;
};

/// Loads an NRRD file (raw or gzip, attached or detached data; 3D, or 4D layered 3D Slicer
/// segmentations). Auto: a file with Slicer segment keys is a segmentation; integer data in
/// 0..65535 with at most 256 distinct values is a label map; anything else is intensity, which
/// needs a threshold to be segmented. Space directions and origin become the voxel size and
/// patient_from_volume(); units are taken as millimetres unless `space units` says metres.
AMBFPLUS_API std::shared_ptr<VolumeData> load_nrrd(const std::string& path,
                                                   const NrrdOptions& options = {});

/// Writes the label grid (what = "labels", with Slicer segment keys so the names and colours
/// travel) or the intensity grid (what = "intensity") as NRRD, gzip-compressed unless gzip=false.
AMBFPLUS_API void save_nrrd(const VolumeData& volume, const std::string& path,
                            const std::string& what = "labels", bool gzip = true);

/// Writes the iso-surface of the solid voxels (or of one label) as a triangle mesh (.stl binary or
/// .ply binary), in the volume frame, metres: surface nets on the smoothed occupancy, so flat
/// faces sit on voxel boundaries. Returns the number of triangles.
AMBFPLUS_API std::int64_t write_surface_mesh(VolumeData& volume, const std::string& path,
                                             std::uint16_t label = 0, double iso = 0.5);

}  // namespace ambfplus
