#include "ambfplus/scene/simulator.h"
#include "ambfplus/errors.h"

#include <cmath>
#include <stdexcept>

namespace ambfplus {

std::shared_ptr<Simulator> Simulator::create(const SimulatorOptions& options) {
  if (!(options.time_step > 0.0) || !std::isfinite(options.time_step)) {
    throw ArgumentError("time_step must be a positive number of seconds, got " +
                        std::to_string(options.time_step));
  }
  return std::shared_ptr<Simulator>(new Simulator(options));
}

Simulator::Simulator(const SimulatorOptions& options)
    : world_(new World(*this, options.world_name, options.time_step)) {}

Simulator::~Simulator() = default;

const std::vector<std::string>& Simulator::arguments() const { return arguments_; }

void Simulator::set_arguments(std::vector<std::string> arguments) {
  arguments_ = std::move(arguments);
}

}  // namespace ambfplus
