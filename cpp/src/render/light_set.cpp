#include "render/light_set.h"

#include <cmath>

#include "ambfplus/scene/world.h"

namespace ambfplus::render {

namespace {
void push3(std::vector<float>& v, const Eigen::Vector3f& x) {
  v.insert(v.end(), {x.x(), x.y(), x.z()});
}
}  // namespace

LightSet::LightSet(const World& world, const Eigen::Isometry3d& camera_from_world, bool shadows) {
  // The map index of a light that casts shadows, -1 for one that does not.
  auto shadow_of = [&](const Light& light) {
    const bool casts = light.type() != LightSpec::Type::kPoint && light.shadow_quality() > 0;
    if (!shadows || !casts || casters.size() >= std::size_t(kMaxShadowMaps)) return -1;
    ShadowCaster c;
    c.light_id = light.id();
    c.directional = light.type() == LightSpec::Type::kDirectional;
    c.position = light.pose().translation();
    c.direction = light.direction();
    c.cutoff = light.spot_cutoff();
    c.size = light.shadow_map_size();
    casters.push_back(c);
    return static_cast<int>(casters.size()) - 1;
  };
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
        dir_shadow.push_back(shadow_of(*light));
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
        spot_shadow.push_back(shadow_of(*light));
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
    dir_shadow.push_back(-1);
    push3(dir_direction, Eigen::Vector3f(0, 0, 1));
    push3(dir_color, Eigen::Vector3f::Constant(0.85f));
  }
}

std::string LightSet::defines() const {
  return "#define DIRECTIONAL_LIGHTS " + std::to_string(directional) + "\n#define POINT_LIGHTS " +
         std::to_string(point) + "\n#define SPOT_LIGHTS " + std::to_string(spot) + "\n" +
         (casters.empty() ? "" : "#define SHADOW_MAPS " + std::to_string(casters.size()) + "\n");
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
  if (!casters.empty()) {
    glUniform1iv(program.uniform("u_directional_shadow"), static_cast<GLsizei>(dir_shadow.size()),
                 dir_shadow.data());
    if (!spot_shadow.empty()) {
      glUniform1iv(program.uniform("u_spot_shadow"), static_cast<GLsizei>(spot_shadow.size()),
                   spot_shadow.data());
    }
  }
}

void ShadowUniforms::upload(Program& program) const {
  const auto n = static_cast<GLsizei>(textures.size());
  if (n == 0) return;
  std::vector<GLint> units(textures.size());
  for (GLsizei i = 0; i < n; ++i) {
    units[i] = kShadowMapUnit + i;
    glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + units[i]));
    glBindTexture(GL_TEXTURE_2D, textures[i]);
  }
  glActiveTexture(GL_TEXTURE0);
  glUniform1iv(program.uniform("u_shadow_maps"), n, units.data());
  glUniformMatrix4fv(program.uniform("u_shadow_from_camera"), n, GL_FALSE, from_camera.data());
  glUniform2fv(program.uniform("u_shadow_texel"), n, texel.data());
}

}  // namespace ambfplus::render
