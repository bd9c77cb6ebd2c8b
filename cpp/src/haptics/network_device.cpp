#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/haptics/device.h"

namespace ambfplus {
namespace {

constexpr char kPoseMagic[4] = {'A', 'P', 'D', 'P'};
constexpr char kForceMagic[4] = {'A', 'P', 'D', 'F'};
constexpr std::uint16_t kVersion = 1;

// Little-endian fields (the machines this runs on are; memcpy keeps alignment safe).
template <typename T>
T field(const std::uint8_t* data, std::size_t offset) {
  T v;
  std::memcpy(&v, data + offset, sizeof(T));
  return v;
}

template <typename T>
void put(std::uint8_t* data, std::size_t offset, T v) {
  std::memcpy(data + offset, &v, sizeof(T));
}

}  // namespace

bool NetworkDevice::parse(const std::uint8_t* data, std::size_t size, double max_distance,
                          DeviceState& state, std::uint64_t& sequence, std::string& reason) {
  if (size != kPoseBytes) {
    reason = "size";
    return false;
  }
  if (std::memcmp(data, kPoseMagic, 4) != 0) {
    reason = "magic";
    return false;
  }
  if (field<std::uint16_t>(data, 4) != kVersion) {
    reason = "version";
    return false;
  }
  sequence = field<std::uint64_t>(data, 8);
  double v[7];
  for (int i = 0; i < 7; ++i) v[i] = field<double>(data, 16 + 8 * i);
  for (double x : v) {
    if (!std::isfinite(x)) {
      reason = "values";
      return false;
    }
  }
  const Eigen::Vector3d position(v[0], v[1], v[2]);
  if (position.norm() > max_distance) {
    reason = "range";
    return false;
  }
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    reason = "rotation";
    return false;
  }
  state.position = position;
  state.orientation = q.normalized();
  state.buttons = field<std::uint32_t>(data, 72);
  return true;
}

NetworkDevice::NetworkDevice(int port, const std::string& address, double max_distance)
    : Device({"network", 10.0, 1000.0, 5.0, 0.1}), max_distance_(max_distance) {
  const std::string where = "network device on " + address + ":" + std::to_string(port);
  if (port < 0 || port > 65535) throw ArgumentError(where + ": port must be 0..65535");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  if (inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    throw ArgumentError(where + ": not an IPv4 address");
  }
  socket_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (socket_ < 0) throw ResourceError(where + ": socket: " + std::strerror(errno));
  if (bind(socket_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    const std::string error = std::strerror(errno);
    close(socket_);
    throw ResourceError(where + ": bind: " + error);
  }
  socklen_t size = sizeof(a);
  getsockname(socket_, reinterpret_cast<sockaddr*>(&a), &size);
  port_ = ntohs(a.sin_port);
  thread_ = std::thread([this] { receive(); });
}

NetworkDevice::~NetworkDevice() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (socket_ >= 0) close(socket_);
}

// Waits for datagrams (waking every 50 ms to see whether to stop) and keeps the last good one.
void NetworkDevice::receive() {
  std::uint8_t buffer[2048];
  while (!stop_) {
    pollfd p{socket_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    sockaddr_storage from{};
    socklen_t from_size = sizeof(from);
    const ssize_t n = recvfrom(socket_, buffer, sizeof(buffer), MSG_TRUNC,
                               reinterpret_cast<sockaddr*>(&from), &from_size);
    if (n < 0) continue;
    DeviceState s;
    std::uint64_t sequence = 0;
    std::string reason;
    const bool ok = parse(buffer, static_cast<std::size_t>(n), max_distance_, s, sequence, reason);
    std::lock_guard<std::mutex> lock(mutex_);
    if (ok && accepted_ > 0 && sequence <= sequence_) {
      reason = "sequence";
    } else if (ok) {
      // Readings start from the first pose, so the drill is taken up where it is.
      if (accepted_ == 0) {
        origin_position_ = s.position;
        origin_orientation_ = s.orientation;
      }
      state_ = s;
      state_.position = s.position - origin_position_;
      state_.orientation = (s.orientation * origin_orientation_.inverse()).normalized();
      sequence_ = sequence;
      ++accepted_;
      std::memcpy(client_, &from, from_size);
      client_size_ = from_size;
      has_client_ = true;
      continue;
    }
    auto it = std::find_if(rejected_.begin(), rejected_.end(),
                           [&](const auto& r) { return r.first == reason; });
    if (it == rejected_.end()) {
      rejected_.emplace_back(reason, 1);
    } else {
      ++it->second;
    }
  }
}

DeviceState NetworkDevice::read(std::int64_t, double time) {
  std::lock_guard<std::mutex> lock(mutex_);
  time_ = time;
  return state_;
}

void NetworkDevice::write(const Eigen::Vector3d& force, double dt) {
  last_force_ = force;
  std::uint8_t message[kForceBytes] = {};
  sockaddr_storage to{};
  socklen_t to_size = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!has_client_) return;
    std::memcpy(&to, client_, client_size_);
    to_size = client_size_;
    put(message, 8, sequence_);
    put(message, 16, time_);
  }
  std::memcpy(message, kForceMagic, 4);
  put(message, 4, kVersion);
  for (int i = 0; i < 3; ++i) put(message, 24 + 8 * i, force[i]);
  // Never blocks the physics thread: a full socket buffer drops this force (the next step
  // sends another).
  sendto(socket_, message, sizeof(message), MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&to),
         to_size);
}

std::uint64_t NetworkDevice::accepted() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return accepted_;
}

std::vector<std::pair<std::string, std::uint64_t>> NetworkDevice::rejected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rejected_;
}

}  // namespace ambfplus
