#pragma once

// Reading ADF (YAML) files: typed values whose errors name the file, line and key, AMBF's
// vectors and poses, identifier indirection, paths, and warnings that are both logged and kept.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/adf/adf.h"
#include "ambfplus/errors.h"
#include "ambfplus/scene/object.h"
#include "ambfplus/scene/options.h"

namespace ambfplus::adf {

namespace fs = std::filesystem;

class Diagnostics;

/// Bounds on what a block may ask, beyond which Bullet's solver and the renderer's precision are
/// gone (AMBF takes them and the scene turns to NaN): a body's mass (kg), each principal moment of
/// inertia (kg m^2) and a mesh or primitive's scale.
constexpr double kMaxMass = 1e9;
constexpr double kMaxInertia = 1e15;
constexpr double kMaxScale = 1e6;

/// One parsed ADF file.
struct Doc {
  std::string path;  ///< as given
  fs::path dir;      ///< its folder, absolute
  YAML::Node root;   ///< a mapping
};

/// Reads a YAML file whose top level is a mapping (`what` names it in errors: "model file").
/// Throws AssetNotFound when absent, ConfigError with the line for YAML syntax errors, a
/// non-mapping top level, or an `adf version` other than 1.0.
/// A key written twice in one mapping is read as AMBF (yaml-cpp) reads it, the first one
/// winning: a warning to diag (none when diag is null: the file is read again elsewhere) when
/// both give the same value, a ConfigError naming both lines when they differ.
Doc load(const std::string& path, const std::string& what, Diagnostics* diag = nullptr);

/// "line N: " for a node (1-based), "" for a node without a position.
std::string at(const YAML::Node& node);

/// Throws ConfigError(doc.path, "line N: <where>: <message>").
[[noreturn]] void fail(const Doc& doc, const YAML::Node& node, const std::string& where,
                       const std::string& message);

/// node as T, or ConfigError naming the file, line, object and key and the type expected.
template <typename T>
T as(const Doc& doc, const YAML::Node& node, const std::string& where, const std::string& key,
     const char* expected) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    fail(doc, node, where, "'" + key + "' must be " + expected);
  }
}

/// A finite number (ConfigError naming the key and line for text, .nan or .inf).
double number(const Doc& doc, const YAML::Node& node, const std::string& where,
              const std::string& key);
int integer(const Doc& doc, const YAML::Node& node, const std::string& where,
            const std::string& key);
bool boolean(const Doc& doc, const YAML::Node& node, const std::string& where,
             const std::string& key);
std::string text(const Doc& doc, const YAML::Node& node, const std::string& where,
                 const std::string& key);

/// parent[key] as an integer when present (its errors name parent_key.key), else fallback.
int integer_or(const Doc& doc, const YAML::Node& parent, const char* key, const std::string& where,
               const std::string& parent_key, int fallback);

/// block[key] when it is a mapping, absent or empty; ConfigError naming prefix + key (and the
/// line) when it is a scalar or a list. Every block[key] that is then indexed goes through this,
/// since yaml-cpp's operator[] on a scalar throws an error that names no file.
YAML::Node mapping(const Doc& doc, const YAML::Node& block, const char* key,
                   const std::string& where, const std::string& prefix = "");

/// parent[key] as a finite number when present, else fallback.
double number_or(const Doc& doc, const YAML::Node& parent, const char* key,
                 const std::string& where, double fallback);

/// block's `scale` (1 when absent): ConfigError unless in (0, kMaxScale].
double scale_of(const Doc& doc, const YAML::Node& block, const std::string& where);

/// A mass in kg at node: ConfigError unless in [0, kMaxMass] (0: static).
double mass_of(const Doc& doc, const YAML::Node& node, const std::string& where);

/// `{x, y, z}`, all three (AMBF reads each; ConfigError naming the one missing). An absent node
/// gives the fallback.
Eigen::Vector3d xyz(const Doc& doc, const YAML::Node& node, const std::string& where,
                    const std::string& key, const Eigen::Vector3d& fallback);

/// Fixed-axis roll, pitch, yaw (AMBF's `{r, p, y}`): R = Rz(y) Ry(p) Rx(r).
Eigen::Matrix3d rpy(double r, double p, double y);

/// `{position: {x,y,z}, orientation: {r,p,y}}` as a pose; the position is multiplied by scale.
/// Either part may be absent (zero), but one given needs all three of its keys. ConfigError
/// for a coordinate beyond kMaxPosition (1e6 m).
Eigen::Matrix4d frame(const Doc& doc, const YAML::Node& node, const std::string& where,
                      const std::string& key, double scale = 1.0);

/// The blocks the list under root[list_key] names, in order, each once (a list naming a block
/// twice makes it once; Diagnostics::repeated_entries warns of it). ConfigError for a list that
/// is not a list, or names a block the file does not have.
std::vector<std::pair<std::string, YAML::Node>> listed(const Doc& doc, const std::string& list_key);

/// A block's `name` with spaces removed (AMBF), or the identifier's last word when absent.
std::string block_name(const Doc& doc, const std::string& id, const YAML::Node& block);

std::string remove_spaces(std::string s);

/// A path from a file, made absolute against dir (absolute paths are kept).
std::string resolve(const fs::path& dir, const std::string& path);

/// A YAML value as an option value: numbers, true/false (yes/no, on/off), text, lists, mappings.
OptionValue option_value(const YAML::Node& node);

/// The first scalar in node (itself, or inside its lists and mappings) that reads as a
/// non-finite number (nan, .nan, inf, .inf), if any.
std::optional<YAML::Node> non_finite(const YAML::Node& node);

/// Sets spec's fields from those of `keys` that block has, through the spec's option table (a
/// file's key is Python's keyword with spaces for underscores); a bad value fails naming the
/// file, line and block.
template <typename Spec>
void set_options(const Doc& doc, const std::string& id, const YAML::Node& block,
                 const OptionTable<Spec>& table, Spec& spec,
                 std::initializer_list<const char*> keys) {
  for (const char* key : keys) {
    const YAML::Node value = block[key];
    if (!value) continue;
    if (const std::optional<YAML::Node> bad = non_finite(value)) {
      fail(doc, *bad, id,
           std::string("'") + key + "' must hold finite numbers, got " + bad->Scalar());
    }
    try {
      table.set(spec, key, option_value(value));
    } catch (const ArgumentError& e) {
      fail(doc, value, id, e.what());
    }
  }
}

/// A yaml-cpp error that escaped the readers' checks (such as a key looked up in a single value)
/// as a ConfigError naming the file and line.
[[noreturn]] void yaml_error(const std::string& path, const YAML::Exception& e);

/// Runs read, turning a yaml-cpp error into yaml_error's ConfigError.
template <typename Read>
decltype(auto) yaml_checked(const std::string& path, Read&& read) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    yaml_error(path, e);
  }
}

/// Warnings of a load, logged as they come and kept for the report.
class Diagnostics {
 public:
  void warn(const std::string& file, const std::string& message);
  void error(const std::string& file, const std::string& message);
  /// One warning per key of block that is not in known ("unknown key 'x' ignored").
  void unknown_keys(const Doc& doc, const std::string& where, const YAML::Node& block,
                    std::initializer_list<const char*> known);
  /// One warning per top-level key of doc that is neither in known nor a block one of the lists
  /// under list_keys names ("unknown key 'x' ignored"), whatever its value.
  void unknown_top_level(const Doc& doc, const std::set<std::string>& known,
                         std::initializer_list<const char*> list_keys);
  /// One warning per block of the lists named that takes a name an earlier block of the file
  /// has (AMBF renames it with a number suffix), naming both blocks.
  void repeated_names(const Doc& doc, std::initializer_list<const char*> list_keys);
  /// One warning per entry of the lists named that names a block an earlier entry of its list
  /// names: the block is made once (AMBF's lists are looked up by name), naming both lines.
  void repeated_entries(const Doc& doc, std::initializer_list<const char*> list_keys);
  /// One warning per key of `keys` that some block of the list `list_key` has: a key AMBF
  /// reads that ambfplus does not apply, naming the blocks (up to three) that have it.
  void not_applied(const Doc& doc, const char* list_key, std::initializer_list<const char*> keys,
                   const std::string& why);
  std::vector<AdfProblem>& warnings() { return warnings_; }
  std::vector<AdfProblem>& errors() { return errors_; }

 private:
  std::vector<AdfProblem> warnings_;
  std::vector<AdfProblem> errors_;
};

}  // namespace ambfplus::adf
