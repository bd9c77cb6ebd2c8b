#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

/// Base of every error the engine raises on purpose.
class AMBFPLUS_API Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A scene or data file that cannot be used: names the file, the key or line, and what was
/// expected.
class AMBFPLUS_API ConfigError : public Error {
 public:
  ConfigError(const std::string& file, const std::string& reason)
      : Error(file.empty() ? reason : file + ": " + reason), file_(file) {}
  /// The file at fault ("" when the error is not tied to one).
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

/// A file the scene refers to does not exist.
class AMBFPLUS_API AssetNotFound : public Error {
 public:
  explicit AssetNotFound(const std::string& path, const std::string& context = "")
      : Error((context.empty() ? std::string() : context + ": ") + "file not found: " + path),
        path_(path),
        tried_{path} {}
  /// None of the places a file was looked for holds it; the message lists them all.
  AssetNotFound(const std::vector<std::string>& tried, const std::string& context)
      : Error(context + ": file not found; tried " + join(tried)),
        path_(tried.empty() ? std::string() : tried.front()),
        tried_(tried) {}
  /// The path that was looked for (the first, when several were).
  const std::string& path() const { return path_; }
  /// Every path that was looked for, in order.
  const std::vector<std::string>& tried() const { return tried_; }

 private:
  static std::string join(const std::vector<std::string>& paths) {
    std::string out;
    for (const std::string& p : paths) out += (out.empty() ? "" : ", ") + p;
    return out;
  }
  std::string path_;
  std::vector<std::string> tried_;
};

/// The renderer cannot do what was asked (no usable EGL device, shader errors, GL errors).
class AMBFPLUS_API RenderError : public Error {
 public:
  explicit RenderError(const std::string& message) : Error(message) {}
};

/// A value or argument a caller gave cannot be used (out of range, not finite, a name taken or
/// unknown): names the argument and what was expected. In Python, an ambfplus.ArgumentError,
/// which is also a ValueError.
class AMBFPLUS_API ArgumentError : public Error {
 public:
  explicit ArgumentError(const std::string& message) : Error(message) {}
};

/// An index outside what it indexes (a sensor's ray, a soft body's node). In Python, an
/// ambfplus.OutOfRange, which is also an IndexError.
class AMBFPLUS_API OutOfRange : public Error {
 public:
  explicit OutOfRange(const std::string& message) : Error(message) {}
};

/// A call that does not fit the current state (a loop started twice, a session not running).
/// In Python, an ambfplus.StateError, which is also a RuntimeError.
class AMBFPLUS_API StateError : public Error {
 public:
  explicit StateError(const std::string& message) : Error(message) {}
};

/// A resource of the system cannot be had (a socket, a port, a device file). In Python, an
/// ambfplus.ResourceError, which is also an OSError.
class AMBFPLUS_API ResourceError : public Error {
 public:
  explicit ResourceError(const std::string& message) : Error(message) {}
};

/// A plugin cannot be loaded or initialised.
class AMBFPLUS_API PluginError : public Error {
 public:
  explicit PluginError(const std::string& message) : Error(message) {}
};

}  // namespace ambfplus
