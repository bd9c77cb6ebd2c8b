// A strict reading of a PLY file's structure (the format of Greg Turk's public description:
// a text header of element and property declarations, then rows as text or binary), done before
// the file is handed to assimp.

#include "io/ply_check.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

#include "ambfplus/errors.h"

namespace ambfplus::io {
namespace {

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct ScalarType {
  int bytes = 0;
  bool integer = true;
  bool is_signed = true;
};

const std::map<std::string, ScalarType>& scalar_types() {
  static const std::map<std::string, ScalarType> types = {
      {"char", {1, true, true}},     {"int8", {1, true, true}},     {"uchar", {1, true, false}},
      {"uint8", {1, true, false}},   {"short", {2, true, true}},    {"int16", {2, true, true}},
      {"ushort", {2, true, false}},  {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"int32", {4, true, true}},    {"uint", {4, true, false}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},   {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}},
  };
  return types;
}

struct Property {
  std::string name;
  ScalarType type;
  bool list = false;
  ScalarType count_type;  // lists only
};

struct Element {
  std::string name;
  std::int64_t count = 0;
  std::vector<Property> properties;
  int header_line = 0;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body = 0;  // offset of the first byte after end_header's line
  int body_line = 0;     // line number of the body's first line
};

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

ScalarType scalar_type(const std::string& path, int line, const std::string& name) {
  const auto it = scalar_types().find(name);
  if (it == scalar_types().end()) {
    throw ConfigError(path, "line " + std::to_string(line) + ": unknown PLY type '" + name +
                                "' (expected char, uchar, short, ushort, int, uint, float or "
                                "double, or their sized names)");
  }
  return it->second;
}

Header read_header(const std::string& path, const std::string& bytes) {
  Header h;
  std::size_t pos = 0;
  int line_no = 0;
  bool format_seen = false;
  while (true) {
    if (pos >= bytes.size()) {
      throw ConfigError(path, "the PLY header has no 'end_header' line (it ends at line " +
                                  std::to_string(line_no) + ")");
    }
    const std::size_t end = bytes.find('\n', pos);
    std::string line = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> w = words(line);
    const std::string where = "line " + std::to_string(line_no) + ": ";
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") throw ConfigError(path, "line 1: expected 'ply'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (!format_seen) throw ConfigError(path, where + "end_header before any 'format' line");
      h.body = pos;
      h.body_line = line_no + 1;
      return h;
    }
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") {
        throw ConfigError(path, where +
                                    "expected 'format ascii|binary_little_endian|"
                                    "binary_big_endian 1.0', got '" +
                                    line + "'");
      }
      if (w[1] == "ascii") {
        h.format = Format::kAscii;
      } else if (w[1] == "binary_little_endian") {
        h.format = Format::kBinaryLittle;
      } else if (w[1] == "binary_big_endian") {
        h.format = Format::kBinaryBig;
      } else {
        throw ConfigError(path, where + "unknown PLY format '" + w[1] + "'");
      }
      format_seen = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) throw ConfigError(path, where + "expected 'element <name> <count>'");
      char* stop = nullptr;
      errno = 0;
      const long long count = std::strtoll(w[2].c_str(), &stop, 10);
      if (*stop != '\0' || errno == ERANGE || count < 0 || count > (1ll << 31)) {
        throw ConfigError(path, where + "element '" + w[1] + "': expected a count 0.." +
                                    std::to_string(1ll << 31) + ", got '" + w[2] + "'");
      }
      h.elements.push_back(Element{w[1], count, {}, line_no});
    } else if (w[0] == "property") {
      if (h.elements.empty()) throw ConfigError(path, where + "a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        p.list = true;
        p.count_type = scalar_type(path, line_no, w[2]);
        p.type = scalar_type(path, line_no, w[3]);
        p.name = w[4];
        if (!p.count_type.integer) {
          throw ConfigError(path, where + "a list's count type must be an integer type");
        }
      } else if (w.size() == 3) {
        p.type = scalar_type(path, line_no, w[1]);
        p.name = w[2];
      } else {
        throw ConfigError(path, where +
                                    "expected 'property <type> <name>' or 'property list "
                                    "<count type> <type> <name>', got '" +
                                    line + "'");
      }
      h.elements.back().properties.push_back(p);
    } else {
      throw ConfigError(path, where + "unknown PLY header line '" + line +
                                  "' (is the 'end_header' line missing?)");
    }
  }
}

// The vertex indices of faces (and triangle strips, where -1 restarts a strip) must name
// vertices that exist.
bool is_index_list(const Element& e, const Property& p) {
  return p.list && (e.name == "face" || e.name == "tristrips") &&
         (p.name == "vertex_indices" || p.name == "vertex_index");
}

struct IndexCheck {
  const std::string& path;
  std::int64_t vertices;

  void operator()(const Element& e, double index, const std::string& where) const {
    if (e.name == "tristrips" && index == -1) return;
    if (!(index >= 0 && index < static_cast<double>(vertices))) {
      throw ConfigError(path, where + "element '" + e.name + "' names vertex " +
                                  std::to_string(static_cast<long long>(index)) +
                                  " but there are " + std::to_string(vertices) + " vertices");
    }
  }
};

bool fits(const ScalarType& t, double v) {
  if (!t.integer) return true;  // non-finite coordinates are caught after loading
  if (v != std::floor(v)) return false;
  const double bits = 8.0 * t.bytes;
  const double lo = t.is_signed ? -std::pow(2.0, bits - 1) : 0;
  const double hi = t.is_signed ? std::pow(2.0, bits - 1) - 1 : std::pow(2.0, bits) - 1;
  return v >= lo && v <= hi;
}

void check_ascii(const std::string& path, const std::string& bytes, const Header& h,
                 const IndexCheck& index_check) {
  std::size_t pos = h.body;
  int line_no = h.body_line - 1;
  std::string line;
  auto next_nonblank = [&]() {
    while (pos < bytes.size()) {
      const std::size_t end = bytes.find('\n', pos);
      line = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
      pos = end == std::string::npos ? bytes.size() : end + 1;
      ++line_no;
      if (line.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  };
  for (const Element& e : h.elements) {
    for (std::int64_t row = 0; row < e.count; ++row) {
      if (!next_nonblank()) {
        throw ConfigError(path, "the file ends after " + std::to_string(row) + " of the " +
                                    std::to_string(e.count) + " rows of element '" + e.name +
                                    "' (declared on line " + std::to_string(e.header_line) + ")");
      }
      const std::string where = "line " + std::to_string(line_no) + ": ";
      const std::vector<std::string> w = words(line);
      std::size_t t = 0;
      auto number = [&](const ScalarType& type, const std::string& what) {
        if (t >= w.size()) {
          throw ConfigError(path, where + "row " + std::to_string(row) + " of element '" + e.name +
                                      "' ends before its " + what);
        }
        const std::string& token = w[t++];
        char* stop = nullptr;
        const double v = std::strtod(token.c_str(), &stop);
        if (token.empty() || *stop != '\0' || !fits(type, v)) {
          throw ConfigError(path, where + "element '" + e.name + "', " + what + ": expected " +
                                      (type.integer ? "an integer of its type" : "a number") +
                                      ", got '" + token + "'");
        }
        return v;
      };
      for (const Property& p : e.properties) {
        if (!p.list) {
          number(p.type, "property '" + p.name + "'");
          continue;
        }
        const double n = number(p.count_type, "count of list '" + p.name + "'");
        if (n < 0 || n > static_cast<double>(w.size() - t)) {
          throw ConfigError(path, where + "element '" + e.name + "', list '" + p.name +
                                      "' has count " + w[t - 1] + " but the line holds " +
                                      std::to_string(w.size() - t) + " more values");
        }
        if (is_index_list(e, p) && n == 0) {
          throw ConfigError(path, where + "element '" + e.name + "' has a face of no vertices");
        }
        for (int k = 0; k < static_cast<int>(n); ++k) {
          const double v = number(p.type, "list '" + p.name + "'");
          if (is_index_list(e, p)) index_check(e, v, where);
        }
      }
      if (t != w.size()) {
        throw ConfigError(path, where + "row " + std::to_string(row) + " of element '" + e.name +
                                    "' has " + std::to_string(w.size()) + " values, expected " +
                                    std::to_string(t) + " ('" + line + "')");
      }
    }
  }
  if (next_nonblank()) {
    throw ConfigError(path, "line " + std::to_string(line_no) +
                                ": more data after the rows the header declares ('" + line +
                                "'): the header's counts do not describe the file");
  }
}

double read_binary(const char* p, const ScalarType& t, bool big_endian) {
  unsigned char b[8];
  std::memcpy(b, p, t.bytes);
  if (big_endian) std::reverse(b, b + t.bytes);
  switch (t.bytes) {
    case 1:
      return t.is_signed ? double(static_cast<std::int8_t>(b[0])) : double(b[0]);
    case 2: {
      std::uint16_t u;
      std::memcpy(&u, b, 2);
      return t.is_signed ? double(static_cast<std::int16_t>(u)) : double(u);
    }
    case 4: {
      if (!t.integer) {
        float f;
        std::memcpy(&f, b, 4);
        return f;
      }
      std::uint32_t u;
      std::memcpy(&u, b, 4);
      return t.is_signed ? double(static_cast<std::int32_t>(u)) : double(u);
    }
    default: {
      double d;
      std::memcpy(&d, b, 8);
      return d;
    }
  }
}

void check_binary(const std::string& path, const std::string& bytes, const Header& h,
                  const IndexCheck& index_check) {
  const bool big = h.format == Format::kBinaryBig;
  std::size_t pos = h.body;
  for (const Element& e : h.elements) {
    for (std::int64_t row = 0; row < e.count; ++row) {
      const std::string where = "byte " + std::to_string(pos) + ": ";
      auto need = [&](std::size_t n) {
        if (bytes.size() - pos < n) {
          throw ConfigError(path, "the file ends inside row " + std::to_string(row) + " of the " +
                                      std::to_string(e.count) + " rows of element '" + e.name +
                                      "' (declared on line " + std::to_string(e.header_line) + ")");
        }
      };
      for (const Property& p : e.properties) {
        if (!p.list) {
          need(p.type.bytes);
          pos += p.type.bytes;
          continue;
        }
        need(p.count_type.bytes);
        const double n = read_binary(bytes.data() + pos, p.count_type, big);
        pos += p.count_type.bytes;
        if (n < 0) {
          throw ConfigError(
              path, where + "element '" + e.name + "', list '" + p.name + "' has a negative count");
        }
        if (is_index_list(e, p) && n == 0) {
          throw ConfigError(path, where + "element '" + e.name + "' has a face of no vertices");
        }
        const std::size_t items = static_cast<std::size_t>(n);
        need(items * p.type.bytes);
        if (is_index_list(e, p)) {
          for (std::size_t k = 0; k < items; ++k) {
            index_check(e, read_binary(bytes.data() + pos + k * p.type.bytes, p.type, big), where);
          }
        }
        pos += items * p.type.bytes;
      }
    }
  }
  if (pos != bytes.size()) {
    throw ConfigError(path, "byte " + std::to_string(pos) + ": " +
                                std::to_string(bytes.size() - pos) +
                                " bytes follow the rows the header declares: the header's counts "
                                "do not describe the file");
  }
}

}  // namespace

bool looks_like_ply(const std::string& bytes) {
  return bytes.rfind("ply\n", 0) == 0 || bytes.rfind("ply\r\n", 0) == 0;
}

void check_ply(const std::string& path, const std::string& bytes) {
  const Header h = read_header(path, bytes);
  const Element* vertex = nullptr;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") vertex = &e;
  }
  if (vertex == nullptr) throw ConfigError(path, "the PLY header declares no 'vertex' element");
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const Property& p : vertex->properties) found = found || (!p.list && p.name == axis);
    if (!found) {
      throw ConfigError(path, "line " + std::to_string(vertex->header_line) +
                                  ": element 'vertex' has no property '" + axis + "'");
    }
  }
  const IndexCheck index_check{path, vertex->count};
  if (h.format == Format::kAscii) {
    check_ascii(path, bytes, h, index_check);
  } else {
    check_binary(path, bytes, h, index_check);
  }
}

}  // namespace ambfplus::io
