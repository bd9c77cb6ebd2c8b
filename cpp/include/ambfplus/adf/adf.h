#pragma once

// AMBF Description Format: launch, world, model and input-device files, loaded unchanged into a
// world. What the loader reads, its defaults and its outcomes for bad or dangling input are in
// cpp/README.md ("ADF").

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/export.h"

namespace ambfplus {

class Model;
class World;

/// Something a load reported: the file it concerns and what happened.
struct AMBFPLUS_API AdfProblem {
  std::string file;
  std::string message;
};

/// A plugin an ADF declares (`plugins: [{name, filename, path}]`), loaded when its file is: at
/// the launch (simulator scope), world, model or object level.
struct AMBFPLUS_API AdfPlugin {
  std::string name;
  std::string filename;
  std::string path;  ///< absolute, or "" when not given
};

/// A launch file: paths made absolute against its folder.
struct AMBFPLUS_API AdfLaunch {
  std::string file;
  std::string world;                ///< `world config`
  std::string colors;               ///< `color config`
  std::string input_devices;        ///< `input devices config`
  std::vector<std::string> models;  ///< `multibody configs`, by launch index
  std::vector<AdfPlugin> plugins;   ///< `plugins`
};

/// Reads a launch file. Throws AssetNotFound when absent, ConfigError (file, line, key) for YAML
/// errors and for a missing `world config`, `color config`, `input devices config` or
/// `multibody configs`.
AMBFPLUS_API AdfLaunch read_launch(const std::string& path);

/// An input device of an input-devices file (hardware is driven elsewhere; this is its
/// configuration as AMBF reads it).
struct AMBFPLUS_API AdfInputDevice {
  std::string identifier;     ///< its key in the file, e.g. "Geomagic Touch"
  std::string hardware_name;  ///< `hardware name`
  double haptic_gain_linear = 0.0, haptic_gain_angular = 0.0;  ///< `haptic gain`
  double deadband = 0.001;                                     ///< m
  double max_force = 0.0;                                      ///< N, 0 = not given
  double max_jerk = 0.0;
  double workspace_scaling = 1.0;
  Eigen::Matrix3d orientation_offset = Eigen::Matrix3d::Identity();
  std::map<std::string, int> buttons;  ///< `button mapping` (a1, a2, g1, next mode, prev mode)
  std::string simulated_multibody;     ///< absolute path, or ""
  std::string root_link;
  std::optional<Eigen::Matrix4d> location;
  bool enable_joint_control = true;
  std::vector<std::string> pair_cameras;
  bool visible = false;
  double visible_size = 0.005;
};

/// Reads the devices an input-devices file lists under `input devices`, in order. A device
/// without `hardware name` is left out with a warning (as AMBF does).
AMBFPLUS_API std::vector<AdfInputDevice> read_input_devices(
    const std::string& path, std::vector<AdfProblem>* warnings = nullptr);

/// Named colours of a colour file (`name: {r, g, b, a}` in 0..255), as RGBA 0..1.
using AdfColors = std::map<std::string, std::array<float, 4>>;
AMBFPLUS_API AdfColors read_colors(const std::string& path);

/// How a launch is loaded.
struct AMBFPLUS_API AdfLoadOptions {
  /// Launch indices to load (AMBF's `-l 0,2`); absent: AMBF's default (index 1) unless `extra`
  /// files are given, then none.
  std::optional<std::vector<int>> indices;
  std::vector<std::string> extra;  ///< more model files (AMBF's `-a`), after the indices
  /// Input devices to set up by index (AMBF's `-i`); their simulated multibodies are loaded.
  std::vector<int> devices;
  bool load_world = true;        ///< the world file's lights, cameras, environment, gravity
  bool strict = false;           ///< the first model that fails throws instead of being reported
  std::string namespace_prefix;  ///< AMBF's `--ns`, put before every namespace
  /// Simulator plugins to load after the launch file's (AMBF's `--plugins`): files or names
  /// as a `plugins` entry's `filename`.
  std::vector<std::string> plugins;
};

/// What a launch load did: the models it loaded (world environment first), and what it
/// reported. Models that failed are not in the world at all.
struct AMBFPLUS_API AdfReport {
  AdfLaunch launch;
  std::vector<Model*> models;
  std::vector<AdfInputDevice> input_devices;  ///< the ones asked for
  std::vector<AdfProblem> errors;             ///< models (or devices) that did not load
  std::vector<AdfProblem> warnings;
};

/// Loads a launch file into the world: the world file, then the models asked for, then the
/// simulator plugins. A model that fails is reported in errors and leaves nothing behind; with
/// options.strict it throws. A plugin that fails is reported in errors (its model stays); with
/// options.strict it throws PluginError. The launch file itself, or its world file, failing
/// always throws.
AMBFPLUS_API AdfReport load_launch(World& world, const std::string& path,
                                   const AdfLoadOptions& options = {});

/// Loads a world file (gravity, namespace, lights, cameras, environment model, enclosure), then
/// its plugins. Throws AssetNotFound, ConfigError or PluginError.
AMBFPLUS_API void load_world_file(World& world, const std::string& path,
                                  const AdfColors& colors = {},
                                  std::vector<AdfProblem>* warnings = nullptr);

/// Loads one model file as a new model (named after the file; a number is added when taken).
/// All or nothing: on an error nothing of it stays in the world. Throws AssetNotFound (listing
/// every path tried for a mesh), ConfigError (file, line, object, key) or PluginError (a
/// plugin of the model or of one of its objects).
AMBFPLUS_API Model& load_model_file(World& world, const std::string& path,
                                    const AdfColors& colors = {},
                                    std::vector<AdfProblem>* warnings = nullptr);

}  // namespace ambfplus
