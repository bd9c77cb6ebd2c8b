// The original drilling simulator's scene, run by ambfplus: a simulator plugin that finds the
// drill and the anatomy the volumetric_drilling ADF files declare and makes an ambfplus drill of
// them (finger-proxy cursors, forces, removal). Options come from the simulator's arguments
// (the command line's unknown ones, as AMBF forwards them):
//   --removal physical|compatible   how the burr removes tissue (default physical)
//   --cursors N                     tip and shaft cursors (the original's --nt, default 8)
//   --spacing M                     metres between cursors (the original's --ds, 0.0015)
//   --stiffness K                   N/m of proxy-goal separation (default 700)
//   --volume NAME                   the anatomy to drill (default: the world's first volume)
// Drive the drill ("drill", or the name --drill-name gives) with an input device.

#include <algorithm>
#include <cmath>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ambfplus/haptics/drill.h"
#include "ambfplus/log.h"
#include "ambfplus/plugin/plugin.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/world.h"

namespace {

using ambfplus::Drill;
using ambfplus::RigidBody;

// The value after `flag` in args, or fallback.
std::string option(const std::vector<std::string>& args, const std::string& flag,
                   const std::string& fallback) {
  for (std::size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == flag) return args[i + 1];
  }
  for (const std::string& a : args) {
    if (a.rfind(flag + "=", 0) == 0) return a.substr(flag.size() + 1);
  }
  return fallback;
}

double number(const std::vector<std::string>& args, const std::string& flag, double fallback) {
  const std::string text = option(args, flag, "");
  if (text.empty()) return fallback;
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("volumetric_drilling: " + flag + " needs a number, got '" + text +
                              "'");
}

class VolumetricDrilling : public ambfplus::Plugin {
 public:
  int init() override {
    ambfplus::World& w = world();
    const std::vector<std::string>& args = simulator().arguments();
    ambfplus::Volume* volume = find_volume(w, option(args, "--volume", ""));
    if (volume == nullptr) {
      ambfplus::log(ambfplus::LogLevel::kWarning,
                    "volumetric_drilling: the world has no volume to drill; not kept");
      return 0;
    }
    // The drill's body (an invisible anchor in the original's drills.yaml) and one body per
    // burr, named by its diameter ("1mm" ... "6mm"), whose mesh shows the burr in use.
    const std::vector<ambfplus::Object*> bodies =
        w.lookup("mastoidectomy_drill", ambfplus::ObjectKind::kRigidBody);
    RigidBody* anchor = bodies.size() == 1 ? static_cast<RigidBody*>(bodies[0]) : nullptr;
    const std::regex burr_name(R"(^([0-9]+(\.[0-9]+)?)mm$)");
    for (RigidBody* b : w.objects_of_kind<RigidBody>()) {
      std::smatch m;
      if (std::regex_match(b->name(), m, burr_name)) burrs_.emplace_back(std::stod(m[1]) * 1e-3, b);
    }
    std::sort(burrs_.begin(), burrs_.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });

    ambfplus::DrillSpec spec;
    spec.name = option(args, "--drill-name", "drill");
    spec.volume = volume;
    if (!burrs_.empty()) {
      spec.burr_diameters.clear();
      for (const auto& b : burrs_) spec.burr_diameters.push_back(b.first);
    }
    spec.burr = static_cast<int>(spec.burr_diameters.size()) - 1;  // the largest, as the original
    spec.cursors = static_cast<int>(number(args, "--cursors", spec.cursors));
    spec.spacing = number(args, "--spacing", spec.spacing);
    spec.stiffness = number(args, "--stiffness", spec.stiffness);
    const std::string removal = option(args, "--removal", "physical");
    if (removal != "physical" && removal != "compatible") {
      throw std::invalid_argument(
          "volumetric_drilling: --removal must be physical or "
          "compatible, got '" +
          removal + "'");
    }
    spec.removal = removal == "compatible" ? ambfplus::RemovalMode::kCompatible
                                           : ambfplus::RemovalMode::kPhysical;
    if (anchor != nullptr) spec.pose = anchor->pose().matrix();
    ambfplus::Model& model = anchor != nullptr ? anchor->model() : w.default_model();
    drill_ = &model.add_drill(spec);
    // The meshes ride on the drill (they stop colliding with its cursors).
    if (anchor != nullptr) drill_->attach(*anchor);
    for (const auto& b : burrs_) drill_->attach(*b.second);
    show_burr();
    ambfplus::log(ambfplus::LogLevel::kInfo, "volumetric_drilling: drill '" + drill_->name() +
                                                 "' on volume '" + volume->name() + "' with " +
                                                 std::to_string(burrs_.size()) + " burr meshes, " +
                                                 removal + " removal");
    return 1;
  }

  void physics_update(double) override {
    if (drill_->burr() != shown_) show_burr();
  }

 private:
  static ambfplus::Volume* find_volume(ambfplus::World& w, const std::string& name) {
    for (ambfplus::Volume* v : w.objects_of_kind<ambfplus::Volume>()) {
      if (name.empty() || v->name() == name) return v;
    }
    return nullptr;
  }

  // Only the burr in use is drawn.
  void show_burr() {
    shown_ = drill_->burr();
    for (std::size_t i = 0; i < burrs_.size(); ++i) {
      RigidBody& body = *burrs_[i].second;
      ambfplus::Material m = body.material();
      m.visible = static_cast<int>(i) == shown_;
      body.set_material(m);
    }
  }

  Drill* drill_ = nullptr;
  std::vector<std::pair<double, RigidBody*>> burrs_;  // diameter (m), its mesh's body
  int shown_ = -1;
};

}  // namespace

AMBFPLUS_PLUGIN(VolumetricDrilling)
