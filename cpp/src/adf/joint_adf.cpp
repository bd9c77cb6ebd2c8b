// A model file's `joints` blocks.

#include <yaml-cpp/yaml.h>

#include <string>

#include "adf/joint_axes_adf.h"
#include "adf/model_blocks.h"
#include "util/strings.h"

namespace ambfplus::adf {

namespace {

// `controller output type`: FORCE or EFFORT, VELOCITY; POSITION and values AMBF does not know
// drive efforts (AMBF's fallback for the latter), with a warning.
ControlOutput controller_output(const Doc& doc, const std::string& id, const YAML::Node& out,
                                Context& ctx) {
  const std::string value = text(doc, out, id, "controller output type");
  const std::string o = to_lower(value);
  if (o == "force" || o == "effort") return ControlOutput::kEffort;
  if (o == "velocity") return ControlOutput::kVelocity;
  const std::string why =
      o == "position" ? "ambfplus's joint controller has no position output"
                      : "AMBF knows FORCE, EFFORT, VELOCITY and POSITION, and falls back to FORCE";
  ctx.diag->warn(doc.path, at(out) + id + ": 'controller output type' " + value + ": " + why +
                               "; the controller drives efforts (FORCE) instead");
  return ControlOutput::kEffort;
}

}  // namespace

JointPlan plan_joint(const Doc& doc, const std::string& model_ns, const std::string& id,
                     const YAML::Node& j, Context& ctx) {
  ctx.diag->unknown_keys(doc, id, j,
                         {"name",
                          "namespace",
                          "parent",
                          "child",
                          "parent pivot",
                          "child pivot",
                          "parent axis",
                          "child axis",
                          "type",
                          "joint offset",
                          "child offset",
                          "offset",
                          "joint limits",
                          "damping",
                          "stiffness",
                          "equilibrium point",
                          "max motor impulse",
                          "joint erp",
                          "joint cfm",
                          "controller",
                          "controller output type",
                          "ignore inter-collision",
                          "enable feedback",
                          "enable motor",
                          "passive",
                          "publish frequency",
                          "plugins"});
  JointPlan plan;
  plan.id = id;
  plan.block = j;
  plan.ns = block_ns(doc, ctx, model_ns, id, j);
  JointSpec& s = plan.spec;
  s.name = block_name(doc, id, j);
  for (const char* key : {"parent", "child", "type"}) {
    if (!j[key]) fail(doc, j, id, std::string("a joint needs '") + key + "'");
  }
  plan.parent = text(doc, j["parent"], id, "parent");
  plan.child = text(doc, j["child"], id, "child");
  const YAML::Node type = j["type"];
  try {
    s.type = parse_joint_type(text(doc, type, id, "type"));
  } catch (const ArgumentError& e) {
    fail(doc, type, id, e.what());
  }
  s.parent_pivot = xyz(doc, j["parent pivot"], id, "parent pivot", Eigen::Vector3d::Zero());
  s.child_pivot = xyz(doc, j["child pivot"], id, "child pivot", Eigen::Vector3d::Zero());
  s.parent_axis = xyz(doc, j["parent axis"], id, "parent axis", Eigen::Vector3d::UnitZ());
  s.child_axis = xyz(doc, j["child axis"], id, "child axis", Eigen::Vector3d::UnitZ());
  for (const char* key : {"parent axis", "child axis"}) {
    const Eigen::Vector3d& a = std::string(key) == "parent axis" ? s.parent_axis : s.child_axis;
    if (!(a.norm() > 1e-12)) fail(doc, j[key], id, std::string("'") + key + "' must not be zero");
  }
  s.offset = number_or(doc, j, "joint offset", id, 0.0);
  // AMBF reads `offset` as the child's offset, before `child offset`.
  const YAML::Node child_offset = j["offset"] ? j["offset"] : j["child offset"];
  if (child_offset) s.child_offset = number(doc, child_offset, id, "offset");

  const bool multi_axis = s.type == JointType::kConeTwist || s.type == JointType::kSixDof ||
                          s.type == JointType::kSixDofSpring;
  if (s.type == JointType::kConeTwist) {
    plan.cone = read_cone_twist_limits(doc, j, id, ctx);
  } else if (multi_axis) {
    plan.six_dof = read_six_dof_axes(doc, j, id, s.type, ctx);
  } else {
    double middle = 0.0;
    if (const YAML::Node limits = mapping(doc, j, "joint limits", id)) {
      // AMBF turns limits on only when both are given.
      if (limits["low"] && limits["high"]) {
        const double low = number(doc, limits["low"], id, "joint limits.low");
        const double high = number(doc, limits["high"], id, "joint limits.high");
        middle = (low + high) / 2;
        if (low > high) {
          // AMBF hands them to Bullet, which reads such a range as no limit.
          ctx.diag->warn(doc.path, at(limits) + id +
                                       ": 'joint limits' has low > high; Bullet (and so AMBF) "
                                       "reads that as no limit: the joint moves freely");
        } else {
          s.lower = low;
          s.upper = high;
        }
      }
    }
    set_options(doc, id, j, joint_options(), s, {"damping", "stiffness"});
    s.equilibrium = number_or(doc, j, "equilibrium point", id, middle);
  }
  s.erp = number_or(doc, j, "joint erp", id, s.erp);
  s.cfm = number_or(doc, j, "joint cfm", id, s.cfm);
  // A declared controller ({P, I, D}) drives efforts unless its output type says otherwise.
  set_options(doc, id, j, joint_options(), s,
              {"max motor impulse", "controller", "ignore inter-collision", "passive"});
  if (const YAML::Node controller = j["controller"]) {
    try {
      s.controller.validate("controller");  // here, so that the error names the line
    } catch (const ArgumentError& e) {
      fail(doc, controller, id, e.what());
    }
  }
  if (const YAML::Node out = j["controller output type"]) {
    s.controller.output = controller_output(doc, id, out, ctx);
  }
  plan.plugins = read_plugins(doc, j["plugins"], id);
  return plan;
}

}  // namespace ambfplus::adf
