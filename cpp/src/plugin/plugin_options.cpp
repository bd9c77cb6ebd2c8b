#include "plugin/plugin_options.h"

#include <cmath>
#include <functional>
#include <map>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::plugin {
namespace {

template <typename Spec>
using Setters = std::map<std::string, std::function<void(Spec&, const Option&)>>;

template <typename Map>
std::string known(const Map& setters) {
  std::string out;
  for (const auto& [key, set] : setters) out += (out.empty() ? "" : ", ") + key;
  return out;
}

template <typename Spec>
void apply(Spec& spec, const std::vector<Option>& options, const Setters<Spec>& setters,
           const std::string& what) {
  for (const Option& o : options) {
    const auto it = setters.find(o.key);
    if (it == setters.end()) {
      throw ArgumentError(what + ": unknown option '" + o.key + "': expected " + known(setters));
    }
    it->second(spec, o);
  }
}

// Checked readers of an option's value.
double number(const Option& o) {
  if (o.values.size() != 1 || !std::isfinite(o.values[0])) {
    throw ArgumentError("option '" + o.key + "' takes one finite number");
  }
  return o.values[0];
}
int integer(const Option& o) {
  const double v = number(o);
  if (v != std::floor(v)) throw ArgumentError("option '" + o.key + "' takes a whole number");
  return static_cast<int>(v);
}
std::vector<double> numbers(const Option& o, std::size_t n = 0) {
  if ((n != 0 && o.values.size() != n) || o.values.empty()) {
    throw ArgumentError("option '" + o.key + "' takes " +
                        (n != 0 ? std::to_string(n) : std::string("some")) + " numbers");
  }
  for (double v : o.values) {
    if (!std::isfinite(v)) throw ArgumentError("option '" + o.key + "' must be finite");
  }
  return o.values;
}
std::string text(const Option& o) {
  if (!o.text) throw ArgumentError("option '" + o.key + "' takes a text");
  return *o.text;
}
Eigen::Matrix4d pose(const Option& o) {
  const std::vector<double> v = numbers(o, 16);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = v[4 * r + c];
  return m;
}

}  // namespace

namespace {

RigidBodySpec body_spec(const std::string& name, const std::vector<Option>& options) {
  RigidBodySpec spec;
  spec.name = name;
  const Setters<RigidBodySpec> setters = {
      {"shape", [](auto& s, const Option& o) { s.shape.kind = parse_shape_kind(text(o)); }},
      {"size",
       [](auto& s, const Option& o) {
         const auto v = numbers(o, 3);
         s.shape.size = Eigen::Vector3d(v[0], v[1], v[2]);
       }},
      {"radius", [](auto& s, const Option& o) { s.shape.radius = number(o); }},
      {"height", [](auto& s, const Option& o) { s.shape.height = number(o); }},
      {"axis", [](auto& s, const Option& o) { s.shape.axis = integer(o); }},
      {"mesh",
       [](auto& s, const Option& o) {
         s.shape.kind = Shape::Kind::kMesh;
         s.shape.mesh = text(o);
       }},
      {"scale", [](auto& s, const Option& o) { s.shape.scale = number(o); }},
      {"mass", [](auto& s, const Option& o) { s.dynamics.mass = number(o); }},
      {"kinematic", [](auto& s, const Option& o) { s.dynamics.kinematic = number(o) != 0; }},
      {"collision", [](auto& s, const Option& o) { s.collision.enabled = number(o) != 0; }},
      {"color",
       [](auto& s, const Option& o) {
         const auto v = numbers(o, 4);
         for (int i = 0; i < 4; ++i) s.material.color[i] = static_cast<float>(v[i]);
       }},
      {"visible", [](auto& s, const Option& o) { s.material.visible = number(o) != 0; }},
      {"pose", [](auto& s, const Option& o) { s.pose = pose(o); }},
  };
  apply(spec, options, setters, "body '" + name + "'");
  return spec;
}

}  // namespace

RigidBody& add_body(Model& model, const std::string& name, const std::vector<Option>& options) {
  return model.add_body(body_spec(name, options));
}

RigidBody& add_ghost(Model& model, const std::string& name, const std::vector<Option>& options) {
  return ambfplus::add_ghost(model, body_spec(name, options));
}

Drill& add_drill(Model& model, const std::string& name, const std::vector<Option>& options) {
  DrillSpec spec;
  spec.name = name;
  World& world = model.world();
  const Setters<DrillSpec> setters = {
      {"volume",
       [&](auto& s, const Option& o) {
         Object* v = world.find(text(o));
         if (v == nullptr || v->kind() != ObjectKind::kVolume) {
           throw ArgumentError("option 'volume': no volume named '" + text(o) + "'");
         }
         s.volume = static_cast<Volume*>(v);
       }},
      {"burr_diameters", [](auto& s, const Option& o) { s.burr_diameters = numbers(o); }},
      {"burr", [](auto& s, const Option& o) { s.burr = integer(o); }},
      {"cursors", [](auto& s, const Option& o) { s.cursors = integer(o); }},
      {"spacing", [](auto& s, const Option& o) { s.spacing = number(o); }},
      {"shaft_radii", [](auto& s, const Option& o) { s.shaft_radii = numbers(o); }},
      {"stiffness", [](auto& s, const Option& o) { s.stiffness = number(o); }},
      {"damping", [](auto& s, const Option& o) { s.damping = number(o); }},
      {"max_force", [](auto& s, const Option& o) { s.max_force = number(o); }},
      {"soft_start", [](auto& s, const Option& o) { s.soft_start = number(o); }},
      {"removal",
       [](auto& s, const Option& o) {
         const std::string mode = text(o);
         if (mode != "physical" && mode != "compatible") {
           throw ArgumentError("option 'removal' is physical or compatible, not '" + mode + "'");
         }
         s.removal = mode == "compatible" ? RemovalMode::kCompatible : RemovalMode::kPhysical;
       }},
      {"cutting_rate", [](auto& s, const Option& o) { s.cutting_rate = number(o); }},
      {"voxels_per_step",
       [](auto& s, const Option& o) {
         s.voxels_per_step.clear();
         for (double v : numbers(o)) s.voxels_per_step.push_back(static_cast<int>(std::lround(v)));
       }},
      {"pose", [](auto& s, const Option& o) { s.pose = pose(o); }},
  };
  apply(spec, options, setters, "drill '" + name + "'");
  if (spec.volume == nullptr) {
    throw ArgumentError("drill '" + name + "': option 'volume' (a volume's name) is needed");
  }
  return model.add_drill(spec);
}

}  // namespace ambfplus::plugin
