// InputDeviceSpec: its checks and its keyword options.

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/input_device.h"

namespace ambfplus {

void InputDeviceSpec::validate() const {
  const std::string who = "input device '" + name + "': ";
  if (!(workspace_scale > 0) || !std::isfinite(workspace_scale)) {
    throw ArgumentError(who + "workspace scale must be > 0");
  }
  if (!(max_force >= 0) || !(force_scale >= 0) || !std::isfinite(force_scale)) {
    throw ArgumentError(who + "max force and force scale must be >= 0");
  }
  for (int b : {drill_button, clutch_button, burr_button}) {
    if (b < -1 || b > 31) throw ArgumentError(who + "buttons are 0..31 (-1: none)");
  }
}

const OptionTable<InputDeviceSpec>& input_device_options() {
  using S = InputDeviceSpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "add_input_device()",
      {
          O{"workspace_scale", "float", "world m per device m",
            [](S& s, V v, K k) { s.workspace_scale = v.number(k); }},
          O{"reference", "Object | None", "the object whose axes device motion follows",
            [](S& s, V v, K k) { s.reference = v.object(k); }},
          O{"drill_button", "int", "held: the burr spins (-1: none)",
            [](S& s, V v, K k) { s.drill_button = v.integer(k); }},
          O{"clutch_button", "int", "held: the device moves alone (-1: none)",
            [](S& s, V v, K k) { s.clutch_button = v.integer(k); }},
          O{"burr_button", "int", "pressed: the next burr (-1: none)",
            [](S& s, V v, K k) { s.burr_button = v.integer(k); }},
          O{"max_force", "float", "N sent at most",
            [](S& s, V v, K k) { s.max_force = v.number(k); }},
          O{"force_scale", "float", "force sent per newton of the drill's",
            [](S& s, V v, K k) { s.force_scale = v.number(k); }},
      });
  return table;
}

}  // namespace ambfplus
