// The per-axis keys of multi-axis joints: six dof (spring) limits, stiffness, damping and
// equilibrium point as `{linear: ..., angular: ...}`, and cone twist limits `{x, y, z}`.

#include "adf/joint_axes_adf.h"

#include <yaml-cpp/yaml.h>

namespace ambfplus::adf {
namespace {

const char* const kAxes[3] = {"x", "y", "z"};

// `{linear: {x, y, z}, angular: {x, y, z}}` into out (absent parts keep their value); false
// (with a warning) when the node has another form, as AMBF then reads zeros.
bool read_linear_angular(const Doc& doc, const YAML::Node& node, const std::string& id,
                         const std::string& key, std::array<double, 6>& out, Context& ctx) {
  if (!node.IsMap()) {
    ctx.diag->warn(doc.path, at(node) + id + ": '" + key +
                                 "' of a six dof joint must be {linear: {x, y, z}, angular: "
                                 "{x, y, z}}; zeros are used (as AMBF does)");
    return false;
  }
  for (int part = 0; part < 2; ++part) {
    const char* name = part == 0 ? "linear" : "angular";
    const YAML::Node values = node[name];
    if (!values) continue;
    for (int a = 0; a < 3; ++a) {
      if (values[kAxes[a]]) {
        out[3 * part + a] = number(doc, values[kAxes[a]], id, key + "." + name + "." + kAxes[a]);
      }
    }
  }
  return true;
}

}  // namespace

std::optional<SixDofAxes> read_six_dof_axes(const Doc& doc, const YAML::Node& j,
                                            const std::string& id, JointType type, Context& ctx) {
  const bool spring = type == JointType::kSixDofSpring;
  const YAML::Node limits = j["joint limits"];
  bool any = static_cast<bool>(limits);
  SixDofAxes axes;
  if (limits) {
    if (!limits.IsMap()) {
      ctx.diag->warn(doc.path, at(limits) + id +
                                   ": 'joint limits' of a six dof joint must be {linear: {low: "
                                   "{x, y, z}, high: {x, y, z}}, angular: ...}; left free");
    } else {
      for (int part = 0; part < 2; ++part) {
        const char* name = part == 0 ? "linear" : "angular";
        const YAML::Node range = limits[name];
        if (!range) continue;
        for (int a = 0; a < 3; ++a) {
          const int i = 3 * part + a;
          const std::string key = std::string("joint limits.") + name;
          if (range["low"] && range["low"][kAxes[a]]) {
            axes.lower[i] = number(doc, range["low"][kAxes[a]], id, key + ".low." + kAxes[a]);
          }
          if (range["high"] && range["high"][kAxes[a]]) {
            axes.upper[i] = number(doc, range["high"][kAxes[a]], id, key + ".high." + kAxes[a]);
          }
        }
      }
    }
  }
  const struct {
    const char* key;
    std::array<double, 6>* out;
  } springs[3] = {{"stiffness", &axes.stiffness},
                  {"damping", &axes.damping},
                  {"equilibrium point", &axes.equilibrium}};
  for (const auto& s : springs) {
    const YAML::Node node = j[s.key];
    if (!node) continue;
    if (!spring) {
      ctx.diag->warn(doc.path, at(node) + id + ": '" + s.key +
                                   "' of a six dof joint is ignored (AMBF reads it for six dof "
                                   "spring joints only)");
      continue;
    }
    any = read_linear_angular(doc, node, id, s.key, *s.out, ctx) || any;
  }
  if (!any) return std::nullopt;
  return axes;
}

std::optional<std::array<double, 3>> read_cone_twist_limits(const Doc& doc, const YAML::Node& j,
                                                            const std::string& id, Context& ctx) {
  const YAML::Node limits = j["joint limits"];
  if (!limits) return std::nullopt;
  if (!limits.IsMap() || !limits["x"] || !limits["y"] || !limits["z"]) {
    ctx.diag->warn(doc.path, at(limits) + id +
                                 ": 'joint limits' of a cone twist joint must be {x, y, z}; "
                                 "left unlimited");
    return std::nullopt;
  }
  std::array<double, 3> out{};
  for (int a = 0; a < 3; ++a) {
    out[a] = number(doc, limits[kAxes[a]], id, std::string("joint limits.") + kAxes[a]);
    if (out[a] < 0) {
      fail(doc, limits[kAxes[a]], id, "cone twist 'joint limits' must be >= 0 (spans, rad)");
    }
  }
  for (const char* key : {"stiffness", "damping", "equilibrium point"}) {
    if (j[key]) {
      ctx.diag->warn(doc.path, at(j[key]) + id + ": '" + key +
                                   "' of a cone twist joint is ignored (as AMBF does)");
    }
  }
  return out;
}

}  // namespace ambfplus::adf
