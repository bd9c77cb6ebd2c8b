#pragma once

// Files the engine reads whole: regular files only. A FIFO, a device or a socket would block
// a read forever or never end, so each is refused with what it is.

#include <filesystem>
#include <string>

#include "ambfplus/errors.h"

namespace ambfplus {

/// Throws AssetNotFound when nothing is at `path`, and ConfigError naming what is there when it
/// is not a regular file (a folder, a FIFO, a device, a socket); `what` says what was expected
/// ("mesh", "NRRD", ...). Links are followed.
inline void require_regular_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::regular) return;
  if (!fs::exists(status)) throw AssetNotFound(path, what);
  const char* kind = "something else";
  switch (status.type()) {
    case fs::file_type::directory:
      kind = "a folder";
      break;
    case fs::file_type::fifo:
      kind = "a FIFO (named pipe)";
      break;
    case fs::file_type::socket:
      kind = "a socket";
      break;
    case fs::file_type::block:
    case fs::file_type::character:
      kind = "a device";
      break;
    default:
      break;
  }
  throw ConfigError(path,
                    std::string("not a regular file but ") + kind + " (" + what + " expected)");
}

/// Whether `path` is a regular file (links followed), for readers that skip what is not.
inline bool is_regular_file(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace ambfplus
