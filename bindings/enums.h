#pragma once

// Kinds that files and older scripts write as strings are py::enum_ classes whose parameters also
// take the names: a str is parsed by the engine's own parse function, whose error lists the
// names it knows. Every file binding one of these types includes this header, so the caster is
// the same everywhere.

#include <pybind11/pybind11.h>

#include <string>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/constraint_actuator.h"
#include "ambfplus/scene/joint.h"
#include "ambfplus/scene/light.h"
#include "ambfplus/scene/rigid_body.h"

// The caster of an enum bound with py::enum_ that also loads a str through `parse`. The signature
// says so for parameters ("ShapeKind | str") and names the class for return values.
#define AMBFPLUS_ENUM_FROM_STR(Type, py_name, parse)                            \
  namespace pybind11::detail {                                                  \
  template <>                                                                   \
  struct type_caster<Type> : public type_caster_base<Type> {                    \
    static constexpr auto name =                                                \
        io_name("ambfplus._core." py_name " | str", "ambfplus._core." py_name); \
    bool load(handle src, bool convert) {                                       \
      if (convert && isinstance<str>(src)) {                                    \
        parsed_ = parse(src.cast<std::string>());                               \
        this->value = &parsed_;                                                 \
        return true;                                                            \
      }                                                                         \
      return type_caster_base<Type>::load(src, convert);                        \
    }                                                                           \
                                                                                \
   private:                                                                     \
    Type parsed_{};                                                             \
  };                                                                            \
  }

AMBFPLUS_ENUM_FROM_STR(ambfplus::Shape::Kind, "ShapeKind", ambfplus::parse_shape_kind)
AMBFPLUS_ENUM_FROM_STR(ambfplus::Axis, "Axis", ambfplus::parse_axis)
AMBFPLUS_ENUM_FROM_STR(ambfplus::MeshCollision, "MeshCollision", ambfplus::parse_mesh_collision)
AMBFPLUS_ENUM_FROM_STR(ambfplus::JointType, "JointType", ambfplus::parse_joint_type)
AMBFPLUS_ENUM_FROM_STR(ambfplus::ControlOutput, "ControlOutput", ambfplus::parse_control_output)
AMBFPLUS_ENUM_FROM_STR(ambfplus::ActuatorHold, "ActuatorHold", ambfplus::parse_actuator_hold)
AMBFPLUS_ENUM_FROM_STR(ambfplus::LightSpec::Type, "LightType", ambfplus::parse_light_type)
AMBFPLUS_ENUM_FROM_STR(ambfplus::RemovalMode, "RemovalMode", ambfplus::parse_removal_mode)

namespace ambfplus::bindings {

/// Binds an enum whose members are named as the engine writes them (lower case, underscores for
/// spaces), so a member's name, `Kind("name")` and the str parameters agree.
template <typename Enum>
void declare_enum(pybind11::module_& m, const char* name, const char* doc,
                  std::initializer_list<std::pair<const char*, Enum>> values,
                  Enum (*parse)(const std::string&)) {
  pybind11::enum_<Enum> e(m, name, doc);
  for (const auto& [member, value] : values) e.value(member, value);
  e.def(pybind11::init([parse](const std::string& text) { return parse(text); }),
        pybind11::arg("name"), "The member a name stands for (as files and strings write it).");
}

}  // namespace ambfplus::bindings
