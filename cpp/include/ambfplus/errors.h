#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

namespace detail {

/// Length of the well-formed UTF-8 sequence starting at s[i] (1 to 4), or 0 when none starts there.
inline std::size_t utf8_sequence_length(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;  // no overlong forms
    if (c == 0xED) hi = 0x9F;  // no surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;  // nothing beyond U+10FFFF
  } else {
    return 0;
  }
  if (i + n > s.size() || byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return n;
}

/// Offset of the first byte of s that is not valid UTF-8, or s.size() when all of it is.
inline std::size_t utf8_error_offset(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t n = utf8_sequence_length(s, i);
    if (n == 0) return i;
    i += n;
  }
  return i;
}

/// s with every byte that is not valid UTF-8 written as \xNN, so that a message quoting a
/// broken file still reaches Python as text.
inline std::string printable_utf8(const std::string& s) {
  if (utf8_error_offset(s) == s.size()) return s;
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t n = utf8_sequence_length(s, i);
    if (n > 0) {
      out.append(s, i, n);
      i += n;
      continue;
    }
    const auto c = static_cast<unsigned char>(s[i++]);
    out += "\\x";
    out += kHex[c >> 4];
    out += kHex[c & 15];
  }
  return out;
}

}  // namespace detail

/// Base of every error the engine raises on purpose. Its message is always valid UTF-8 (bytes
/// that are not are escaped as \xNN).
class AMBFPLUS_API Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message)
      : std::runtime_error(detail::printable_utf8(message)) {}
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

/// An argument or option of the wrong type, or a keyword option that does not exist (the message
/// names it and the known ones). In Python, an ambfplus.ArgumentTypeError, which is an
/// ArgumentError that is also a TypeError (as Python's own unexpected keywords are).
class AMBFPLUS_API ArgumentTypeError : public ArgumentError {
 public:
  explicit ArgumentTypeError(const std::string& message) : ArgumentError(message) {}
};

/// A name or key that names nothing where it was looked up (an object of a world, a label). In
/// Python, an ambfplus.NotFound, which is also a KeyError.
class AMBFPLUS_API NotFound : public Error {
 public:
  explicit NotFound(const std::string& message) : Error(message) {}
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
