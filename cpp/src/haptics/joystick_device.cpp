#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/device.h"

namespace ambfplus {
namespace {

// The Linux joystick interface's event types (linux/joystick.h), without the header.
constexpr std::uint8_t kButton = 0x01, kAxis = 0x02, kInit = 0x80;
constexpr std::size_t kEventBytes = 8;

}  // namespace

JoystickDevice::JoystickDevice(const std::string& path, Mapping mapping)
    : Device({"joystick", 0.0, 0.0, 0.0, 0.1}), mapping_(mapping) {
  if (!(mapping.speed >= 0) || !(mapping.deadband >= 0 && mapping.deadband < 1)) {
    throw ArgumentError("joystick device: speed must be >= 0 and deadband in [0, 1)");
  }
  if (path.empty()) return;
  fd_ = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    throw AssetNotFound(path, std::string("joystick device (") + std::strerror(errno) + ")");
  }
  thread_ = std::thread([this] { listen(); });
}

JoystickDevice::~JoystickDevice() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) close(fd_);
}

// Reads events until stopped. A pipe without a writer reads as the end of the file: wait for
// one. A device that goes away (unplugged) releases every button, so a pedal pulled out with
// the burr spinning stops it.
void JoystickDevice::listen() {
  std::uint8_t buffer[256];
  while (!stop_) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n > 0) {
      feed(buffer, static_cast<std::size_t>(n));
    } else if (n == 0 || errno == EAGAIN || errno == EINTR) {
      usleep(50000);
    } else {
      std::lock_guard<std::mutex> lock(mutex_);
      held_ = 0;
      deflection_ = {0, 0, 0};
      disconnected_ = true;
      return;
    }
  }
}

bool JoystickDevice::disconnected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return disconnected_;
}

void JoystickDevice::feed(const std::uint8_t* data, std::size_t size) {
  std::lock_guard<std::mutex> lock(mutex_);
  partial_.insert(partial_.end(), data, data + size);
  std::size_t used = 0;
  for (; used + kEventBytes <= partial_.size(); used += kEventBytes) {
    std::int16_t value = 0;
    std::memcpy(&value, partial_.data() + used + 4, sizeof(value));
    event(value, partial_[used + 6], partial_[used + 7]);
  }
  partial_.erase(partial_.begin(), partial_.begin() + static_cast<std::ptrdiff_t>(used));
}

// Roles of a button in the device's own bits: 0 burr spins, 1 clutch, 2 next burr.
void JoystickDevice::event(std::int16_t value, std::uint8_t type, std::uint8_t number) {
  const std::uint8_t kind = type & ~kInit;
  if (kind == kButton) {
    const int roles[3] = {mapping_.drill, mapping_.clutch, mapping_.burr};
    for (int bit = 0; bit < 3; ++bit) {
      if (roles[bit] != number) continue;
      if (value != 0) {
        held_ |= 1u << bit;
        latched_ |= 1u << bit;
      } else {
        held_ &= ~(1u << bit);
      }
    }
  } else if (kind == kAxis) {
    for (int a = 0; a < 3; ++a) {
      if (mapping_.axes[a] != number) continue;
      double d = value / 32767.0;
      d = std::abs(d) < mapping_.deadband ? 0.0 : std::max(-1.0, std::min(1.0, d));
      // Screen axes: a stick pushed up (negative) moves up.
      deflection_[a] = a == 1 ? -d : d;
    }
  }
}

DeviceState JoystickDevice::read(std::int64_t, double time) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Velocity integrated in simulation time, so a replay of the readings is the same.
  const double dt = last_time_ < 0 ? 0.0 : time - last_time_;
  last_time_ = time;
  for (int a = 0; a < 3; ++a) state_.position[a] += deflection_[a] * mapping_.speed * dt;
  state_.buttons = held_ | latched_;
  latched_ = 0;
  return state_;
}

}  // namespace ambfplus
