#include "plugin/plugin_options.h"

#include <cmath>
#include <utility>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/ghost.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/world.h"

namespace ambfplus::plugin {
namespace {

OptionValue scalar(double v) {
  if (std::isfinite(v) && std::floor(v) == v && std::fabs(v) < 2147483648.0) {
    return OptionValue(static_cast<std::int64_t>(v));
  }
  return OptionValue(v);
}

}  // namespace

OptionMap to_options(const AmbfplusOption* options, int count) {
  OptionMap out;
  for (int i = 0; i < count; ++i) {
    const AmbfplusOption& o = options[i];
    const std::string key = o.key != nullptr ? o.key : "";
    if (o.text != nullptr) {
      out.push_back({key, std::string(o.text)});
    } else if (o.count == 1 && o.values != nullptr) {
      out.push_back({key, scalar(o.values[0])});
    } else {
      std::vector<OptionValue> list;
      for (int k = 0; k < o.count && o.values != nullptr; ++k) list.push_back(scalar(o.values[k]));
      out.push_back({key, OptionValue(std::move(list))});
    }
  }
  return out;
}

Object& add_object(Model& model, const std::string& kind, const std::string& name,
                   const OptionMap& options) {
  if (kind == "body" || kind == "ghost") {
    RigidBodySpec spec;
    spec.name = name;
    rigid_body_options().apply(spec, options);
    return kind == "body" ? model.add_body(spec) : add_ghost(model, std::move(spec));
  }
  if (kind == "drill") {
    DrillSpec spec;
    spec.name = name;
    OptionMap rest;
    for (const OptionEntry& e : options) {
      if (e.key != "volume") {
        rest.push_back(e);
        continue;
      }
      const std::string& volume = e.value.text("volume");
      const std::vector<Object*> found =
          name_candidates(model.world(), volume, ObjectKind::kVolume);
      Object* v = found.size() == 1 ? found.front() : nullptr;
      if (v == nullptr) {
        throw ArgumentError("drill '" + name + "': no volume named '" + volume + "'");
      }
      spec.volume = static_cast<Volume*>(v);
    }
    if (spec.volume == nullptr) {
      throw ArgumentError("drill '" + name + "': option 'volume' (a volume's name) is needed");
    }
    drill_options().apply(spec, rest);
    return add_drill(model, spec);
  }
  throw ArgumentError("ambfplus_world_add makes a 'body', a 'ghost' or a 'drill', not '" + kind +
                      "'");
}

}  // namespace ambfplus::plugin
