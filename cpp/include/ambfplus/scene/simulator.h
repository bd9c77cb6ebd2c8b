#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/export.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {

struct AdfReport;

/// Options fixed when a simulator is created.
struct AMBFPLUS_API SimulatorOptions {
  double time_step = 0.001;  ///< seconds per fixed step
  std::string world_name = "World";
};

/// The top of the hierarchy: Simulator > World > Model > Object. Owns its world; every handle
/// the bindings give out keeps the simulator alive.
class AMBFPLUS_API Simulator : public std::enable_shared_from_this<Simulator> {
 public:
  /// Creates a simulator with an empty world that has only the scene's own systems (what the
  /// scene's unit tests need); engine::create_simulator adds physics, haptics, rendering and
  /// plugins. Throws ArgumentError for bad options.
  static std::shared_ptr<Simulator> create(const SimulatorOptions& options = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  World& world() { return *world_; }
  /// Advances the world by n fixed steps.
  void step(std::int64_t n = 1) { world_->step(n); }

  /// What loading a launch file into it loaded and reported (null if it was not loaded so).
  const std::shared_ptr<const AdfReport>& load_report() const { return load_report_; }
  void set_load_report(std::shared_ptr<const AdfReport> report) {
    load_report_ = std::move(report);
  }

  /// Command-line arguments meant for simulator plugins (AMBF forwards the ones it does not
  /// know), e.g. {"--removal", "compatible"}; set before a launch file's plugins load.
  const std::vector<std::string>& arguments() const;
  void set_arguments(std::vector<std::string> arguments);

 private:
  explicit Simulator(const SimulatorOptions& options);
  std::unique_ptr<World> world_;
  std::shared_ptr<const AdfReport> load_report_;
  std::vector<std::string> arguments_;
};

}  // namespace ambfplus
