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
    const std::string labels = option(args, "--labels", "");
    if (!labels.empty()) name_labels(*volume->data(), ambfplus::read_label_table(labels));
    mark_critical(*volume->data());
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
    start_ = drill_->goal();
    add_cursor_markers(model);
    show_burr();
    ambfplus::log(ambfplus::LogLevel::kInfo, "volumetric_drilling: drill '" + drill_->name() +
                                                 "' on volume '" + volume->name() + "' with " +
                                                 std::to_string(burrs_.size()) + " burr meshes, " +
                                                 removal + " removal");
    return 1;
  }

  void physics_update(double) override {
    if (drill_->burr() != shown_) show_burr();
    if (show_cursors_) place_cursor_markers();
  }

  void keyboard(int key, int, int action, int mods) override {
    if (action != kPress) return;
    if (mods == 0 && key == 'B') {
      visible_ = !visible_;
      show_burr();
    } else if (mods == 0 && key == 'X') {
      drill_->set_meshes_follow_goal(!drill_->meshes_follow_goal());
    } else if (mods == kControl && key == 'C') {
      show_cursors_ = !show_cursors_;
      for (RigidBody* m : markers_) set_visible(*m, show_cursors_);
      if (show_cursors_) place_cursor_markers();
    } else if (mods == kControl && key == 'R') {
      drill_->set_goal(start_);
    } else if ((mods == kControl || mods == kAlt) && key == 'T') {
      const int burr = drill_->burr();
      const int now = drill_->spec().voxels_per_step[burr];
      drill_->set_voxels_per_step(burr, std::max(1, now + (mods == kControl ? 1 : -1)));
      ambfplus::log(ambfplus::LogLevel::kInfo,
                    "volumetric_drilling: " + std::to_string(drill_->spec().voxels_per_step[burr]) +
                        " voxels per step with this burr (compatible removal)");
    }
  }

  void reset() override { drill_->set_goal(start_); }

 private:
  // GLFW's press action and modifier bits.
  static constexpr int kPress = 1, kControl = 0x2, kAlt = 0x4;

  static void set_visible(RigidBody& body, bool visible) {
    ambfplus::Material m = body.material();
    m.visible = visible;
    body.set_material(m);
  }

  // A small sphere per cursor proxy (green) and goal (red), drawn only, hidden until Ctrl+C.
  void add_cursor_markers(ambfplus::Model& model) {
    for (int i = 0; i < drill_->cursor_count(); ++i) {
      for (const bool goal : {false, true}) {
        ambfplus::RigidBodySpec s;
        s.name = drill_->name() + (goal ? "_goal_" : "_proxy_") + std::to_string(i);
        s.shape.kind = ambfplus::Shape::Kind::kSphere;
        s.shape.radius = std::max(0.0003, drill_->cursor_radius(i) * 0.35);
        s.dynamics.mass = 0;
        s.dynamics.kinematic = true;
        s.collision.enabled = false;
        s.material.color = goal ? std::array<float, 4>{0.9f, 0.15f, 0.1f, 1.0f}
                                : std::array<float, 4>{0.1f, 0.85f, 0.2f, 1.0f};
        s.material.visible = false;
        markers_.push_back(&model.add_body(s));
      }
    }
  }

  void place_cursor_markers() {
    for (int i = 0; i < drill_->cursor_count(); ++i) {
      Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
      at.translation() = drill_->cursor_proxy(i);
      markers_[2 * i]->set_pose(at);
      at.translation() = drill_->cursor_goal(i);
      markers_[2 * i + 1]->set_pose(at);
    }
  }

  // Names the volume's labels from a table: each label takes the table's label of the nearest
  // colour (voxels relabelled), and the new labels are what reset() restores.
  static void name_labels(ambfplus::VolumeData& data, const ambfplus::LabelTable& named) {
    std::vector<std::uint16_t> to(data.label_table().max_id() + 1, 0);
    for (const ambfplus::Label& l : data.label_table().labels()) to[l.id] = named.nearest(l.color);
    const std::int64_t n = data.voxel_count();
    auto relabel = [&](auto* grid) {
      for (std::int64_t v = 0; v < n; ++v) {
        if (grid[v] != 0 && grid[v] < to.size()) grid[v] = static_cast<std::uint8_t>(to[grid[v]]);
      }
    };
    if (data.label_type() == ambfplus::LabelType::kUInt8) {
      if (named.max_id() > 255) {
        throw std::invalid_argument(
            "volumetric_drilling: --labels has ids above 255 for an "
            "8-bit volume");
      }
      relabel(static_cast<std::uint8_t*>(data.label_data()));
    } else {
      auto* grid = static_cast<std::uint16_t*>(data.label_data());
      for (std::int64_t v = 0; v < n; ++v) {
        if (grid[v] != 0 && grid[v] < to.size()) grid[v] = to[grid[v]];
      }
    }
    data.set_label_table(named);
    data.mark_dirty({{0, 0, 0}, data.shape()});
    data.commit();
  }

  // Critical structures: by name where the table names them, else all but the commonest label.
  static void mark_critical(ambfplus::VolumeData& data) {
    std::vector<ambfplus::Label> labels = data.label_table().labels();
    if (std::any_of(labels.begin(), labels.end(), [](const auto& l) { return l.critical; })) {
      return;
    }
    static const char* const kCritical[] = {"facial", "chorda", "nerve",     "ica",     "carotid",
                                            "sinus",  "dura",   "labyrinth", "cochlea", "iac"};
    bool named = false;
    for (ambfplus::Label& l : labels) {
      std::string lower = l.name;
      std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
      for (const char* word : kCritical) {
        if (lower.find(word) != std::string::npos) l.critical = named = true;
      }
    }
    if (!named) {
      const std::vector<std::int64_t> counts = data.label_counts();
      const auto commonest = static_cast<std::uint16_t>(
          std::max_element(counts.begin() + 1, counts.end()) - counts.begin());
      for (ambfplus::Label& l : labels) l.critical = l.id != commonest;
    }
    data.set_label_table(ambfplus::LabelTable(labels));
  }

  static ambfplus::Volume* find_volume(ambfplus::World& w, const std::string& name) {
    for (ambfplus::Volume* v : w.objects_of_kind<ambfplus::Volume>()) {
      if (name.empty() || v->name() == name) return v;
    }
    return nullptr;
  }

  // Only the burr in use is drawn (none while hidden with B).
  void show_burr() {
    shown_ = drill_->burr();
    for (std::size_t i = 0; i < burrs_.size(); ++i) {
      set_visible(*burrs_[i].second, visible_ && static_cast<int>(i) == shown_);
    }
  }

  Drill* drill_ = nullptr;
  std::vector<std::pair<double, RigidBody*>> burrs_;  // diameter (m), its mesh's body
  std::vector<RigidBody*> markers_;                   // proxy then goal, per cursor
  Eigen::Isometry3d start_ = Eigen::Isometry3d::Identity();
  int shown_ = -1;
  bool visible_ = true;
  bool show_cursors_ = false;
};

}  // namespace

AMBFPLUS_PLUGIN(VolumetricDrilling)
