#include "ambfplus/adf/volume_adf.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/world.h"

namespace fs = std::filesystem;

namespace ambfplus {
namespace {

std::string remove_spaces(std::string s) {
  s.erase(std::remove(s.begin(), s.end(), ' '), s.end());
  return s;
}

// A child node's value as T, or a ConfigError naming the file, line and key.
template <typename T>
T value(const std::string& path, const YAML::Node& node, const std::string& where,
        const std::string& key) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(path, "line " + std::to_string(node.Mark().line + 1) + ": " + where + ": '" +
                                key + "' has the wrong type");
  }
}

Eigen::Vector3d xyz(const std::string& path, const YAML::Node& n, const std::string& where,
                    const std::string& key, const Eigen::Vector3d& fallback) {
  if (!n) return fallback;
  Eigen::Vector3d v = fallback;
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (n[axes[a]]) v[a] = value<double>(path, n[axes[a]], where, key + "." + axes[a]);
  }
  return v;
}

Eigen::Matrix3d rpy(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

YAML::Node load_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw AssetNotFound(path, "ADF file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw ConfigError(path, "expected a mapping of keys at the top level");
  return root;
}

// The blocks listed under root[list_key], as (identifier, block) pairs.
std::vector<std::pair<std::string, YAML::Node>> listed_blocks(const std::string& path,
                                                              const YAML::Node& root,
                                                              const std::string& list_key) {
  std::vector<std::pair<std::string, YAML::Node>> out;
  const YAML::Node list = root[list_key];
  if (!list) return out;
  if (!list.IsSequence()) {
    throw ConfigError(path, "line " + std::to_string(list.Mark().line + 1) + ": '" + list_key +
                                "' must be a list of block names");
  }
  for (const YAML::Node& entry : list) {
    const std::string id = value<std::string>(path, entry, list_key, list_key);
    const YAML::Node block = root[id];
    if (!block || !block.IsMap()) {
      throw ConfigError(path, "line " + std::to_string(entry.Mark().line + 1) + ": '" + list_key +
                                  "' lists '" + id + "' but the file has no block of that name");
    }
    out.emplace_back(id, block);
  }
  return out;
}

// A block's `name` (spaces removed), or its identifier's tail.
std::string block_name(const std::string& path, const std::string& id, const YAML::Node& block) {
  return block["name"] ? remove_spaces(value<std::string>(path, block["name"], id, "name"))
                       : remove_spaces(id.substr(id.find(' ') + 1));
}

// `location: {position, orientation}` as a pose.
Eigen::Matrix4d location_pose(const std::string& path, const std::string& id,
                              const YAML::Node& location) {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  if (!location) return pose;
  const Eigen::Vector3d p =
      xyz(path, location["position"], id, "location.position", Eigen::Vector3d::Zero());
  double r = 0, pi = 0, y = 0;
  if (const YAML::Node o = location["orientation"]) {
    if (o["r"]) r = value<double>(path, o["r"], id, "location.orientation.r");
    if (o["p"]) pi = value<double>(path, o["p"], id, "location.orientation.p");
    if (o["y"]) y = value<double>(path, o["y"], id, "location.orientation.y");
  }
  pose.topLeftCorner<3, 3>() = rpy(r, pi, y);
  pose.topRightCorner<3, 1>() = p;
  return pose;
}

}  // namespace

std::vector<AdfVolumeBlock> read_adf_volumes(const std::string& path) {
  const YAML::Node root = load_file(path);
  const fs::path dir = fs::absolute(fs::path(path).parent_path());
  std::vector<AdfVolumeBlock> out;
  for (const auto& [id, block] : listed_blocks(path, root, "volumes")) {
    AdfVolumeBlock v;
    v.identifier = id;
    v.name = block_name(path, id, block);
    v.pose = location_pose(path, id, block["location"]);
    const double scale = block["scale"] ? value<double>(path, block["scale"], id, "scale") : 1.0;
    v.images.dimensions =
        xyz(path, block["dimensions"], id, "dimensions", Eigen::Vector3d::Ones()) * scale;
    const YAML::Node images = block["images"];
    if (!images || !images["path"]) {
      throw ConfigError(path, "line " + std::to_string(block.Mark().line + 1) + ": " + id +
                                  ": needs images: {path, prefix, format, count}");
    }
    const fs::path folder = value<std::string>(path, images["path"], id, "images.path");
    v.images.folder = (folder.is_absolute() ? folder : dir / folder).lexically_normal().string();
    if (images["prefix"])
      v.images.prefix = value<std::string>(path, images["prefix"], id, "images.prefix");
    if (images["format"])
      v.images.format = value<std::string>(path, images["format"], id, "images.format");
    if (images["count"]) v.images.count = value<int>(path, images["count"], id, "images.count");
    if (block["labels"]) {
      const fs::path labels = value<std::string>(path, block["labels"], id, "labels");
      v.labels = (labels.is_absolute() ? labels : dir / labels).lexically_normal().string();
    }
    if (block["iso-surface value"])
      v.iso = value<double>(path, block["iso-surface value"], id, "iso-surface value");
    if (block["quality"]) v.quality = value<double>(path, block["quality"], id, "quality");
    if (block["optical density"]) {
      v.optical_density = value<double>(path, block["optical density"], id, "optical density");
    }
    v.custom_shaders = static_cast<bool>(block["shaders"]);
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<AdfDrillBlock> read_adf_drills(const std::string& path) {
  const YAML::Node root = load_file(path);
  std::vector<AdfDrillBlock> out;
  static const std::set<std::string> known = {
      "name",           "volume",      "location",     "burr diameters", "burr",      "cursors",
      "cursor spacing", "shaft radii", "stiffness",    "damping",        "max force", "soft start",
      "friction",       "removal",     "cutting rate", "voxels per step"};
  for (const auto& [id, block] : listed_blocks(path, root, "drills")) {
    AdfDrillBlock d;
    d.identifier = id;
    DrillSpec& s = d.spec;
    s.name = block_name(path, id, block);
    for (const auto& entry : block) {
      const std::string key = entry.first.as<std::string>();
      if (known.count(key) == 0) {
        log(LogLevel::kWarning, path + ": line " + std::to_string(entry.first.Mark().line + 1) +
                                    ": " + id + ": unknown key '" + key + "' ignored");
      }
    }
    if (!block["volume"]) {
      throw ConfigError(path, "line " + std::to_string(block.Mark().line + 1) + ": " + id +
                                  ": needs 'volume' (the VOLUME block it drills)");
    }
    d.volume = value<std::string>(path, block["volume"], id, "volume");
    s.pose = location_pose(path, id, block["location"]);
    auto number = [&](const char* key, double& into) {
      if (block[key]) into = value<double>(path, block[key], id, key);
    };
    auto integer = [&](const char* key, int& into) {
      if (block[key]) into = value<int>(path, block[key], id, key);
    };
    if (block["burr diameters"]) {
      s.burr_diameters =
          value<std::vector<double>>(path, block["burr diameters"], id, "burr diameters");
    }
    integer("burr", s.burr);
    integer("cursors", s.cursors);
    number("cursor spacing", s.spacing);
    if (block["shaft radii"]) {
      s.shaft_radii = value<std::vector<double>>(path, block["shaft radii"], id, "shaft radii");
    }
    number("stiffness", s.stiffness);
    number("damping", s.damping);
    number("max force", s.max_force);
    number("soft start", s.soft_start);
    if (const YAML::Node f = block["friction"]) {
      if (f["static"]) {
        s.friction.static_coefficient = value<double>(path, f["static"], id, "friction.static");
      }
      if (f["dynamic"]) {
        s.friction.dynamic_coefficient = value<double>(path, f["dynamic"], id, "friction.dynamic");
      }
    }
    if (block["removal"]) {
      const std::string mode = value<std::string>(path, block["removal"], id, "removal");
      if (mode != "physical" && mode != "compatible") {
        throw ConfigError(path, "line " + std::to_string(block["removal"].Mark().line + 1) + ": " +
                                    id + ": 'removal' must be physical or compatible, got '" +
                                    mode + "'");
      }
      s.removal = mode == "physical" ? RemovalMode::kPhysical : RemovalMode::kCompatible;
    }
    number("cutting rate", s.cutting_rate);
    if (block["voxels per step"]) {
      s.voxels_per_step =
          value<std::vector<int>>(path, block["voxels per step"], id, "voxels per step");
    } else if (block["burr diameters"]) {
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

std::vector<Volume*> load_adf_volumes(World& world, const std::string& path,
                                      const std::string& labels) {
  const std::vector<AdfVolumeBlock> blocks = read_adf_volumes(path);
  // Drills are checked before any slices load, so a bad block costs no time.
  std::vector<AdfDrillBlock> drills = read_adf_drills(path);
  std::vector<std::size_t> drilled;  // the volume each drill is on
  for (const AdfDrillBlock& d : drills) {
    std::size_t i = 0;
    while (i < blocks.size() && d.volume != blocks[i].identifier &&
           remove_spaces(d.volume) != blocks[i].name) {
      ++i;
    }
    if (i == blocks.size()) {
      throw ConfigError(path, d.identifier + ": 'volume' names '" + d.volume +
                                  "', which is not one of the file's volumes");
    }
    drilled.push_back(i);
  }
  std::string model_name = fs::path(path).stem().string();
  for (int n = 1; [&] {
         for (Model* m : world.models()) {
           if (m->name() == model_name) return true;
         }
         return false;
       }();
       ++n) {
    model_name = fs::path(path).stem().string() + std::to_string(n);
  }
  Model& model = world.add_model(model_name);
  std::vector<Volume*> out;
  for (const AdfVolumeBlock& b : blocks) {
    SliceStackSpec images = b.images;
    const std::string table = labels.empty() ? b.labels : labels;
    if (!table.empty()) images.labels = read_label_table(table);
    VolumeSpec spec;
    spec.name = b.name;
    spec.data = load_slice_stack(images);
    spec.pose = b.pose;
    spec.iso = b.iso;
    spec.quality = b.quality;
    spec.optical_density = b.optical_density;
    if (b.custom_shaders) {
      log(LogLevel::kInfo, path + ": " + b.identifier +
                               " declares AMBF volume shaders; ambfplus ray casts volumes itself");
    }
    try {
      out.push_back(&model.add_volume(spec));
    } catch (const std::invalid_argument& e) {
      throw ConfigError(path, b.identifier + ": " + e.what());
    }
  }
  for (std::size_t k = 0; k < drills.size(); ++k) {
    AdfDrillBlock& d = drills[k];
    d.spec.volume = out[drilled[k]];
    try {
      model.add_drill(d.spec);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(path, d.identifier + ": " + e.what());
    }
  }
  return out;
}

}  // namespace ambfplus
