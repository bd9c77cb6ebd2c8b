// Model files: bodies, joints, cameras, lights, volumes and drills, read in full before anything
// is created, then created all or nothing.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <system_error>

#include <Eigen/Geometry>

#include "adf/adf_internal.h"
#include "adf/joint_axes_adf.h"
#include "ambfplus/adf/volume_adf.h"
#include "ambfplus/errors.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/proximity_sensor.h"
#include "ambfplus/scene/six_dof.h"
#include "ambfplus/scene/soft_body.h"
#include "ambfplus/scene/world.h"
#include "util/strings.h"

namespace ambfplus::adf {
namespace {

// A file in the first folder that has it (exactly, or with another case), or AssetNotFound
// listing every place looked.
std::string find_file(const Doc& doc, const std::string& where, const std::string& file,
                      const std::vector<std::string>& folders, const char* what) {
  std::vector<std::string> tried;
  std::error_code ec;
  if (fs::path(file).is_absolute()) {
    if (fs::is_regular_file(file, ec)) return file;
    throw AssetNotFound(std::vector<std::string>{file}, doc.path + ": " + where + ": " + what);
  }
  for (const std::string& folder : folders) {
    const fs::path dir = resolve(doc.dir, folder);
    const fs::path candidate = (dir / file).lexically_normal();
    if (std::find(tried.begin(), tried.end(), candidate.string()) != tried.end()) continue;
    tried.push_back(candidate.string());
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
    // Files made on case-insensitive systems: Plane.obj for Plane.OBJ.
    const fs::path parent = candidate.parent_path();
    if (fs::is_directory(parent, ec)) {
      const std::string want = to_lower(candidate.filename().string());
      for (const auto& entry : fs::directory_iterator(parent, ec)) {
        if (entry.is_regular_file(ec) && to_lower(entry.path().filename().string()) == want) {
          return entry.path().string();
        }
      }
    }
  }
  throw AssetNotFound(tried, doc.path + ": " + where + ": " + what + " '" + file + "'");
}

// A primitive from `shape` and `geometry` (dimensions times scale). Planes come back with the
// pose of their z = 0 plane (from `normal` and `offset`).
std::pair<Shape, Eigen::Matrix4d> primitive(const Doc& doc, const std::string& where,
                                            const YAML::Node& shape_node,
                                            const YAML::Node& geometry, double scale) {
  Shape s;
  const std::string kind = text(doc, shape_node, where, "shape");
  const std::string k = to_lower(kind);
  if (k != "box" && k != "sphere" && k != "cylinder" && k != "capsule" && k != "cone" &&
      k != "plane") {
    fail(doc, shape_node, where,
         "shape '" + kind + "' is not one of BOX, SPHERE, CYLINDER, CAPSULE, CONE, PLANE");
  }
  s.kind = parse_shape_kind(k);
  s.scale = scale;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  if (!geometry || !geometry.IsMap()) {
    fail(doc, shape_node, where, "a " + kind + " needs its geometry: {...}");
  }
  auto need = [&](const char* key) {
    const YAML::Node n = geometry[key];
    if (!n) fail(doc, geometry, where, "the " + kind + "'s geometry needs '" + key + "'");
    return number(doc, n, where, std::string("geometry.") + key);
  };
  if (const YAML::Node axis = geometry["axis"]) {
    const std::string a = to_lower(text(doc, axis, where, "geometry.axis"));
    if (a != "x" && a != "y" && a != "z") fail(doc, axis, where, "'axis' must be x, y or z");
    s.axis = a[0] - 'x';
  }
  switch (s.kind) {
    case Shape::Kind::kBox:
      s.size = Eigen::Vector3d(need("x"), need("y"), need("z")) * scale;
      break;
    case Shape::Kind::kSphere:
      s.radius = need("radius") * scale;
      break;
    case Shape::Kind::kCylinder:
    case Shape::Kind::kCapsule:
    case Shape::Kind::kCone:
      s.radius = need("radius") * scale;
      s.height = need("height") * scale;
      break;
    case Shape::Kind::kPlane: {
      Eigen::Vector3d n =
          xyz(doc, geometry["normal"], where, "geometry.normal", Eigen::Vector3d::Zero());
      if (!(n.norm() > 0)) fail(doc, geometry, where, "a plane needs a non-zero 'normal'");
      n.normalize();
      pose.topLeftCorner<3, 3>() =
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), n).toRotationMatrix();
      pose.topRightCorner<3, 1>() = n * number_or(doc, geometry, "offset", where, 0.0) * scale;
      break;
    }
    default:
      break;
  }
  return {s, pose};
}

// A block's namespace: its `namespace` joined to base (AMBF's rules), or base.
std::string block_ns(const Doc& doc, const Context& ctx, const std::string& base,
                     const std::string& id, const YAML::Node& block) {
  const YAML::Node ns = block["namespace"];
  return join_ns(ctx.prefix, base, ns ? text(doc, ns, id, "namespace") : "");
}

Material material(const Doc& doc, const std::string& where, const YAML::Node& block,
                  const Context& ctx) {
  Material m;
  auto rgb = [&](const YAML::Node& n, const std::string& key, float* out) {
    const Eigen::Vector3d c(number_or(doc, n, "r", where, out[0]),
                            number_or(doc, n, "g", where, out[1]),
                            number_or(doc, n, "b", where, out[2]));
    if (!(c.array() >= 0).all() || !(c.array() <= 1).all()) {
      fail(doc, n, where, "'" + key + "' components must be in 0..1");
    }
    for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(c[i]);
  };
  if (const YAML::Node rgba = block["color rgba"]) {
    rgb(rgba, "color rgba", m.color.data());
    m.color[3] = static_cast<float>(number_or(doc, rgba, "a", where, 1.0));
  } else if (const YAML::Node parts = block["color components"]) {
    if (parts["diffuse"]) rgb(parts["diffuse"], "color components.diffuse", m.color.data());
    if (parts["specular"]) {
      float spec[3] = {m.specular, m.specular, m.specular};
      rgb(parts["specular"], "color components.specular", spec);
      // Our Phong term is white light times one factor: AMBF's specular colour, dimmed to the
      // strength CHAI's default material shows it with.
      m.specular = 0.2f * (spec[0] + spec[1] + spec[2]) / 3.0f;
    }
    if (parts["shininess"]) {
      m.shininess = static_cast<float>(number(doc, parts["shininess"], where, "shininess"));
    }
    m.color[3] = static_cast<float>(number_or(doc, parts, "transparency", where, 1.0));
    // AMBF: ambient = level x diffuse when given, else CHAI3D's grey default.
    const float level =
        parts["ambient"] ? static_cast<float>(number_or(doc, parts["ambient"], "level", where, 1.0))
                         : -1.0f;
    m.ambient = level >= 0 ? std::array<float, 3>{level * m.color[0], level * m.color[1],
                                                  level * m.color[2]}
                           : std::array<float, 3>{0.3f, 0.3f, 0.3f};
  } else if (const YAML::Node name = block["color"]) {
    const std::string c = text(doc, name, where, "color");
    const auto it = ctx.colors ? ctx.colors->find(c) : AdfColors::const_iterator();
    if (ctx.colors && it != ctx.colors->end()) {
      m.color = it->second;
    } else if (c == "random") {
      // A colour of its own, the same on every load.
      const std::size_t h = std::hash<std::string>{}(where);
      for (int i = 0; i < 3; ++i) m.color[i] = 0.25f + 0.6f * ((h >> (8 * i)) & 255) / 255.0f;
    } else {
      ctx.diag->warn(doc.path,
                     at(name) + where + ": colour '" + c + "' is not in the colour " +
                         (ctx.colors && !ctx.colors->empty() ? "file" : "table (none loaded)") +
                         "; grey is used");
    }
  }
  return m;
}

struct BodyPlan {
  std::string id;
  std::string ns;
  RigidBodySpec spec;
  std::vector<AdfPlugin> plugins;
};

BodyPlan plan_body(const Doc& doc, const std::string& model_hr, const std::string& model_lr,
                   const std::string& model_ns, const std::string& id, const YAML::Node& b,
                   Context& ctx) {
  ctx.diag->unknown_keys(doc, id, b,
                         {"name",
                          "namespace",
                          "mesh",
                          "shape",
                          "geometry",
                          "compound shape",
                          "mass",
                          "inertia",
                          "inertial offset",
                          "scale",
                          "location",
                          "high resolution path",
                          "low resolution path",
                          "collision mesh",
                          "collision mesh type",
                          "collision shape",
                          "collision geometry",
                          "collision offset",
                          "compound collision shape",
                          "collision margin",
                          "collision groups",
                          "friction",
                          "restitution",
                          "damping",
                          "color",
                          "color rgba",
                          "color components",
                          "use material",
                          "shaders",
                          "controller",
                          "controller output type",
                          "publish frequency",
                          "passive",
                          "publish children names",
                          "publish joint names",
                          "publish joint positions",
                          "visible",
                          "plugins"});
  BodyPlan plan;
  plan.id = id;
  plan.ns = block_ns(doc, ctx, model_ns, id, b);
  RigidBodySpec& s = plan.spec;
  s.name = block_name(doc, id, b);
  const double scale = number_or(doc, b, "scale", id, 1.0);
  if (!(scale > 0)) fail(doc, b["scale"], id, "'scale' must be > 0");
  s.pose = frame(doc, b["location"], id, "location");

  // Mass and inertia.
  if (const YAML::Node mass = b["mass"]) {
    s.dynamics.mass = number(doc, mass, id, "mass");
    if (!(s.dynamics.mass >= 0)) fail(doc, mass, id, "'mass' must be >= 0 (0: static)");
  } else {
    ctx.diag->warn(doc.path, at(b) + id + ": no 'mass'; 1 kg is used (AMBF's default)");
  }
  if (const YAML::Node inertia = b["inertia"]) {
    const Eigen::Vector3d i(number_or(doc, inertia, "ix", id, 0.0),
                            number_or(doc, inertia, "iy", id, 0.0),
                            number_or(doc, inertia, "iz", id, 0.0));
    if (!(i.array() >= 0).all()) fail(doc, inertia, id, "'inertia' must be >= 0");
    // All zero on a moving body means "not given" (as exporters write it).
    if (s.dynamics.mass == 0 || i.norm() > 0) s.dynamics.inertia = i;
  }
  if (b["inertial offset"]) {
    s.dynamics.inertial_offset = frame(doc, b["inertial offset"], id, "inertial offset", scale);
  }

  // Contact parameters.
  if (const YAML::Node f = b["friction"]) {
    s.dynamics.static_friction = number_or(doc, f, "static", id, s.dynamics.static_friction);
    s.dynamics.rolling_friction = number_or(doc, f, "rolling", id, s.dynamics.rolling_friction);
  }
  s.dynamics.restitution = number_or(doc, b, "restitution", id, s.dynamics.restitution);
  if (const YAML::Node d = b["damping"]) {
    s.dynamics.linear_damping = number_or(doc, d, "linear", id, s.dynamics.linear_damping);
    s.dynamics.angular_damping = number_or(doc, d, "angular", id, s.dynamics.angular_damping);
  }

  // Mesh folders: the body's own, else the model's.
  const std::string body_hr = b["high resolution path"]
                                  ? text(doc, b["high resolution path"], id, "high resolution path")
                                  : "";
  const std::string body_lr = b["low resolution path"]
                                  ? text(doc, b["low resolution path"], id, "low resolution path")
                                  : "";
  std::vector<std::string> visual_dirs, collision_dirs;
  for (const std::string& d : {body_hr, model_hr, std::string(".")}) {
    if (!d.empty()) visual_dirs.push_back(d);
  }
  for (const std::string& d : {body_lr, body_hr, model_lr, model_hr, std::string(".")}) {
    if (!d.empty()) collision_dirs.push_back(d);
  }

  // What is drawn.
  s.shape.kind = Shape::Kind::kNone;
  s.shape.scale = scale;
  std::string visual_file;
  if (const YAML::Node shape = b["shape"]) {
    s.shape = primitive(doc, id, shape, b["geometry"], scale).first;
    if (s.shape.kind == Shape::Kind::kPlane && s.dynamics.mass > 0) {
      fail(doc, shape, id, "a PLANE is infinite, so its body needs mass 0");
    }
  } else if (b["compound shape"]) {
    ctx.diag->warn(doc.path, at(b["compound shape"]) + id +
                                 ": 'compound shape' (a visual made of primitives) is not drawn "
                                 "yet; its collision shapes still apply");
  } else if (const YAML::Node mesh = b["mesh"]) {
    const std::string file = text(doc, mesh, id, "mesh");
    if (!file.empty()) {
      visual_file = find_file(doc, id, file, visual_dirs, "mesh");
      s.shape.kind = Shape::Kind::kMesh;
      s.shape.mesh = visual_file;
    }
  }

  // What collides.
  Collision& c = s.collision;
  c.margin = number_or(doc, b, "collision margin", id, c.margin);
  if (const YAML::Node groups = b["collision groups"]) {
    if (!groups.IsSequence()) fail(doc, groups, id, "'collision groups' must be a list");
    for (const YAML::Node& g : groups) {
      const int n = integer(doc, g, id, "collision groups");
      if (n < 0 || n > 31) {
        ctx.diag->warn(doc.path, at(g) + id + ": collision group " + std::to_string(n) +
                                     " ignored (ambfplus has groups 0 to 31)");
        continue;
      }
      c.groups |= 1u << n;
    }
  }
  const YAML::Node offset_node =
      b["collision offset"] ? b["collision offset"] : b["inertial offset"];
  if (const YAML::Node shape = b["collision shape"]) {
    auto [part, plane] = primitive(doc, id, shape, b["collision geometry"], scale);
    // One shape sits at the collision offset, which defaults to the inertial offset.
    c.shapes.emplace_back(part, frame(doc, offset_node, id, "collision offset", scale) * plane);
    if (part.kind == Shape::Kind::kPlane && s.dynamics.mass > 0) {
      fail(doc, shape, id, "a PLANE collision shape is infinite, so its body needs mass 0");
    }
  } else if (const YAML::Node parts = b["compound collision shape"]) {
    if (!parts.IsSequence()) fail(doc, parts, id, "'compound collision shape' must be a list");
    for (const YAML::Node& p : parts) {
      if (!p["shape"]) fail(doc, p, id, "every compound collision part needs 'shape'");
      auto [part, plane] = primitive(doc, id, p["shape"], p["geometry"], scale);
      if (part.kind == Shape::Kind::kPlane) fail(doc, p, id, "a PLANE cannot be a compound part");
      c.shapes.emplace_back(part, frame(doc, p["offset"], id, "offset", scale));
    }
  } else if (s.shape.kind == Shape::Kind::kMesh) {
    const YAML::Node cm = b["collision mesh"] ? b["collision mesh"] : b["mesh"];
    const std::string file = text(doc, cm, id, "collision mesh");
    if (!file.empty()) {
      const std::string found = find_file(doc, id, file, collision_dirs, "collision mesh");
      if (found != visual_file) c.mesh = found;
    }
    if (const YAML::Node type = b["collision mesh type"]) {
      try {
        c.mesh_type = parse_mesh_collision(text(doc, type, id, "collision mesh type"));
      } catch (const ArgumentError& e) {
        fail(doc, type, id, e.what());
      }
    }
  } else if (b["collision mesh"] && !text(doc, b["collision mesh"], id, "collision mesh").empty()) {
    ctx.diag->warn(doc.path, at(b["collision mesh"]) + id +
                                 ": a collision mesh needs a visual mesh in ambfplus; ignored");
  }
  s.material = material(doc, id, b, ctx);
  s.material.shader = read_shader(doc, b["shaders"], id, "shaders", ctx);
  if (b["visible"]) s.material.visible = boolean(doc, b["visible"], id, "visible");
  plan.plugins = read_plugins(doc, b["plugins"], id);
  return plan;
}

struct JointPlan {
  std::string id;
  std::string ns;
  std::string parent, child;  // as written
  YAML::Node block;
  JointSpec spec;  // without its bodies
  std::vector<AdfPlugin> plugins;
  std::optional<SixDofAxes> six_dof;          // six dof (spring) per-axis settings
  std::optional<std::array<double, 3>> cone;  // cone twist limits
};

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
    if (const YAML::Node limits = j["joint limits"]) {
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
    s.damping = number_or(doc, j, "damping", id, 0.0);
    s.stiffness = number_or(doc, j, "stiffness", id, 0.0);
    s.equilibrium = number_or(doc, j, "equilibrium point", id, middle);
  }
  s.max_motor_impulse = number_or(doc, j, "max motor impulse", id, s.max_motor_impulse);
  s.erp = number_or(doc, j, "joint erp", id, s.erp);
  s.cfm = number_or(doc, j, "joint cfm", id, s.cfm);
  if (const YAML::Node c = j["controller"]) {
    s.controller.p = number_or(doc, c, "P", id, s.controller.p);
    s.controller.i = number_or(doc, c, "I", id, s.controller.i);
    s.controller.d = number_or(doc, c, "D", id, s.controller.d);
    s.controller.output = ControlOutput::kEffort;
  }
  if (const YAML::Node out = j["controller output type"]) {
    const std::string o = to_lower(text(doc, out, id, "controller output type"));
    if (o == "force" || o == "effort") {
      s.controller.output = ControlOutput::kEffort;
    } else if (o == "velocity") {
      s.controller.output = ControlOutput::kVelocity;
    } else {
      fail(doc, out, id, "'controller output type' must be FORCE, EFFORT or VELOCITY");
    }
  }
  if (j["ignore inter-collision"]) {
    s.ignore_inter_collision =
        boolean(doc, j["ignore inter-collision"], id, "ignore inter-collision");
  }
  if (j["passive"]) s.passive = boolean(doc, j["passive"], id, "passive");
  plan.plugins = read_plugins(doc, j["plugins"], id);
  return plan;
}

struct CameraPlan {
  std::string id, ns, parent;
  CameraSpec spec;
  Eigen::Vector3d eye = Eigen::Vector3d::Zero(), target = Eigen::Vector3d::Zero(),
                  up = Eigen::Vector3d::UnitZ();
  std::vector<AdfPlugin> plugins;
  double eye_separation = 0.0;  // `stereo`: a left and a right eye beside the camera
  double stereo_focal = 0.0;    // where the eyes' views converge (off-axis), m
  std::optional<ShaderSpec> preprocessing;
};

CameraPlan plan_camera(const Doc& doc, const std::string& base_ns, const std::string& id,
                       const YAML::Node& n, Context& ctx) {
  ctx.diag->unknown_keys(doc, id, n,
                         {"name",
                          "namespace",
                          "parent",
                          "location",
                          "look at",
                          "up",
                          "clipping plane",
                          "field view angle",
                          "orthographic view width",
                          "stereo",
                          "controlling devices",
                          "monitor",
                          "publish image",
                          "publish image interval",
                          "publish image resolution",
                          "publish depth",
                          "publish depth interval",
                          "publish depth resolution",
                          "publish depth noise",
                          "preprocessing shaders",
                          "depth compute shaders",
                          "multipass",
                          "visible",
                          "publish frequency",
                          "passive",
                          "plugins"});
  CameraPlan plan;
  plan.id = id;
  plan.ns = block_ns(doc, ctx, base_ns, id, n);
  plan.spec.name = block_name(doc, id, n);
  if (n["parent"]) plan.parent = text(doc, n["parent"], id, "parent");
  plan.eye = xyz(doc, n["location"], id, "location", plan.eye);
  plan.target = xyz(doc, n["look at"], id, "look at", plan.target);
  plan.up = xyz(doc, n["up"], id, "up", plan.up);
  if ((plan.target - plan.eye).norm() < 1e-12) plan.target = plan.eye - Eigen::Vector3d::UnitX();
  if (const YAML::Node clip = n["clipping plane"]) {
    plan.spec.near = number_or(doc, clip, "near", id, plan.spec.near);
    plan.spec.far = number_or(doc, clip, "far", id, plan.spec.far);
  }
  plan.spec.fov_y = number_or(doc, n, "field view angle", id, plan.spec.fov_y);
  if (const YAML::Node res = n["publish image resolution"]) {
    plan.spec.width = static_cast<int>(number_or(doc, res, "width", id, plan.spec.width));
    plan.spec.height = static_cast<int>(number_or(doc, res, "height", id, plan.spec.height));
  }
  CameraPublish& pub = plan.spec.publish;
  if (n["publish image"]) pub.image = boolean(doc, n["publish image"], id, "publish image");
  if (n["publish depth"]) pub.depth = boolean(doc, n["publish depth"], id, "publish depth");
  if (n["publish image interval"]) {
    pub.image_interval = integer(doc, n["publish image interval"], id, "publish image interval");
  }
  if (n["publish depth interval"]) {
    pub.depth_interval = integer(doc, n["publish depth interval"], id, "publish depth interval");
  }
  if (const YAML::Node noise = n["publish depth noise"]) {
    pub.depth_noise = true;
    pub.noise_mean = number_or(doc, noise, "mean", id, pub.noise_mean);
    const YAML::Node std_dev = noise["std_dev"] ? noise["std_dev"] : noise["std dev"];
    if (std_dev) pub.noise_std = number(doc, std_dev, id, "publish depth noise.std_dev");
    pub.noise_bias = number_or(doc, noise, "bias", id, pub.noise_bias);
  }
  if (pub.image_interval < 1 || pub.depth_interval < 1) {
    fail(doc, n, id, "publish intervals must be >= 1");
  }
  if (const YAML::Node stereo = n["stereo"]) {
    plan.eye_separation = number_or(doc, stereo, "eye separation", id, 0.0);
    plan.stereo_focal = number_or(doc, stereo, "focal length", id, 0.0);
    if (!(plan.eye_separation > 0)) fail(doc, stereo, id, "'stereo' needs 'eye separation' > 0");
  }
  plan.preprocessing =
      read_shader(doc, n["preprocessing shaders"], id, "preprocessing shaders", ctx);
  if (n["orthographic view width"]) {
    ctx.diag->warn(doc.path, at(n["orthographic view width"]) + id +
                                 ": 'orthographic view width' is not applied yet");
  }
  if (n["depth compute shaders"]) {
    // AMBF's unprojection of a non-linear depth buffer; ours renders metric depth directly.
    ctx.diag->warn(doc.path, at(n["depth compute shaders"]) + id +
                                 ": 'depth compute shaders' are not needed (depth is rendered "
                                 "metric) and are ignored");
  }
  plan.plugins = read_plugins(doc, n["plugins"], id);
  return plan;
}

struct LightPlan {
  std::string id, ns, parent;
  LightSpec spec;
  std::vector<AdfPlugin> plugins;
};

LightPlan plan_light(const Doc& doc, const std::string& base_ns, const std::string& id,
                     const YAML::Node& n, Context& ctx) {
  ctx.diag->unknown_keys(
      doc, id, n,
      {"name", "namespace", "parent", "location", "direction", "spot exponent", "shadow quality",
       "cutoff angle", "attenuation", "color", "publish frequency", "passive", "plugins"});
  LightPlan plan;
  plan.id = id;
  plan.ns = block_ns(doc, ctx, base_ns, id, n);
  LightSpec& s = plan.spec;
  s.name = block_name(doc, id, n);
  s.type = LightSpec::Type::kSpot;  // AMBF's lights are spot lights
  if (n["parent"]) plan.parent = text(doc, n["parent"], id, "parent");
  s.position = xyz(doc, n["location"], id, "location", s.position);
  s.direction = xyz(doc, n["direction"], id, "direction", s.direction);
  if (!(s.direction.norm() > 0)) fail(doc, n["direction"], id, "'direction' must not be zero");
  s.spot_exponent = static_cast<float>(number_or(doc, n, "spot exponent", id, s.spot_exponent));
  s.spot_cutoff = static_cast<float>(number_or(doc, n, "cutoff angle", id, s.spot_cutoff));
  if (const YAML::Node a = n["attenuation"]) {
    s.attenuation = {static_cast<float>(number_or(doc, a, "constant", id, 1.0)),
                     static_cast<float>(number_or(doc, a, "linear", id, 0.0)),
                     static_cast<float>(number_or(doc, a, "quadratic", id, 0.0))};
  }
  if (n["shadow quality"]) {
    const int q = integer(doc, n["shadow quality"], id, "shadow quality");
    if (q < 0 || q > 5) fail(doc, n["shadow quality"], id, "'shadow quality' must be 0 to 5");
  }
  plan.plugins = read_plugins(doc, n["plugins"], id);
  return plan;
}

SoftBodySpec plan_soft_body(const Doc& doc, const std::string& model_lr,
                            const std::string& model_hr, const std::string& id, const YAML::Node& b,
                            Context& ctx) {
  ctx.diag->unknown_keys(doc, id, b,
                         {"name",
                          "namespace",
                          "mesh",
                          "collision mesh",
                          "high resolution path",
                          "low resolution path",
                          "scale",
                          "location",
                          "mass",
                          "inertial offset",
                          "linear gain",
                          "angular gain",
                          "color",
                          "color rgba",
                          "color components",
                          "config",
                          "randomize constraints",
                          "collision margin",
                          "collision groups",
                          "publish frequency",
                          "passive",
                          "shaders",
                          "visible",
                          "plugins"});
  SoftBodySpec s;
  s.name = block_name(doc, id, b);
  s.scale = number_or(doc, b, "scale", id, 1.0);
  if (!(s.scale > 0)) fail(doc, b["scale"], id, "'scale' must be > 0");
  s.pose = frame(doc, b["location"], id, "location");
  s.mass = number_or(doc, b, "mass", id, s.mass);
  s.margin = number_or(doc, b, "collision margin", id, s.margin);
  // AMBF builds a soft body from its collision mesh (low resolution folders first).
  const YAML::Node mesh = b["collision mesh"] ? b["collision mesh"] : b["mesh"];
  if (!mesh) fail(doc, b, id, "a soft body needs 'mesh'");
  std::vector<std::string> dirs;
  for (const char* key : {"low resolution path", "high resolution path"}) {
    if (b[key]) dirs.push_back(text(doc, b[key], id, key));
  }
  for (const std::string& d : {model_lr, model_hr, std::string(".")}) {
    if (!d.empty()) dirs.push_back(d);
  }
  s.mesh = find_file(doc, id, text(doc, mesh, id, "mesh"), dirs, "soft body mesh");
  if (const YAML::Node config = b["config"]) {
    if (!config.IsMap()) fail(doc, config, id, "'config' must be a mapping of coefficients");
    for (const auto& entry : config) {
      const std::string key = entry.first.as<std::string>();
      if (key == "fixed nodes") {
        s.config.fixed_nodes = as<std::vector<int>>(doc, entry.second, id, "config.fixed nodes",
                                                    "a list of node indices");
        continue;
      }
      if (key == "cutting") {
        ctx.diag->warn(doc.path, at(entry.first) + id + ": soft body cutting is not applied yet");
        continue;
      }
      try {
        if (!set_soft_body_config(s.config, key, number(doc, entry.second, id, "config." + key))) {
          ctx.diag->warn(doc.path,
                         at(entry.first) + id + ": unknown config key '" + key + "' ignored");
        }
      } catch (const ArgumentError& e) {
        fail(doc, entry.second, id, e.what());
      }
    }
  }
  if (b["randomize constraints"]) {
    s.randomize_constraints = boolean(doc, b["randomize constraints"], id, "randomize constraints");
  }
  s.material = material(doc, id, b, ctx);
  s.material.shader = read_shader(doc, b["shaders"], id, "shaders", ctx);
  if (b["visible"]) s.material.visible = boolean(doc, b["visible"], id, "visible");
  return s;
}

struct SensorPlan {
  std::string id, ns, parent;
  YAML::Node block;
  bool actuator = false;
  ProximitySensorSpec sensor;
  ConstraintActuatorSpec act;
};

// A `sensors` or `actuators` block, or nothing (with a warning) for types ambfplus lacks.
std::optional<SensorPlan> plan_sensor(const Doc& doc, const std::string& model_ns, bool actuator,
                                      const std::string& id, const YAML::Node& n, Context& ctx) {
  const char* what = actuator ? "actuator" : "sensor";
  if (!n["type"]) {
    ctx.diag->warn(doc.path, at(n) + id + ": a " + what + " without 'type' is left out");
    return std::nullopt;
  }
  const std::string type = to_lower(text(doc, n["type"], id, "type"));
  if ((actuator && type != "constraint") || (!actuator && type != "proximity")) {
    ctx.diag->warn(doc.path, at(n["type"]) + id + ": " + what + " type '" +
                                 text(doc, n["type"], id, "type") +
                                 "' is not supported yet; left out");
    return std::nullopt;
  }
  if (actuator) {
    ctx.diag->unknown_keys(doc, id, n,
                           {"name", "namespace", "type", "parent", "location", "max impulse", "tau",
                            "visible", "visible size", "publish frequency", "passive"});
  } else {
    ctx.diag->unknown_keys(
        doc, id, n,
        {"name", "namespace", "type", "parent", "location", "range", "array", "parametric", "mesh",
         "direction", "visible", "visible size", "publish frequency", "passive"});
  }
  if (!n["parent"]) fail(doc, n, id, std::string("a ") + what + " needs 'parent'");
  SensorPlan p;
  p.id = id;
  p.block = n;
  p.actuator = actuator;
  p.ns = block_ns(doc, ctx, model_ns, id, n);
  p.parent = text(doc, n["parent"], id, "parent");
  const std::string name = block_name(doc, id, n);
  const Eigen::Matrix4d location = frame(doc, n["location"], id, "location");
  const bool visible = n["visible"] && boolean(doc, n["visible"], id, "visible");
  if (actuator) {
    ConstraintActuatorSpec& a = p.act;
    a.name = name;
    a.location = location;
    a.max_impulse = number_or(doc, n, "max impulse", id, a.max_impulse);
    a.tau = number_or(doc, n, "tau", id, a.tau);
    a.visible = visible;
    a.visible_size = number_or(doc, n, "visible size", id, a.visible_size);
    return p;
  }
  ProximitySensorSpec& s = p.sensor;
  s.name = name;
  s.location = location;
  s.range = number_or(doc, n, "range", id, s.range);
  s.visible = visible;
  s.visible_size = number_or(doc, n, "visible size", id, s.visible_size);
  if (const YAML::Node array = n["array"]) {
    if (!array.IsSequence()) fail(doc, array, id, "'array' must be a list of {offset, direction}");
    for (const YAML::Node& ray : array) {
      SensorRay r;
      r.offset = xyz(doc, ray["offset"], id, "array.offset", r.offset);
      r.direction = xyz(doc, ray["direction"], id, "array.direction", r.direction);
      s.rays.push_back(r);
    }
  } else if (const YAML::Node fan = n["parametric"]) {
    try {
      s.rays = parametric_sensor_rays(static_cast<int>(number_or(doc, fan, "resolution", id, 2)),
                                      number_or(doc, fan, "horizontal angle", id, 0.0),
                                      number_or(doc, fan, "vertical angle", id, 0.0),
                                      number_or(doc, fan, "start offset", id, 0.0));
    } catch (const ArgumentError& e) {
      fail(doc, fan, id, e.what());
    }
  } else if (n["mesh"]) {
    ctx.diag->warn(
        doc.path, at(n["mesh"]) + id + ": sensor rays from a mesh are not supported yet; left out");
    return std::nullopt;
  } else if (const YAML::Node direction = n["direction"]) {
    // AMBF's older form: one ray from the sensor's location along `direction`, `range` long.
    SensorRay r;
    r.offset = Eigen::Vector3d::Zero();
    r.direction = xyz(doc, direction, id, "direction", Eigen::Vector3d::Zero());
    if (!(r.direction.norm() > 1e-12)) fail(doc, direction, id, "'direction' must not be zero");
    r.direction.normalize();
    s.rays.push_back(r);
  } else {
    fail(doc, n, id,
         "a proximity sensor needs 'array' or 'parametric' rays, or one ray's 'direction'");
  }
  return p;
}

// The one object a reference names: this file's bodies first (identifier or name), then the
// world (exact, else a unique substring, also under the model's namespace), of one kind or, for
// parents, any kind but joints. nullptr when none or several match; why is in `why`.
Object* find_object(World& world, const std::string& ref, const std::string& ns,
                    const std::vector<std::pair<std::string, RigidBody*>>& own,
                    std::optional<ObjectKind> kind, std::string& why) {
  for (const auto& [id, body] : own) {
    if (id == ref || ns + id == ref) return body;
  }
  for (const auto& [id, body] : own) {
    if (body->name() == remove_spaces(ref)) return body;
  }
  std::vector<Object*> found = world.lookup(ref, kind);
  if (found.empty()) found = world.lookup(ns + ref, kind);
  if (!kind) {
    found.erase(std::remove_if(found.begin(), found.end(),
                               [](Object* o) { return o->kind() == ObjectKind::kJoint; }),
                found.end());
  }
  if (found.size() == 1) return found.front();
  const std::string what = kind ? "body" : "object";
  if (found.empty()) {
    why = "no " + what + " '" + ref + "' in the file or the world";
  } else {
    why = "'" + ref + "' matches " + std::to_string(found.size()) + " " + what + "s (" +
          found[0]->qualified_name() + ", " + found[1]->qualified_name() +
          (found.size() > 2 ? ", ..." : "") + ")";
  }
  return nullptr;
}

RigidBody* find_body(World& world, const std::string& ref, const std::string& ns,
                     const std::vector<std::pair<std::string, RigidBody*>>& own, std::string& why) {
  return static_cast<RigidBody*>(find_object(world, ref, ns, own, ObjectKind::kRigidBody, why));
}

// AMBF gives a child's location in its parent's frame; a camera's frame there is AMBF's (x back
// from the view direction, y right, z up), ours is OpenCV's (x right, y down, z forward).
Eigen::Isometry3d parent_frame(const Object& parent) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  if (parent.kind() == ObjectKind::kCamera) {
    frame.linear() << 0, 1, 0,  //
        0, 0, -1,               //
        -1, 0, 0;
  }
  return frame;
}

// Runs attempt now; if what it names is not in the world yet, keeps it to run again when a later
// file brings it (AMBF resolves parents across files, in any order). `missing` is the warning
// if that never happens.
void now_or_later(Model& model, const Doc& doc, const std::function<std::string()>& missing,
                  std::function<bool(World&)> attempt) {
  if (attempt(model.world())) return;
  model.world().defer_link({&model, doc.path, missing(), std::move(attempt)});
}

// Attaches child to the object parent names (looked up in own, then the world) at local in
// that object's frame, now or once it appears.
void attach_when_found(Model& model, const Doc& doc, Object& child, const std::string& id,
                       const std::string& parent, const std::string& ns,
                       const std::vector<std::pair<std::string, RigidBody*>>& own,
                       const Eigen::Isometry3d& local) {
  if (parent.empty()) return;
  Object* target = &child;
  auto attempt = [target, parent, ns, own, local](World& world) {
    std::string why;
    Object* found = find_object(world, parent, ns, own, std::nullopt, why);
    if (found == nullptr) return false;
    target->attach_to(found, parent_frame(*found) * local);
    return true;
  };
  now_or_later(
      model, doc,
      [&] {
        std::string why;
        find_object(model.world(), parent, ns, own, std::nullopt, why);
        return id + ": parent '" + parent + "' not found (" + why +
               "); placed in the world frame instead (attached if a later load brings it)";
      },
      attempt);
}

}  // namespace

std::string join_ns(const std::string& prefix, const std::string& base, const std::string& ns) {
  std::string out;
  if (ns.empty()) {
    out = base;
  } else if (ns.front() == '/') {
    out = prefix.empty()
              ? ns
              : (prefix.back() == '/' ? prefix.substr(0, prefix.size() - 1) : prefix) + ns;
  } else {
    out = base + ns;
  }
  if (!out.empty() && out.back() != '/') out += '/';
  return out;
}

std::string unique_name(const World& world, const std::string& name) {
  if (world.find(name) == nullptr) return name;
  for (int n = 1;; ++n) {
    const std::string candidate = name + std::to_string(n);
    if (world.find(candidate) == nullptr) return candidate;
  }
}

void add_cameras_and_lights(Model& model, const Doc& doc, const std::string& base_ns, Context& ctx,
                            const std::vector<std::pair<std::string, RigidBody*>>& own,
                            std::vector<ObjectPlugins>& plugins) {
  World& world = model.world();
  std::vector<CameraPlan> cameras;
  std::vector<LightPlan> lights;
  for (const auto& [id, block] : listed(doc, "cameras")) {
    cameras.push_back(plan_camera(doc, base_ns, id, block, ctx));
  }
  for (const auto& [id, block] : listed(doc, "lights")) {
    lights.push_back(plan_light(doc, base_ns, id, block, ctx));
  }
  // A parent that is not there yet leaves the object in the world frame until it comes.
  for (CameraPlan& c : cameras) {
    c.spec.name = unique_name(world, c.spec.name);
    Camera& camera = model.add_camera(c.spec);
    camera.set_identifier(c.id);
    camera.set_name_space(c.ns);
    camera.set_preprocessing_shader(c.preprocessing);
    camera.look_at(c.eye, c.target, c.up);
    attach_when_found(model, doc, camera, c.id, c.parent, c.ns, own, camera.pose());
    if (c.eye_separation > 0) {
      // AMBF's passive stereo: two eyes half the separation either side, converging (off-axis)
      // at the focal length when one is given.
      const double f = camera.intrinsics()(0, 0);
      const double shift = c.stereo_focal > 0 ? f * c.eye_separation / c.stereo_focal / 2 : 0.0;
      for (const int side : {-1, 1}) {
        CameraSpec eye = c.spec;
        eye.name = unique_name(world, c.spec.name + (side < 0 ? "_left" : "_right"));
        Camera& e = model.add_camera(eye);
        e.set_name_space(c.ns);
        e.set_preprocessing_shader(c.preprocessing);
        Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
        local.translation().x() = side * c.eye_separation / 2;
        e.attach_to(&camera, local);
        e.set_principal_point(eye.width / 2.0 + side * shift, eye.height / 2.0);
      }
    }
    if (!c.plugins.empty()) plugins.push_back({&camera, c.id, c.plugins});
  }
  for (LightPlan& l : lights) {
    l.spec.name = unique_name(world, l.spec.name);
    Light& light = model.add_light(l.spec);
    light.set_identifier(l.id);
    light.set_name_space(l.ns);
    attach_when_found(model, doc, light, l.id, l.parent, l.ns, own, light.pose());
    if (!l.plugins.empty()) plugins.push_back({&light, l.id, l.plugins});
  }
}

Model& load_model(World& world, const std::string& path, Context& ctx) {
  const Doc doc = load(path, "model file");
  const YAML::Node& root = doc.root;
  const std::string where = "model";
  // Top-level keys that are not blocks (mappings) and not AMBF's are reported.
  {
    static const std::set<std::string> known = {"bodies",
                                                "soft bodies",
                                                "ghost objects",
                                                "joints",
                                                "sensors",
                                                "actuators",
                                                "cameras",
                                                "lights",
                                                "volumes",
                                                "vehicles",
                                                "drills",
                                                "high resolution path",
                                                "low resolution path",
                                                "namespace",
                                                "ignore inter-collision",
                                                "joint erp",
                                                "joint cfm",
                                                "plugins",
                                                "shaders",
                                                "adf version"};
    for (const auto& entry : root) {
      const std::string key = entry.first.as<std::string>();
      if (known.count(key) == 0 && !entry.second.IsMap()) {
        ctx.diag->warn(doc.path, at(entry.first) + "unknown key '" + key + "' ignored");
      }
    }
  }
  const std::string model_ns =
      join_ns(ctx.prefix, world.name_space(),
              root["namespace"] ? text(doc, root["namespace"], where, "namespace") : "");
  const std::string hr = root["high resolution path"] ? text(doc, root["high resolution path"],
                                                             where, "high resolution path")
                                                      : "";
  const std::string lr = root["low resolution path"]
                             ? text(doc, root["low resolution path"], where, "low resolution path")
                             : "";
  const bool ignore_inter_collision =
      root["ignore inter-collision"] &&
      boolean(doc, root["ignore inter-collision"], where, "ignore inter-collision");

  // Everything is read (and every mesh found) before anything is created.
  std::vector<BodyPlan> bodies;
  for (const auto& [id, block] : listed(doc, "bodies")) {
    try {
      bodies.push_back(plan_body(doc, hr, lr, model_ns, id, block, ctx));
    } catch (const AssetNotFound& e) {
      // A world's environment goes on without a body whose mesh is missing (AMBF's scope).
      if (!ctx.skip_missing_meshes) throw;
      ctx.diag->error(doc.path, at(block) + id + ": left out: " + e.what());
    }
  }
  // Ghost objects: a body's keys (no mass) and a `parent` they ride on.
  struct GhostPlan {
    BodyPlan body;
    std::string parent;
  };
  std::vector<GhostPlan> ghosts;
  for (const auto& [id, block] : listed(doc, "ghost objects")) {
    YAML::Node keys = YAML::Clone(block);
    std::string parent;
    if (block["parent"]) parent = text(doc, block["parent"], id, "parent");
    keys.remove("parent");
    if (!keys["mass"]) keys["mass"] = 0.0;  // a ghost has none; no warning about it
    ghosts.push_back({plan_body(doc, hr, lr, model_ns, id, keys, ctx), parent});
  }
  std::vector<JointPlan> joints;
  for (const auto& [id, block] : listed(doc, "joints")) {
    joints.push_back(plan_joint(doc, model_ns, id, block, ctx));
  }
  std::vector<std::pair<std::string, SoftBodySpec>> softs;
  std::vector<std::vector<AdfPlugin>> soft_plugins;
  for (const auto& [id, block] : listed(doc, "soft bodies")) {
    softs.emplace_back(id, plan_soft_body(doc, lr, hr, id, block, ctx));
    soft_plugins.push_back(read_plugins(doc, block["plugins"], id));
  }
  std::vector<SensorPlan> sensors;
  for (const bool actuator : {false, true}) {
    for (const auto& [id, block] : listed(doc, actuator ? "actuators" : "sensors")) {
      if (auto p = plan_sensor(doc, model_ns, actuator, id, block, ctx)) sensors.push_back(*p);
    }
  }
  if (!listed(doc, "vehicles").empty()) {
    ctx.diag->warn(doc.path, at(root["vehicles"]) + "'vehicles' are not loaded yet");
  }
  const std::optional<ShaderSpec> model_shader =
      read_shader(doc, root["shaders"], where, "shaders", ctx);
  const std::vector<AdfPlugin> model_plugins = read_plugins(doc, root["plugins"], where);
  const bool has_volumes = static_cast<bool>(root["volumes"]);
  std::vector<AdfVolumeBlock> volumes;
  std::vector<AdfDrillBlock> drills;
  if (has_volumes) volumes = read_adf_volumes(path);
  if (root["drills"]) drills = read_adf_drills(path);

  std::string model_name = unique_model_name(world, fs::path(path).stem().string());
  Model& model = world.add_model(model_name);
  model.set_shader(model_shader);
  std::string current = "model";
  try {
    std::vector<std::pair<std::string, RigidBody*>> own;
    std::vector<ObjectPlugins> object_plugins;
    for (BodyPlan& b : bodies) {
      current = b.id;
      b.spec.name = unique_name(world, b.spec.name);
      RigidBody& body = model.add_body(b.spec);
      body.set_identifier(b.id);
      body.set_name_space(b.ns);
      own.emplace_back(b.id, &body);
      if (!b.plugins.empty()) object_plugins.push_back({&body, b.id, b.plugins});
    }
    // The model-wide flag: its bodies pass through one another (joints have their own).
    if (ignore_inter_collision) {
      for (std::size_t i = 0; i < own.size(); ++i) {
        for (std::size_t k = i + 1; k < own.size(); ++k) {
          own[i].second->ignore_collisions_with(*own[k].second);
        }
      }
    }
    for (std::size_t i = 0; i < softs.size(); ++i) {
      auto& [id, spec] = softs[i];
      current = id;
      spec.name = unique_name(world, spec.name);
      SoftBody& soft = model.add_soft_body(spec);
      soft.set_identifier(id);
      soft.set_name_space(model_ns);
      if (!soft_plugins[i].empty()) object_plugins.push_back({&soft, id, soft_plugins[i]});
    }
    // Joints, sensors and actuators whose bodies are not in the world yet are made when a
    // later file brings them.
    Model* target = &model;
    for (JointPlan& j : joints) {
      current = j.id;
      const bool now = [&] {
        std::string why;
        return find_body(world, j.parent, model_ns, own, why) != nullptr &&
               find_body(world, j.child, model_ns, own, why) != nullptr;
      }();
      if (!now && !j.plugins.empty()) {
        ctx.diag->warn(doc.path, at(j.block) + j.id +
                                     ": its plugins are not loaded: its bodies come in a later "
                                     "file");
      }
      // Plugins only for a joint made now (a later one's file has finished loading).
      std::vector<ObjectPlugins>* sink = now ? &object_plugins : nullptr;
      auto make = [target, plan = j, model_ns, own, sink](World& w) {
        std::string why;
        RigidBody* parent = find_body(w, plan.parent, model_ns, own, why);
        RigidBody* child = find_body(w, plan.child, model_ns, own, why);
        if (parent == nullptr || child == nullptr) return false;
        JointSpec spec = plan.spec;
        spec.parent = parent;
        spec.child = child;
        spec.parent_pivot *= parent->shape().scale;
        spec.child_pivot *= child->shape().scale;
        spec.name = unique_name(w, spec.name);
        Joint& joint = target->add_joint(spec);
        joint.set_identifier(plan.id);
        joint.set_name_space(plan.ns);
        if (plan.six_dof) set_six_dof_axes(joint, *plan.six_dof);
        if (plan.cone)
          set_cone_twist_limits(joint, (*plan.cone)[0], (*plan.cone)[1], (*plan.cone)[2]);
        if (sink != nullptr && !plan.plugins.empty()) {
          sink->push_back({&joint, plan.id, plan.plugins});
        }
        return true;
      };
      now_or_later(
          model, doc,
          [&] {
            std::string why_parent, why_child;
            const bool has_parent =
                find_body(world, j.parent, model_ns, own, why_parent) != nullptr;
            find_body(world, j.child, model_ns, own, why_child);
            return at(j.block) + j.id +
                   ": joint left out: " + (has_parent ? why_child : why_parent) +
                   " (made if a later load brings it)";
          },
          make);
    }
    for (SensorPlan& p : sensors) {
      current = p.id;
      auto make = [target, plan = p, model_ns, own](World& w) {
        std::string why;
        RigidBody* parent = find_body(w, plan.parent, model_ns, own, why);
        if (parent == nullptr) return false;
        Object* made = nullptr;
        if (plan.actuator) {
          ConstraintActuatorSpec spec = plan.act;
          spec.parent = parent;
          spec.name = unique_name(w, spec.name);
          made = &target->add_actuator(spec);
        } else {
          ProximitySensorSpec spec = plan.sensor;
          spec.parent = parent;
          spec.name = unique_name(w, spec.name);
          made = &target->add_sensor(spec);
        }
        made->set_identifier(plan.id);
        made->set_name_space(plan.ns);
        return true;
      };
      now_or_later(
          model, doc,
          [&] {
            std::string why;
            find_body(world, p.parent, model_ns, own, why);
            return at(p.block) + p.id + ": left out: " + why + " (made if a later load brings it)";
          },
          make);
    }
    for (GhostPlan& g : ghosts) {
      current = g.body.id;
      g.body.spec.name = unique_name(world, g.body.spec.name);
      RigidBody& ghost = add_ghost(model, g.body.spec);
      ghost.set_identifier(g.body.id);
      ghost.set_name_space(g.body.ns);
      if (!g.body.plugins.empty()) object_plugins.push_back({&ghost, g.body.id, g.body.plugins});
      attach_when_found(model, doc, ghost, g.body.id, g.parent, g.body.ns, own,
                        Eigen::Isometry3d(g.body.spec.pose));
    }
    current = "cameras and lights";
    add_cameras_and_lights(model, doc, model_ns, ctx, own, object_plugins);
    current = "volumes";
    if (has_volumes || !drills.empty()) add_adf_volumes(model, path, "", volumes, drills);
    // Plugins once the model is built: its objects' in creation order, then its own.
    load_plugins(object_plugins, doc.path, ctx);
    load_plugins(model_plugins, PluginSite::of(model), doc.path, where, ctx);
  } catch (const AssetNotFound&) {
    world.remove_model(model);
    throw;
  } catch (const ConfigError&) {
    world.remove_model(model);
    throw;
  } catch (const PluginError&) {
    world.remove_model(model);
    throw;
  } catch (const std::exception& e) {
    world.remove_model(model);
    throw ConfigError(doc.path, current + ": " + e.what());
  }
  return model;
}

std::string unique_model_name(const World& world, const std::string& base) {
  auto taken = [&](const std::string& name) {
    for (Model* m : world.models()) {
      if (m->name() == name) return true;
    }
    return false;
  };
  if (!taken(base)) return base;
  for (int n = 1;; ++n) {
    if (!taken(base + std::to_string(n))) return base + std::to_string(n);
  }
}

}  // namespace ambfplus::adf
