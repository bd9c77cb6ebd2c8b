// A model file's `soft bodies` blocks.

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "adf/model_blocks.h"
#include "util/strings.h"

namespace ambfplus::adf {

SoftBodySpec plan_soft_body(const Doc& doc, const std::string& model_lr,
                            const std::string& model_hr, const std::string& id, const YAML::Node& b,
                            Context& ctx) {
  ctx.diag->unknown_keys(
      doc, id, b,
      {"name", "namespace", "mesh", "collision mesh", "high resolution path", "low resolution path",
       "scale", "location", "mass", "inertial offset", "gravity", "linear gain", "angular gain",
       "color", "color rgba", "color components", "config", "randomize constraints",
       "collision margin", "collision groups", "publish frequency", "passive", "shaders", "visible",
       "plugins",
       // A body's keys AMBF reads for soft bodies too; warned as not applied.
       "inertia", "controller", "controller output type", "mesh remove duplicates", "shape",
       "compound shape", "geometry", "collision shape", "collision geometry", "collision offset",
       "compound collision shape", "collision mesh type"});
  SoftBodySpec s;
  s.name = block_name(doc, id, b);
  s.scale = scale_of(doc, b, id);
  s.pose = frame(doc, b["location"], id, "location");
  if (b["mass"]) s.mass = mass_of(doc, b["mass"], id);
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
    const OptionTable<SoftBodyConfig>& keys = soft_body_config_options();
    for (const auto& entry : config) {
      const std::string key = entry.first.as<std::string>();
      if (key == "cutting") {
        ctx.diag->warn(doc.path, at(entry.first) + id + ": soft body cutting is not applied yet");
        continue;
      }
      if (keys.find(key) == nullptr) {
        ctx.diag->warn(doc.path,
                       at(entry.first) + id + ": unknown config key '" + key + "' ignored");
        continue;
      }
      try {
        keys.set(s.config, key, option_value(entry.second));
      } catch (const ArgumentError& e) {
        fail(doc, entry.second, id, "config: " + std::string(e.what()));
      }
    }
  }
  set_options(doc, id, b, soft_body_options(), s, {"randomize constraints"});
  s.material = material(doc, id, b, ctx);
  s.material.shader = read_shader(doc, b["shaders"], id, "shaders", ctx);
  if (b["visible"]) s.material.visible = boolean(doc, b["visible"], id, "visible");
  return s;
}

}  // namespace ambfplus::adf
