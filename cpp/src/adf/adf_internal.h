#pragma once

// What the ADF readers share inside the engine.

#include <string>
#include <utility>
#include <vector>

#include "adf/adf_yaml.h"
#include "ambfplus/adf/adf.h"
#include "ambfplus/adf/volume_adf.h"

namespace ambfplus {

class Model;
class RigidBody;
class World;

namespace adf {

/// What a load carries from file to file.
struct Context {
  const AdfColors* colors = nullptr;
  Diagnostics* diag = nullptr;
  std::string prefix;  ///< AMBF's --ns
};

/// A namespace as AMBF resolves it: absolute ones kept (after the prefix), relative ones
/// appended to base, none gives base; always ending in '/'.
std::string join_ns(const std::string& prefix, const std::string& base, const std::string& ns);

/// name, or name1, name2, ... : the first the world does not use (AMBF's duplicate loads).
std::string unique_name(const World& world, const std::string& name);
std::string unique_model_name(const World& world, const std::string& base);

/// The `cameras` and `lights` a file lists, added to model; parents are looked up in `own`
/// (identifier, body) and then the world.
void add_cameras_and_lights(Model& model, const Doc& doc, const std::string& base_ns, Context& ctx,
                            const std::vector<std::pair<std::string, RigidBody*>>& own);

/// A model file, all or nothing.
Model& load_model(World& world, const std::string& path, Context& ctx);

/// Volumes (each from its slice stack) and then drills on them, added to model. A non-empty
/// labels file overrides the blocks' label tables.
std::vector<Volume*> add_adf_volumes(Model& model, const std::string& path,
                                     const std::string& labels,
                                     const std::vector<AdfVolumeBlock>& volumes,
                                     std::vector<AdfDrillBlock> drills);

}  // namespace adf
}  // namespace ambfplus
