// What the block readers of a model file share: finding files, primitives and materials.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <system_error>

#include <Eigen/Geometry>

#include "adf/model_blocks.h"
#include "util/strings.h"

namespace ambfplus::adf {

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
    const double value = number(doc, n, where, std::string("geometry.") + key);
    if (!(value > 0)) {
      fail(doc, n, where, std::string("'geometry.") + key + "' must be > 0, got " + n.Scalar());
    }
    return value;
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
  // AMBF's alpha and transparency are opacities in 0..1, like its colour components.
  auto opacity = [&](const YAML::Node& parent, const char* key, const std::string& name) {
    const double value = number_or(doc, parent, key, where, 1.0);
    if (!(value >= 0 && value <= 1)) {
      fail(doc, parent[key], where,
           "'" + name + "' must be in 0..1 (0: clear, 1: opaque), got " + parent[key].Scalar());
    }
    return static_cast<float>(value);
  };
  if (const YAML::Node rgba = mapping(doc, block, "color rgba", where)) {
    rgb(rgba, "color rgba", m.color.data());
    m.color[3] = opacity(rgba, "a", "color rgba.a");
  } else if (const YAML::Node parts = mapping(doc, block, "color components", where)) {
    if (const YAML::Node diffuse = mapping(doc, parts, "diffuse", where, "color components.")) {
      rgb(diffuse, "color components.diffuse", m.color.data());
    }
    if (const YAML::Node specular = mapping(doc, parts, "specular", where, "color components.")) {
      float spec[3] = {m.specular, m.specular, m.specular};
      rgb(specular, "color components.specular", spec);
      // Our Phong term is white light times one factor: AMBF's specular colour, dimmed to the
      // strength CHAI's default material shows it with.
      m.specular = 0.2f * (spec[0] + spec[1] + spec[2]) / 3.0f;
    }
    if (parts["shininess"]) {
      m.shininess = static_cast<float>(number(doc, parts["shininess"], where, "shininess"));
    }
    m.color[3] = opacity(parts, "transparency", "color components.transparency");
    // AMBF: ambient = level x diffuse when given, else CHAI3D's grey default.
    const YAML::Node ambient = mapping(doc, parts, "ambient", where, "color components.");
    const float level =
        ambient ? static_cast<float>(number_or(doc, ambient, "level", where, 1.0)) : -1.0f;
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

}  // namespace ambfplus::adf
