// DrillSpec: its removal modes, its checks and its keyword options.

#include <cmath>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "util/strings.h"

namespace ambfplus {
namespace {

void require(bool ok, const std::string& who, const std::string& what) {
  if (!ok) throw ArgumentError(who + what);
}

bool finite_at_least(double v, double lo) { return v >= lo && std::isfinite(v); }

}  // namespace

FixtureSpec fixture_from(const OptionValue& value, const std::string& key) {
  FixtureSpec f;
  try {
    fixture_options().apply(f, value.map(key));
  } catch (const ArgumentTypeError& e) {
    throw ArgumentTypeError(key + ": " + e.what());
  } catch (const ArgumentError& e) {
    throw ArgumentError(key + ": " + e.what());
  }
  if (find_option(value.map(key), "structure") == nullptr) {
    throw ArgumentError(key + ": a fixture needs a structure (a label name or id)");
  }
  if (find_option(value.map(key), "start") == nullptr) {
    throw ArgumentError(key + ": fixture '" + f.structure + "' needs a start distance (m)");
  }
  f.validate(key + ": ");
  return f;
}

namespace {}  // namespace

RemovalMode parse_removal_mode(const std::string& name) {
  const std::string n = to_lower(name);
  if (n == "physical") return RemovalMode::kPhysical;
  if (n == "compatible") return RemovalMode::kCompatible;
  throw ArgumentError("removal must be physical or compatible, got '" + name + "'");
}

const char* removal_mode_name(RemovalMode mode) {
  return mode == RemovalMode::kPhysical ? "physical" : "compatible";
}

void DrillSpec::validate() const {
  const std::string who = "drill '" + name + "': ";
  require(!burr_diameters.empty(), who, "needs at least one burr");
  for (double d : burr_diameters) {
    require(d > 0 && std::isfinite(d), who, "burr diameters must be > 0");
  }
  require(burr >= 0 && burr < static_cast<int>(burr_diameters.size()), who,
          "burr index must be 0.." + std::to_string(burr_diameters.size() - 1));
  require(cursors >= 1 && cursors <= 16, who,
          "cursors must be 1..16, got " + std::to_string(cursors));
  require(spacing > 0 && std::isfinite(spacing), who, "cursor spacing must be > 0");
  if (!shaft_radii.empty()) {
    require(static_cast<int>(shaft_radii.size()) == cursors - 1, who,
            "needs " + std::to_string(cursors - 1) + " shaft radii, got " +
                std::to_string(shaft_radii.size()));
    for (double r : shaft_radii) require(r > 0 && std::isfinite(r), who, "shaft radii must be > 0");
  }
  require(voxels_per_step.size() == burr_diameters.size(), who,
          "voxels_per_step needs one count per burr");
  for (int n : voxels_per_step) require(n >= 1, who, "voxels per step must be >= 1");
  require(stiffness > 0 && std::isfinite(stiffness), who, "stiffness must be > 0 N/m");
  require(max_force > 0 && finite_at_least(damping, 0) && finite_at_least(soft_start, 0), who,
          "max_force must be > 0, damping and soft_start >= 0");
  require(finite_at_least(cutting_rate, 0), who, "cutting rate must be >= 0");
  require(finite_at_least(friction.static_coefficient, 0) &&
              finite_at_least(friction.dynamic_coefficient, 0),
          who, "friction coefficients must be >= 0");
  checked_pose(pose, "drill '" + name + "'");
  for (const FixtureSpec& f : fixtures) f.validate(who);
}

const OptionTable<DrillSpec>& drill_options() {
  using S = DrillSpec;
  using O = OptionTable<S>::Option;
  using V = const OptionValue&;
  using K = const std::string&;
  static const OptionTable<S> table(
      "add_drill()",
      {
          O{"burr_diameters", "list[float]", "m",
            [](S& s, V v, K k) { s.burr_diameters = v.numbers(k); }},
          O{"burr", "int", "index into burr_diameters",
            [](S& s, V v, K k) { s.burr = v.integer(k); }},
          O{"cursors", "int", "tip + shaft cursors, 1..16",
            [](S& s, V v, K k) { s.cursors = v.integer(k); }},
          O{"spacing",
            "float",
            "m between cursors along the shaft",
            [](S& s, V v, K k) { s.spacing = v.number(k); },
            {"cursor spacing"}},
          O{"shaft_radii", "list[float]", "m, one per shaft cursor",
            [](S& s, V v, K k) { s.shaft_radii = v.numbers(k); }},
          O{"stiffness", "float", "N/m", [](S& s, V v, K k) { s.stiffness = v.number(k); }},
          O{"damping", "float", "N s/m", [](S& s, V v, K k) { s.damping = v.number(k); }},
          O{"max_force", "float", "N", [](S& s, V v, K k) { s.max_force = v.number(k); }},
          O{"soft_start", "float", "s over which forces ramp up",
            [](S& s, V v, K k) { s.soft_start = v.number(k); }},
          O{"static_friction", "float", "",
            [](S& s, V v, K k) { s.friction.static_coefficient = v.number(k); }},
          O{"dynamic_friction", "float", "",
            [](S& s, V v, K k) { s.friction.dynamic_coefficient = v.number(k); }},
          O{"friction", "dict[str, float]", "{static, dynamic}",
            [](S& s, V v, K k) {
              for (const OptionEntry& e : v.map(k)) {
                if (e.key == "static") {
                  s.friction.static_coefficient = e.value.number(k + ".static");
                } else if (e.key == "dynamic") {
                  s.friction.dynamic_coefficient = e.value.number(k + ".dynamic");
                } else {
                  throw ArgumentTypeError("friction takes static and dynamic, got '" + e.key + "'");
                }
              }
            }},
          O{"removal", "RemovalMode | str", "physical or compatible",
            [](S& s, V v, K k) { s.removal = parse_removal_mode(v.text(k)); }},
          O{"cutting_rate", "float", "m^3 / (s N) at full speed",
            [](S& s, V v, K k) { s.cutting_rate = v.number(k); }},
          O{"voxels_per_step", "list[int]", "per burr (compatible removal)",
            [](S& s, V v, K k) { s.voxels_per_step = v.integers(k); }},
          O{"pose", "numpy.ndarray", "4x4 initial goal, world from drill",
            [](S& s, V v, K k) { s.pose = v.matrix4(k); }},
          O{"fixtures", "list[dict]",
            "forbidden regions: {structure, start, max_force, stop, enabled} each",
            [](S& s, V v, K k) {
              s.fixtures.clear();
              const std::vector<OptionValue>& list = v.list(k);
              for (std::size_t i = 0; i < list.size(); ++i) {
                s.fixtures.push_back(fixture_from(list[i], k + "[" + std::to_string(i) + "]"));
              }
            }},
      });
  return table;
}

}  // namespace ambfplus
