#pragma once

// Keywords that several specs share, for their option tables: a material's (bodies, soft
// bodies) and an attachment's to a parent body (sensors, actuators).

#include <string>
#include <utility>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/scene/options.h"
#include "ambfplus/scene/rigid_body.h"

namespace ambfplus {

/// color, specular, shininess and visible, setting the Material `member` of a Spec.
template <typename Spec>
std::vector<typename OptionTable<Spec>::Option> material_options(Material Spec::*member) {
  using O = typename OptionTable<Spec>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  return {
      O{"color", "tuple[float, ...]", "RGB or RGBA in 0..1",
        [member](Spec& s, V v, K k) { (s.*member).color = v.rgba(k); }},
      O{"specular", "float", "Phong factor",
        [member](Spec& s, V v, K k) { (s.*member).specular = static_cast<float>(v.number(k)); }},
      O{"shininess", "float", "Phong exponent",
        [member](Spec& s, V v, K k) { (s.*member).shininess = static_cast<float>(v.number(k)); }},
      O{"visible", "bool", "drawn in images (False: it still collides)",
        [member](Spec& s, V v, K k) { (s.*member).visible = v.boolean(k); }},
  };
}

/// location (in the parent's frame) or pose (world, now), visible and visible_size of a Spec
/// with those fields and a parent body; `what` names it in messages ("a sensor").
template <typename Spec>
std::vector<typename OptionTable<Spec>::Option> attachment_options(const std::string& what) {
  using O = typename OptionTable<Spec>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  return {
      O{"location", "numpy.ndarray", "4x4 frame in the parent's frame",
        [](Spec& s, V v, K k) { s.location = v.matrix4(k); }},
      O{"pose", "numpy.ndarray", "4x4 frame in the world, now",
        [what](Spec& s, V v, K k) {
          if (s.parent == nullptr) throw ArgumentError(what + "'s pose needs its parent");
          s.location = (s.parent->pose().inverse() * checked_pose(v.matrix4(k))).matrix();
        }},
      O{"visible", "bool", "", [](Spec& s, V v, K k) { s.visible = v.boolean(k); }},
      O{"visible_size", "float", "m", [](Spec& s, V v, K k) { s.visible_size = v.number(k); }},
  };
}

/// options followed by more.
template <typename Option>
std::vector<Option> joined(std::vector<Option> options, std::vector<Option> more) {
  for (Option& o : more) options.push_back(std::move(o));
  return options;
}

}  // namespace ambfplus
