#pragma once

// The material keywords that bodies and soft bodies share, for their option tables.

#include <string>
#include <utility>
#include <vector>

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

/// options followed by more.
template <typename Option>
std::vector<Option> joined(std::vector<Option> options, std::vector<Option> more) {
  for (Option& o : more) options.push_back(std::move(o));
  return options;
}

}  // namespace ambfplus
