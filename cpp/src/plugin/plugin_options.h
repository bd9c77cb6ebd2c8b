#pragma once

// Objects a plugin creates through the C API (ambfplus_world_add): its options go through the
// same keyword tables as Python's add_body and add_drill, so a key means the same in both.

#include <string>

#include "ambfplus/plugin/api.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

class Model;
class Object;

namespace plugin {

/// ambfplus_world_add's options as keyword options: a text, one number, or a list of numbers;
/// whole numbers are integers (so 0 and 1 also stand for False and True).
OptionMap to_options(const AmbfplusOption* options, int count);

/// A "body" (add_body's keywords), a "ghost" (a body's keywords; mass and kinematic are ignored)
/// or a "drill" (add_drill's, plus `volume`: a volume's name).
Object& add_object(Model& model, const std::string& kind, const std::string& name,
                   const OptionMap& options);

}  // namespace plugin
}  // namespace ambfplus
