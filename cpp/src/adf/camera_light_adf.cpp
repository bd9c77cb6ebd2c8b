// A model file's (or a world file's) `cameras` and `lights` blocks, added with their parents.

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "adf/model_blocks.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/light.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::adf {
namespace {

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

// `clipping plane` and `field view angle`, checked here so that an error names the key and line.
void read_view(const Doc& doc, const std::string& id, const YAML::Node& n, CameraSpec& spec) {
  if (const YAML::Node clip = mapping(doc, n, "clipping plane", id)) {
    spec.near = number_or(doc, clip, "near", id, spec.near);
    spec.far = number_or(doc, clip, "far", id, spec.far);
    if (!(spec.near > 0 && spec.far > spec.near)) {
      fail(doc, clip, id,
           "'clipping plane' needs 0 < near < far, got near " + std::to_string(spec.near) +
               ", far " + std::to_string(spec.far));
    }
  }
  spec.fov_y = number_or(doc, n, "field view angle", id, spec.fov_y);
  if (!(spec.fov_y > 0 && spec.fov_y < M_PI)) {
    fail(doc, n["field view angle"], id,
         "'field view angle' must be in (0, pi) radians (a vertical field of view), got " +
             std::to_string(spec.fov_y));
  }
}

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
                          "mouse control multipliers",
                          "publish frequency",
                          "passive",
                          "plugins",
                          "shadows",
                          "antialiasing",
                          "looks"});
  CameraPlan plan;
  plan.id = id;
  plan.ns = block_ns(doc, ctx, base_ns, id, n);
  plan.spec.name = block_name(doc, id, n);
  if (n["parent"]) plan.parent = text(doc, n["parent"], id, "parent");
  plan.eye = xyz(doc, n["location"], id, "location", plan.eye);
  plan.target = xyz(doc, n["look at"], id, "look at", plan.target);
  plan.up = xyz(doc, n["up"], id, "up", plan.up);
  if ((plan.target - plan.eye).norm() < 1e-12) {
    // Without 'look at' AMBF's camera looks along -x; given, it must point somewhere.
    if (n["look at"]) fail(doc, n["look at"], id, "'look at' equals 'location': no view direction");
    plan.target = plan.eye - Eigen::Vector3d::UnitX();
  }
  read_view(doc, id, n, plan.spec);
  if (const YAML::Node res = mapping(doc, n, "publish image resolution", id)) {
    plan.spec.width =
        integer_or(doc, res, "width", id, "publish image resolution", plan.spec.width);
    plan.spec.height =
        integer_or(doc, res, "height", id, "publish image resolution", plan.spec.height);
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
  if (const YAML::Node noise = mapping(doc, n, "publish depth noise", id)) {
    pub.depth_noise = true;
    pub.noise_mean = number_or(doc, noise, "mean", id, pub.noise_mean);
    const YAML::Node std_dev = noise["std_dev"] ? noise["std_dev"] : noise["std dev"];
    if (std_dev) pub.noise_std = number(doc, std_dev, id, "publish depth noise.std_dev");
    pub.noise_bias = number_or(doc, noise, "bias", id, pub.noise_bias);
  }
  if (pub.image_interval < 1 || pub.depth_interval < 1) {
    fail(doc, n, id, "publish intervals must be >= 1");
  }
  // ambfplus's own keys: the rgb pass's shadows, supersampling and volume looks (ground truth
  // never changes).
  if (n["shadows"]) plan.spec.shadows = boolean(doc, n["shadows"], id, "shadows");
  if (n["looks"]) plan.spec.looks = boolean(doc, n["looks"], id, "looks");
  if (n["antialiasing"]) {
    plan.spec.antialiasing = integer(doc, n["antialiasing"], id, "antialiasing");
    if (plan.spec.antialiasing < 1 || plan.spec.antialiasing > kMaxAntialiasing) {
      fail(doc, n["antialiasing"], id, "'antialiasing' must be 1 (off) to 4");
    }
  }
  if (const YAML::Node stereo = mapping(doc, n, "stereo", id)) {
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
  if (const YAML::Node a = mapping(doc, n, "attenuation", id)) {
    s.attenuation = {static_cast<float>(number_or(doc, a, "constant", id, 1.0)),
                     static_cast<float>(number_or(doc, a, "linear", id, 0.0)),
                     static_cast<float>(number_or(doc, a, "quadratic", id, 0.0))};
  }
  // AMBF's scale: 0 casts no shadow (also when the key is absent), 1..5 ever larger maps.
  s.shadow_quality = 0;
  if (n["shadow quality"]) {
    s.shadow_quality = integer(doc, n["shadow quality"], id, "shadow quality");
    if (s.shadow_quality < 0 || s.shadow_quality > kMaxShadowQuality) {
      fail(doc, n["shadow quality"], id, "'shadow quality' must be 0 to 5");
    }
  }
  plan.plugins = read_plugins(doc, n["plugins"], id);
  return plan;
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

// Cameras and lights of one file riding on one another in a circle (A on B on A) are refused,
// naming the circle, before any is made: no order of attaching could place them.
void refuse_parent_cycles(const Doc& doc, const std::vector<CameraPlan>& cameras,
                          const std::vector<LightPlan>& lights) {
  struct Node {
    std::string id, name, parent;
  };
  std::vector<Node> nodes;
  for (const CameraPlan& c : cameras) nodes.push_back({c.id, c.spec.name, c.parent});
  for (const LightPlan& l : lights) nodes.push_back({l.id, l.spec.name, l.parent});
  auto parent_of = [&](const Node& n) -> const Node* {
    for (const Node& m : nodes) {
      if (!n.parent.empty() && (n.parent == m.id || n.parent == m.name)) return &m;
    }
    return nullptr;
  };
  for (const Node& start : nodes) {
    std::string chain = start.name;
    const Node* p = parent_of(start);
    for (std::size_t hops = 0; p != nullptr && hops < nodes.size(); ++hops) {
      chain += " -> " + p->name;
      if (p == &start) {
        const YAML::Node block = doc.root[start.id];
        fail(doc, block["parent"] ? block["parent"] : block, start.id,
             "'parent' makes a parent cycle " + chain + "; none of them can be placed");
      }
      p = parent_of(*p);
    }
  }
}

// Camera and light keys AMBF reads that change nothing here, one warning each per file.
void warn_not_applied(const Doc& doc, Context& ctx) {
  Diagnostics& d = *ctx.diag;
  d.not_applied(doc, "cameras", {"publish depth resolution"},
                "depth is rendered at the camera's 'publish image resolution'");
  d.not_applied(doc, "cameras", {"monitor"}, "a camera opens no window of its own here");
  d.not_applied(doc, "cameras", {"controlling devices"}, "input devices do not move cameras here");
  d.not_applied(doc, "cameras", {"mouse control multipliers"},
                "the launcher's mouse controls keep their own scales");
  d.not_applied(doc, "cameras", {"multipass"}, "cameras render every object in one pass here");
  d.not_applied(doc, "cameras", {"visible"}, "cameras are not drawn as objects here");
}

}  // namespace

void now_or_later(Model& model, const std::string& file,
                  const std::function<std::string()>& missing,
                  std::function<bool(World&)> attempt) {
  if (attempt(model.world())) return;
  model.world().defer_link({&model, file, missing(), std::move(attempt)});
}

void attach_when_found(Model& model, const std::string& file, Object& child, const std::string& id,
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
      model, file,
      [&] {
        std::string why;
        find_object(model.world(), parent, ns, own, std::nullopt, why);
        return id + ": parent '" + parent + "' not found (" + why +
               "); placed in the world frame instead (attached if a later load brings it)";
      },
      attempt);
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
  refuse_parent_cycles(doc, cameras, lights);
  warn_not_applied(doc, ctx);
  // A parent that is not there yet leaves the object in the world frame until it comes.
  for (CameraPlan& c : cameras) {
    c.spec.name = unique_name(world, c.ns, c.spec.name, doc.path, model);
    const InNameSpace in_ns(model, c.ns);
    Camera& camera = model.add_camera(c.spec);
    camera.set_identifier(c.id);
    camera.set_preprocessing_shader(c.preprocessing);
    camera.look_at(c.eye, c.target, c.up);
    attach_when_found(model, doc.path, camera, c.id, c.parent, c.ns, own, camera.pose());
    if (c.eye_separation > 0) {
      // AMBF's passive stereo: two eyes half the separation either side, converging (off-axis)
      // at the focal length when one is given.
      const double f = camera.intrinsics()(0, 0);
      const double shift = c.stereo_focal > 0 ? f * c.eye_separation / c.stereo_focal / 2 : 0.0;
      for (const int side : {-1, 1}) {
        CameraSpec eye = c.spec;
        eye.name = unique_name(world, c.ns, c.spec.name + (side < 0 ? "_left" : "_right"), doc.path,
                               model);
        Camera& e = model.add_camera(eye);
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
    l.spec.name = unique_name(world, l.ns, l.spec.name, doc.path, model);
    const InNameSpace in_ns(model, l.ns);
    Light& light = model.add_light(l.spec);
    light.set_identifier(l.id);
    attach_when_found(model, doc.path, light, l.id, l.parent, l.ns, own, light.pose());
    if (!l.plugins.empty()) plugins.push_back({&light, l.id, l.plugins});
  }
}

}  // namespace ambfplus::adf
