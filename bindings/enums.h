#pragma once

// Kinds that files and older scripts write as strings are py::enum_ classes; every parameter
// taking one also takes its name (KindOrName), which goes to the engine's own parse function
// through the option tables, so a bad name gets the engine's message listing the names it knows.

#include <pybind11/pybind11.h>
#include <pybind11/typing.h>

#include <initializer_list>
#include <string>
#include <utility>

#include "ambfplus/errors.h"

namespace ambfplus::bindings {

/// A parameter taking an enum member or its name; stubs say "Kind | str".
template <typename Enum>
using KindOrName = pybind11::typing::Union<Enum, pybind11::str>;
/// The same, or None.
template <typename Enum>
using OptionalKindOrName = pybind11::typing::Optional<KindOrName<Enum>>;

/// The member a parameter names: an Enum member or its name (parsed by `parse`); kind names the
/// enum in messages.
template <typename Enum>
Enum to_kind(const pybind11::handle& value, Enum (*parse)(const std::string&), const char* kind) {
  if (pybind11::isinstance<pybind11::str>(value)) return parse(value.cast<std::string>());
  if (pybind11::isinstance<Enum>(value)) return value.cast<Enum>();
  const std::string given = pybind11::repr(value);
  throw ArgumentTypeError(std::string("expected a ") + kind + " or its name, got " + given);
}

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
