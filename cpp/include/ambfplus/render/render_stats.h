#pragma once

#include <cstdint>

#include "ambfplus/export.h"

namespace ambfplus {

class Volume;

/// What the last render of a world sent to the GPU for one volume's grids.
struct AMBFPLUS_API VolumeUploadStats {
  bool rendered = false;    ///< false until a camera of the world has drawn the volume
  bool full = false;        ///< the whole grid (first draw) rather than an edited box
  std::int64_t voxels = 0;  ///< label voxels uploaded
  double seconds = 0.0;     ///< wall time of the upload, derived fields included
};

/// The last upload of this volume's data by its world's renderer.
AMBFPLUS_API VolumeUploadStats last_volume_upload(const Volume& volume);

}  // namespace ambfplus
