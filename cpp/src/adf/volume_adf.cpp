#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/errors.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>

#include "adf/model_blocks.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/world.h"

namespace fs = std::filesystem;

namespace ambfplus {

using adf::Doc;

namespace {

// A volume's size: {x, y, z} in metres, each given, finite and positive (1 m each when absent).
Eigen::Vector3d volume_dimensions(const Doc& doc, const YAML::Node& node, const std::string& id) {
  if (!node) return Eigen::Vector3d::Ones();
  if (!node.IsMap()) adf::fail(doc, node, id, "'dimensions' must be {x, y, z} in metres");
  Eigen::Vector3d v;
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const std::string key = std::string("dimensions.") + axes[a];
    if (!node[axes[a]]) adf::fail(doc, node, id, "'" + key + "' is missing");
    v[a] = adf::number(doc, node[axes[a]], id, key);
    if (!std::isfinite(v[a]) || !(v[a] > 0)) {
      adf::fail(doc, node[axes[a]], id, "'" + key + "' must be a positive finite length (m)");
    }
  }
  return v;
}

}  // namespace

std::vector<AdfVolumeBlock> read_adf_volumes(const std::string& path) {
  const Doc doc = adf::load(path, "ADF file");
  adf::Diagnostics diag;
  std::vector<AdfVolumeBlock> out;
  for (const auto& [id, block] : adf::listed(doc, "volumes")) {
    // AMBF 2.0's volume keys, and `labels` (ambfplus's).
    diag.unknown_keys(doc, id, block,
                      {"name", "namespace", "parent", "location", "scale", "dimensions", "images",
                       "labels", "iso-surface value", "quality", "optical density", "shaders",
                       "plugins", "publish frequency", "passive", "color", "color rgba",
                       "color components", "use material"});
    for (const char* key : {"color", "color rgba", "color components", "use material"}) {
      if (block[key]) {
        diag.warn(doc.path, adf::at(block[key]) + id + ": '" + key +
                                "' is not applied: a volume is coloured by its slices and labels");
      }
    }
    AdfVolumeBlock v;
    v.identifier = id;
    v.name = adf::block_name(doc, id, block);
    v.pose = adf::frame(doc, block["location"], id, "location");
    const double scale = adf::scale_of(doc, block, id);
    v.images.dimensions = volume_dimensions(doc, block["dimensions"], id) * scale;
    const YAML::Node images = block["images"];
    if (!images || !images["path"]) {
      adf::fail(doc, block, id, "needs images: {path, prefix, format, count}");
    }
    v.images.folder = adf::resolve(doc.dir, adf::text(doc, images["path"], id, "images.path"));
    if (images["prefix"]) v.images.prefix = adf::text(doc, images["prefix"], id, "images.prefix");
    if (images["format"]) v.images.format = adf::text(doc, images["format"], id, "images.format");
    if (images["count"]) {
      v.images.count = adf::integer(doc, images["count"], id, "images.count");
      if (v.images.count < 1) {
        adf::fail(doc, images["count"], id,
                  "'images.count' must be the number of slices (>= 1), got " +
                      std::to_string(v.images.count));
      }
    }
    if (block["labels"]) {
      v.labels = adf::resolve(doc.dir, adf::text(doc, block["labels"], id, "labels"));
    }
    v.iso = adf::number_or(doc, block, "iso-surface value", id, v.iso);
    v.quality = adf::number_or(doc, block, "quality", id, v.quality);
    v.optical_density = adf::number_or(doc, block, "optical density", id, v.optical_density);
    v.custom_shaders = static_cast<bool>(block["shaders"]);
    if (block["parent"]) v.parent = adf::text(doc, block["parent"], id, "parent");
    v.plugins = adf::read_plugins(doc, block["plugins"], id);
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<AdfDrillBlock> read_adf_drills(const std::string& path) {
  const Doc doc = adf::load(path, "ADF file");
  adf::Diagnostics diag;
  std::vector<AdfDrillBlock> out;
  for (const auto& [id, block] : adf::listed(doc, "drills")) {
    AdfDrillBlock d;
    d.identifier = id;
    DrillSpec& s = d.spec;
    s.name = adf::block_name(doc, id, block);
    diag.unknown_keys(
        doc, id, block,
        {"name", "volume", "location", "burr diameters", "burr", "cursors", "cursor spacing",
         "shaft radii", "stiffness", "damping", "max force", "soft start", "friction", "removal",
         "cutting rate", "voxels per step", "fixtures"});
    if (!block["volume"]) adf::fail(doc, block, id, "needs 'volume' (the VOLUME block it drills)");
    d.volume = adf::text(doc, block["volume"], id, "volume");
    s.pose = adf::frame(doc, block["location"], id, "location");
    // Every other key is add_drill's keyword with spaces for underscores.
    adf::set_options(doc, id, block, drill_options(), s,
                     {"burr diameters", "burr", "cursors", "cursor spacing", "shaft radii",
                      "stiffness", "damping", "max force", "soft start", "friction", "removal",
                      "cutting rate", "voxels per step", "fixtures"});
    if (!block["voxels per step"] && block["burr diameters"]) {
      // The original's counts go with its four burrs; other burrs take 1 per step.
      s.voxels_per_step.assign(s.burr_diameters.size(), 1);
      const std::vector<int> original{1, 3, 6, 10};
      for (std::size_t i = 0; i < s.burr_diameters.size() && i < original.size(); ++i) {
        s.voxels_per_step[i] = original[i];
      }
    }
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<Volume*> adf::add_adf_volumes(
    Model& model, const std::string& path, const std::string& labels,
    const std::vector<AdfVolumeBlock>& blocks, std::vector<AdfDrillBlock> drills,
    const std::string& ns, const std::vector<std::pair<std::string, RigidBody*>>& own) {
  // Drills are checked before any slices load, so a bad block costs no time. A drill on a
  // volume of another file waits for it (SIZE_MAX).
  std::vector<std::size_t> drilled;  // the volume each drill is on
  for (const AdfDrillBlock& d : drills) {
    std::size_t i = 0;
    while (i < blocks.size() && d.volume != blocks[i].identifier &&
           adf::remove_spaces(d.volume) != blocks[i].name) {
      ++i;
    }
    drilled.push_back(i == blocks.size() ? SIZE_MAX : i);
  }
  std::vector<Volume*> out;
  for (const AdfVolumeBlock& b : blocks) {
    SliceStackSpec images = b.images;
    const std::string table = labels.empty() ? b.labels : labels;
    if (!table.empty()) images.labels = read_label_table(table);
    VolumeSpec spec;
    spec.name = b.name;
    try {
      spec.data = load_slice_stack(images);
    } catch (const ArgumentError& e) {
      throw ConfigError(path, b.identifier + ": " + e.what());
    }
    spec.pose = b.pose;
    spec.iso = b.iso;
    spec.quality = b.quality;
    spec.optical_density = b.optical_density;
    if (b.custom_shaders) {
      log(LogLevel::kInfo, path + ": " + b.identifier +
                               " declares AMBF volume shaders; ambfplus ray casts volumes itself");
    }
    try {
      Volume& volume = model.add_volume(spec);
      volume.set_identifier(b.identifier);
      out.push_back(&volume);
    } catch (const ArgumentError& e) {
      throw ConfigError(path, b.identifier + ": " + e.what());
    }
    // `location` is in the parent's frame, which may come in a later file.
    attach_when_found(model, path, *out.back(), b.identifier, b.parent, ns, own,
                      Eigen::Isometry3d(b.pose));
  }
  for (std::size_t k = 0; k < drills.size(); ++k) {
    const AdfDrillBlock& d = drills[k];
    auto make = [target = &model, d, path,
                 volume = drilled[k] == SIZE_MAX ? nullptr : out[drilled[k]]](World& world) {
      DrillSpec spec = d.spec;
      spec.volume = volume;
      if (spec.volume == nullptr) {
        std::string why;
        spec.volume =
            static_cast<Volume*>(find_object(world, d.volume, "", {}, ObjectKind::kVolume, why));
        if (spec.volume == nullptr) return false;
      }
      try {
        add_drill(*target, spec).set_identifier(d.identifier);
      } catch (const ArgumentError& e) {
        throw ConfigError(path, d.identifier + ": " + e.what());
      } catch (const NotFound& e) {  // a fixture's structure the volume's labels lack
        throw ConfigError(path, d.identifier + ": " + e.what());
      }
      return true;
    };
    now_or_later(
        model, path,
        [&] {
          std::string why;
          find_object(model.world(), d.volume, "", {}, ObjectKind::kVolume, why);
          return d.identifier + ": drill left out: its 'volume' '" + d.volume +
                 "' is not one of the file's volumes and " + why +
                 " (made if a later load brings it)";
        },
        make);
  }
  return out;
}

std::vector<Volume*> load_adf_volumes(World& world, const std::string& path,
                                      const std::string& labels) {
  auto lock = world.lock_state();  // the thread-safety contract
  {
    // The readers below read the file again without warnings: warn (logged) once, here.
    adf::Diagnostics diag;
    diag.repeated_entries(adf::load(path, "ADF file", &diag), {"volumes", "drills"});
  }
  const std::vector<AdfVolumeBlock> blocks = read_adf_volumes(path);
  std::vector<AdfDrillBlock> drills = read_adf_drills(path);
  // Without a launch to bring it later, a drill's volume is in the file or already in the world
  // (checked before any slices load).
  for (const AdfDrillBlock& d : drills) {
    const bool in_file = std::any_of(blocks.begin(), blocks.end(), [&](const AdfVolumeBlock& b) {
      return d.volume == b.identifier || adf::remove_spaces(d.volume) == b.name;
    });
    std::string why;
    if (!in_file &&
        adf::find_object(world, d.volume, "", {}, ObjectKind::kVolume, why) == nullptr) {
      throw ConfigError(path, d.identifier + ": 'volume' names '" + d.volume +
                                  "', which is not one of the file's volumes (" + why + ")");
    }
  }
  Model& model = world.add_model(adf::unique_model_name(world, fs::path(path).stem().string()));
  try {
    return adf::add_adf_volumes(model, path, labels, blocks, std::move(drills));
  } catch (...) {
    world.remove_model(model);
    throw;
  }
}

}  // namespace ambfplus
