// The original drilling simulator's scene, run by ambfplus: a simulator plugin that finds the
// drill and the anatomy the volumetric_drilling ADF files declare and makes an ambfplus drill of
// them (finger-proxy cursors, forces, removal). Options come from the simulator's arguments
// (the command line's unknown ones, as AMBF forwards them):
//   --removal physical|compatible   how the burr removes tissue (default physical)
//   --cursors N                     tip and shaft cursors (the original's --nt, default 8)
//   --spacing M                     metres between cursors (the original's --ds, 0.0015)
//   --stiffness K                   N/m of proxy-goal separation (default 700)
//   --volume NAME                   the anatomy to drill (default: the world's first volume)
//   --labels FILE                   names and colours of the anatomy (CSV/YAML, e.g. the
//                                   original's labels.csv): the volume's colours are mapped to
//                                   the nearest, and nerves, vessels, the sinus and dura, the
//                                   labyrinth and the IAC become critical structures
// Without --labels, every label but the most common one (bone) is critical, as the original
// warns whenever the burr touches anything but bone.
// Drive the drill ("drill", or the name --drill-name gives) with an input device. Keys (the
// original's): B shows or hides the drill, X draws it where the hand is rather than where the
// bone holds it, Ctrl+C shows the cursors (proxies green, goals red), Ctrl+R puts the drill back
// where it started, Ctrl+T / Alt+T add or take a voxel per step (compatible removal).

#include <algorithm>
#include <array>
#include <cmath>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ambfplus/plugin/plugin.h"

namespace {

using ambfplus::plugin::Object;
using ambfplus::plugin::Pose;

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

void log(int level, const std::string& message) {
  ambfplus_log(level, ("volumetric_drilling: " + message).c_str());
}

// An option of ambfplus_world_add holding numbers (they must outlive the call).
AmbfplusOption numbers(const char* key, const std::vector<double>& values) {
  return AmbfplusOption{key, values.data(), static_cast<int>(values.size()), nullptr};
}
AmbfplusOption text(const char* key, const std::string& value) {
  return AmbfplusOption{key, nullptr, 0, value.c_str()};
}

class VolumetricDrilling : public ambfplus::plugin::Plugin {
 public:
  int init() override {
    const ambfplus::plugin::World w = world();
    const std::vector<std::string> args = w.arguments();
    const Object volume = find_volume(option(args, "--volume", ""));
    if (!volume) {
      log(AMBFPLUS_WARNING, "the world has no volume to drill; not kept");
      return 0;
    }
    const std::string labels = option(args, "--labels", "");
    if (!labels.empty()) {
      ambfplus::plugin::detail::checked(
          ambfplus_volume_name_labels(w.handle(), volume.id(), labels.c_str()));
    }
    ambfplus::plugin::detail::checked(ambfplus_volume_mark_critical(w.handle(), volume.id()));
    // The drill's body (an invisible anchor in the original's drills.yaml) and one body per
    // burr, named by its diameter ("1mm" ... "6mm"), whose mesh shows the burr in use.
    const std::vector<Object> anchors = w.lookup("mastoidectomy_drill", AMBFPLUS_BODY);
    const Object anchor = anchors.size() == 1 ? anchors[0] : Object();
    const std::regex burr_name(R"(^([0-9]+(\.[0-9]+)?)mm$)");
    for (const Object& b : w.objects(AMBFPLUS_BODY)) {
      std::smatch m;
      const std::string name = b.name();
      if (std::regex_match(name, m, burr_name)) burrs_.emplace_back(std::stod(m[1]) * 1e-3, b);
    }
    std::sort(burrs_.begin(), burrs_.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });

    std::vector<double> diameters{0.001, 0.002, 0.004, 0.006};
    if (!burrs_.empty()) {
      diameters.clear();
      for (const auto& b : burrs_) diameters.push_back(b.first);
    }
    const std::vector<double> burr{static_cast<double>(diameters.size()) - 1};  // the largest
    const std::vector<double> cursors{number(args, "--cursors", 8)};
    const std::vector<double> spacing{number(args, "--spacing", 0.0015)};
    const std::vector<double> stiffness{number(args, "--stiffness", 700)};
    const std::string removal = option(args, "--removal", "physical");
    if (removal != "physical" && removal != "compatible") {
      throw std::invalid_argument(
          "volumetric_drilling: --removal must be physical or "
          "compatible, got '" +
          removal + "'");
    }
    const std::string volume_name = volume.name();
    const Pose start = anchor ? anchor.pose() : identity();
    const std::vector<double> pose(start.begin(), start.end());
    const std::string model = anchor ? anchor.model() : std::string();
    drill_ =
        w.add("drill", option(args, "--drill-name", "drill"),
              {text("volume", volume_name), numbers("burr_diameters", diameters),
               numbers("burr", burr), numbers("cursors", cursors), numbers("spacing", spacing),
               numbers("stiffness", stiffness), text("removal", removal), numbers("pose", pose)},
              model.empty() ? nullptr : model.c_str());
    // The meshes ride on the drill (they stop colliding with its cursors).
    const Pose here = identity();
    if (anchor) anchor.attach_to(drill_, &here);
    for (const auto& b : burrs_) b.second.attach_to(drill_, &here);
    start_ = drill_.get("goal");
    add_cursor_markers(model);
    show_burr();
    log(AMBFPLUS_INFO, "drill '" + drill_.name() + "' on volume '" + volume_name + "' with " +
                           std::to_string(burrs_.size()) + " burr meshes, " + removal + " removal");
    return 1;
  }

  void physics_update(double) override {
    if (static_cast<int>(drill_.get1("burr")) != shown_) show_burr();
    if (show_cursors_) place_cursor_markers();
  }

  void keyboard(int key, int, int action, int mods) override {
    if (action != kPress) return;
    if (mods == 0 && key == 'B') {
      visible_ = !visible_;
      show_burr();
    } else if (mods == 0 && key == 'X') {
      drill_.set1("meshes_follow_goal", drill_.get1("meshes_follow_goal") != 0 ? 0.0 : 1.0);
    } else if (mods == kControl && key == 'C') {
      show_cursors_ = !show_cursors_;
      for (const Object& m : markers_) m.set1("visible", show_cursors_ ? 1.0 : 0.0);
      if (show_cursors_) place_cursor_markers();
    } else if (mods == kControl && key == 'R') {
      drill_.set("goal", start_);
    } else if ((mods == kControl || mods == kAlt) && key == 'T') {
      const int burr = static_cast<int>(drill_.get1("burr"));
      std::vector<double> counts = drill_.get("voxels_per_step");
      counts[burr] = std::max(1.0, counts[burr] + (mods == kControl ? 1 : -1));
      drill_.set("voxels_per_step", counts);
      log(AMBFPLUS_INFO, std::to_string(static_cast<int>(counts[burr])) +
                             " voxels per step with this burr (compatible removal)");
    }
  }

  void reset() override { drill_.set("goal", start_); }

 private:
  // GLFW's press action and modifier bits.
  static constexpr int kPress = 1, kControl = 0x2, kAlt = 0x4;

  static Pose identity() {
    Pose p{};
    p[0] = p[5] = p[10] = p[15] = 1.0;
    return p;
  }

  // A small sphere per cursor proxy (green) and goal (red), drawn only, hidden until Ctrl+C.
  void add_cursor_markers(const std::string& model) {
    const std::vector<double> radii = drill_.get("cursor_radii");
    const std::string sphere = "sphere";
    const std::vector<double> zero{0.0}, one{1.0};
    const std::vector<double> green{0.1, 0.85, 0.2, 1.0}, red{0.9, 0.15, 0.1, 1.0};
    for (std::size_t i = 0; i < radii.size(); ++i) {
      const std::vector<double> radius{std::max(0.0003, radii[i] * 0.35)};
      for (const bool goal : {false, true}) {
        markers_.push_back(
            world().add("body", drill_.name() + (goal ? "_goal_" : "_proxy_") + std::to_string(i),
                        {text("shape", sphere), numbers("radius", radius), numbers("mass", zero),
                         numbers("kinematic", one), numbers("collision", zero),
                         numbers("color", goal ? red : green), numbers("visible", zero)},
                        model.empty() ? nullptr : model.c_str()));
      }
    }
  }

  void place_cursor_markers() {
    const std::vector<double> proxies = drill_.get("cursor_proxies");
    const std::vector<double> goals = drill_.get("cursor_goals");
    for (std::size_t i = 0; 2 * i + 1 < markers_.size(); ++i) {
      Pose at = identity();
      for (const bool goal : {false, true}) {
        const std::vector<double>& p = goal ? goals : proxies;
        at[3] = p[3 * i];
        at[7] = p[3 * i + 1];
        at[11] = p[3 * i + 2];
        markers_[2 * i + (goal ? 1 : 0)].set_pose(at);
      }
    }
  }

  Object find_volume(const std::string& name) const {
    for (const Object& v : world().objects(AMBFPLUS_VOLUME)) {
      if (name.empty() || v.name() == name) return v;
    }
    return Object();
  }

  // Only the burr in use is drawn (none while hidden with B).
  void show_burr() {
    shown_ = static_cast<int>(drill_.get1("burr"));
    for (std::size_t i = 0; i < burrs_.size(); ++i) {
      burrs_[i].second.set1("visible", visible_ && static_cast<int>(i) == shown_ ? 1.0 : 0.0);
    }
  }

  Object drill_;
  std::vector<std::pair<double, Object>> burrs_;  // diameter (m), its mesh's body
  std::vector<Object> markers_;                   // proxy then goal, per cursor
  std::vector<double> start_;                     // the goal to go back to
  int shown_ = -1;
  bool visible_ = true;
  bool show_cursors_ = false;
};

}  // namespace

AMBFPLUS_PLUGIN(VolumetricDrilling)
