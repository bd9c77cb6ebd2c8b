#pragma once

#include <string>
#include <vector>

#include "ambfplus/adf/adf.h"
#include "ambfplus/export.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/volume.h"
#include "ambfplus/volume/volume_io.h"

namespace ambfplus {

class World;

/// A `VOLUME <identifier>` block of an AMBF model file, read but not yet loaded.
struct AMBFPLUS_API AdfVolumeBlock {
  std::string identifier;  ///< the block's key, e.g. "VOLUME mastoidectomy_volume_low"
  std::string name;        ///< its `name` (spaces removed); the identifier's tail when absent
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  ///< `location` (position, r-p-y)
  SliceStackSpec images;         ///< `images` (path made absolute) and `dimensions` x `scale`
  std::string labels;            ///< ambfplus extension `labels:` (CSV/YAML), absolute, or ""
  double iso = 0.5;              ///< `iso-surface value`
  double quality = 0.5;          ///< `quality`
  double optical_density = 1.0;  ///< `optical density`
  bool custom_shaders = false;   ///< `shaders:` is set (AMBF GLSL; our ray caster is used)
  /// `parent`, as written, or "": the volume rides on that object, `location` in its frame.
  std::string parent;
  std::vector<AdfPlugin> plugins;  ///< `plugins`: the volume's object plugins (path absolute)
};

/// Reads the volumes an AMBF model file lists under `volumes:`. Throws AssetNotFound for a missing
/// file and ConfigError naming the file, line and key for YAML errors, a listed block that is
/// absent, or a block without `images`.
AMBFPLUS_API std::vector<AdfVolumeBlock> read_adf_volumes(const std::string& path);

/// A `DRILL <identifier>` block of a model file (an ambfplus extension AMBF ignores), listed under
/// `drills:`; read but not yet created. Keys, all optional but `volume`: name, volume (a VOLUME
/// block's identifier or name, in the same file or, for a model file, any file of the world),
/// location, burr diameters (metres), burr, cursors, cursor spacing,
/// shaft radii, stiffness, damping, max force, soft start, friction {static, dynamic}, removal
/// (physical | compatible), cutting rate, voxels per step.
struct AMBFPLUS_API AdfDrillBlock {
  std::string identifier;
  std::string volume;  ///< as written
  DrillSpec spec;      ///< everything but the volume
};

/// Reads the drills a model file lists under `drills:`, with the same errors as
/// read_adf_volumes; unknown keys are logged once each as warnings.
AMBFPLUS_API std::vector<AdfDrillBlock> read_adf_drills(const std::string& path);

/// Loads the volumes of an AMBF model file into a new model of the world (named after the file),
/// each from its slice stack, then the drills listed under `drills:` on them. A non-empty
/// `labels` (CSV/YAML) overrides the blocks' tables. Returns the volumes in file order.
AMBFPLUS_API std::vector<Volume*> load_adf_volumes(World& world, const std::string& path,
                                                   const std::string& labels = "");

}  // namespace ambfplus
