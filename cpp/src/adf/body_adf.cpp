// A model file's `bodies` blocks: shape or mesh, mass, contact, collision, material.

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "adf/model_blocks.h"
#include "util/strings.h"

namespace ambfplus::adf {

BodyPlan plan_body(const Doc& doc, const std::string& model_hr, const std::string& model_lr,
                   const std::string& model_ns, const std::string& id, const YAML::Node& b,
                   Context& ctx) {
  ctx.diag->unknown_keys(doc, id, b,
                         {"name",
                          "namespace",
                          "mesh",
                          "mesh remove duplicates",
                          "shape",
                          "geometry",
                          "compound shape",
                          "mass",
                          "inertia",
                          "inertial offset",
                          "gravity",
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
  const double scale = scale_of(doc, b, id);
  s.pose = frame(doc, b["location"], id, "location");

  // Mass and inertia.
  if (const YAML::Node mass = b["mass"]) {
    s.dynamics.mass = mass_of(doc, mass, id);
  } else {
    ctx.diag->warn(doc.path, at(b) + id + ": no 'mass'; 1 kg is used (AMBF's default)");
  }
  if (const YAML::Node inertia = mapping(doc, b, "inertia", id)) {
    Eigen::Vector3d i = Eigen::Vector3d::Zero();
    const char* keys[3] = {"ix", "iy", "iz"};
    for (int a = 0; a < 3; ++a) {
      // AMBF reads all three; a missing one would be a silent 0 (an axis that never turns).
      if (!inertia[keys[a]]) {
        fail(doc, inertia, id,
             std::string("'inertia' needs ix, iy and iz; '") + keys[a] +
                 "' is missing (AMBF reads all three; leave 'inertia' out to have it computed "
                 "from the shape)");
      }
      const YAML::Node n = inertia[keys[a]];
      i[a] = number(doc, n, id, std::string("inertia.") + keys[a]);
      if (!(i[a] >= 0) || i[a] > kMaxInertia) {
        fail(doc, n, id,
             std::string("'inertia.") + keys[a] + "' must be >= 0 and at most 1e15 kg m^2, got " +
                 n.Scalar());
      }
    }
    // All zero on a moving body means "not given" (as exporters write it).
    if (s.dynamics.mass == 0 || i.norm() > 0) s.dynamics.inertia = i;
  }
  if (b["inertial offset"]) {
    s.dynamics.inertial_offset = frame(doc, b["inertial offset"], id, "inertial offset", scale);
  }
  if (b["gravity"]) {
    s.dynamics.gravity = xyz(doc, b["gravity"], id, "gravity", Eigen::Vector3d::Zero());
  }

  // Contact parameters.
  if (const YAML::Node f = mapping(doc, b, "friction", id)) {
    s.dynamics.static_friction = number_or(doc, f, "static", id, s.dynamics.static_friction);
    s.dynamics.rolling_friction = number_or(doc, f, "rolling", id, s.dynamics.rolling_friction);
  }
  s.dynamics.restitution = number_or(doc, b, "restitution", id, s.dynamics.restitution);
  if (const YAML::Node d = mapping(doc, b, "damping", id)) {
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
        // AMBF, too, ignores a group number outside its range with a warning.
        ctx.diag->warn(doc.path, at(g) + id + ": 'collision groups' entry " + std::to_string(n) +
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

}  // namespace ambfplus::adf
