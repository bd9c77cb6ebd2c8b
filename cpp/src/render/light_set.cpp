#include "render/light_set.h"

#include <cmath>

#include "ambfplus/scene/world.h"

namespace ambfplus::render {

namespace {
void push3(std::vector<float>& v, const Eigen::Vector3f& x) {
  v.insert(v.end(), {x.x(), x.y(), x.z()});
}
}  // namespace

LightSet::LightSet(const World& world, const Eigen::Isometry3d& camera_from_world) {
  for (const Light* light : world.objects_of_kind<Light>()) {
    const Eigen::Vector3f p = (camera_from_world * light->pose().translation()).cast<float>();
    const Eigen::Vector3f d = (camera_from_world.linear() * light->direction()).cast<float>();
    const Eigen::Vector3f c =
        Eigen::Vector3f(light->color()[0], light->color()[1], light->color()[2]) *
        light->intensity();
    const Eigen::Vector3f k(light->attenuation()[0], light->attenuation()[1],
                            light->attenuation()[2]);
    switch (light->type()) {
      case LightSpec::Type::kDirectional:
        ++directional;
        push3(dir_direction, d);
        push3(dir_color, c);
        break;
      case LightSpec::Type::kPoint:
        ++point;
        push3(point_position, p);
        push3(point_color, c);
        push3(point_attenuation, k);
        break;
      case LightSpec::Type::kSpot:
        ++spot;
        push3(spot_position, p);
        push3(spot_direction, d);
        push3(spot_color, c);
        push3(spot_attenuation, k);
        spot_cos_cutoff.push_back(std::cos(light->spot_cutoff()));
        spot_exponent.push_back(light->spot_exponent());
        break;
    }
  }
  if (directional + point + spot == 0) {
    directional = 1;
    push3(dir_direction, Eigen::Vector3f(0, 0, 1));
    push3(dir_color, Eigen::Vector3f::Constant(0.85f));
  }
}

std::string LightSet::defines() const {
  return "#define DIRECTIONAL_LIGHTS " + std::to_string(directional) + "\n#define POINT_LIGHTS " +
         std::to_string(point) + "\n#define SPOT_LIGHTS " + std::to_string(spot) + "\n";
}

void LightSet::upload(Program& program) const {
  auto vec3s = [&](const char* name, const std::vector<float>& v) {
    if (!v.empty())
      glUniform3fv(program.uniform(name), static_cast<GLsizei>(v.size() / 3), v.data());
  };
  auto floats = [&](const char* name, const std::vector<float>& v) {
    if (!v.empty()) glUniform1fv(program.uniform(name), static_cast<GLsizei>(v.size()), v.data());
  };
  vec3s("u_directional_direction", dir_direction);
  vec3s("u_directional_color", dir_color);
  vec3s("u_point_position", point_position);
  vec3s("u_point_color", point_color);
  vec3s("u_point_attenuation", point_attenuation);
  vec3s("u_spot_position", spot_position);
  vec3s("u_spot_direction", spot_direction);
  vec3s("u_spot_color", spot_color);
  vec3s("u_spot_attenuation", spot_attenuation);
  floats("u_spot_cos_cutoff", spot_cos_cutoff);
  floats("u_spot_exponent", spot_exponent);
}

}  // namespace ambfplus::render
