// NRRD reading and writing (the format of 3D Slicer volumes and segmentations), from the format's
// public specification: a text header of "field: value" and "key:=value" lines, a blank line, then
// raw or gzip data (or a detached data file).

#include <zlib.h>
#include <cerrno>
#include <cstring>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/volume/volume_io.h"
#include "util/files.h"
#include "util/strings.h"
#include "volume/grid_access.h"

namespace fs = std::filesystem;

namespace ambfplus {
namespace {

enum class Scalar { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat, kDouble };

std::size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::kInt8:
    case Scalar::kUInt8:
      return 1;
    case Scalar::kInt16:
    case Scalar::kUInt16:
      return 2;
    case Scalar::kInt32:
    case Scalar::kUInt32:
    case Scalar::kFloat:
      return 4;
    case Scalar::kDouble:
      return 8;
  }
  return 1;
}

bool is_integer(Scalar s) { return s != Scalar::kFloat && s != Scalar::kDouble; }

Scalar parse_type(const std::string& path, const std::string& value) {
  static const std::map<std::string, Scalar> types = {
      {"signed char", Scalar::kInt8},
      {"int8", Scalar::kInt8},
      {"int8_t", Scalar::kInt8},
      {"uchar", Scalar::kUInt8},
      {"unsigned char", Scalar::kUInt8},
      {"uint8", Scalar::kUInt8},
      {"uint8_t", Scalar::kUInt8},
      {"short", Scalar::kInt16},
      {"short int", Scalar::kInt16},
      {"signed short", Scalar::kInt16},
      {"signed short int", Scalar::kInt16},
      {"int16", Scalar::kInt16},
      {"int16_t", Scalar::kInt16},
      {"ushort", Scalar::kUInt16},
      {"unsigned short", Scalar::kUInt16},
      {"unsigned short int", Scalar::kUInt16},
      {"uint16", Scalar::kUInt16},
      {"uint16_t", Scalar::kUInt16},
      {"int", Scalar::kInt32},
      {"signed int", Scalar::kInt32},
      {"int32", Scalar::kInt32},
      {"int32_t", Scalar::kInt32},
      {"uint", Scalar::kUInt32},
      {"unsigned int", Scalar::kUInt32},
      {"uint32", Scalar::kUInt32},
      {"uint32_t", Scalar::kUInt32},
      {"float", Scalar::kFloat},
      {"double", Scalar::kDouble},
  };
  auto it = types.find(to_lower(value));
  if (it == types.end()) {
    throw ConfigError(path, "field 'type': unsupported type '" + value +
                                "' (expected 8-, 16- or 32-bit integers, float or double)");
  }
  return it->second;
}

// Integer range of a scalar type (the range a Slicer label value must lie in).
std::pair<double, double> scalar_range(Scalar s) {
  switch (s) {
    case Scalar::kInt8:
      return {-128, 127};
    case Scalar::kUInt8:
      return {0, 255};
    case Scalar::kInt16:
      return {-32768, 32767};
    case Scalar::kUInt16:
      return {0, 65535};
    case Scalar::kInt32:
      return {-2147483648.0, 2147483647.0};
    case Scalar::kUInt32:
      return {0, 4294967295.0};
    case Scalar::kFloat:
    case Scalar::kDouble:
      break;
  }
  return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
}

struct Header {
  std::map<std::string, std::string> fields;      // lower-case field names
  std::map<std::string, int> field_lines;         // where each field was given
  std::map<std::string, std::string> key_values;  // key:=value pairs
  std::size_t data_offset = 0;                    // bytes to the data in the same file
  bool ended = false;                             // a blank line closed the header

  bool has(const std::string& name) const { return fields.count(name) > 0; }
  /// "field 'sizes' (line 4)", for messages.
  std::string where(const std::string& name) const {
    auto it = field_lines.find(name);
    return "field '" + name + "'" +
           (it == field_lines.end() ? "" : " (line " + std::to_string(it->second) + ")");
  }
};

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

Header read_header(const std::string& path, const std::string& bytes) {
  Header h;
  std::size_t pos = 0;
  int line_no = 0;
  auto next_line = [&](std::string& line) {
    if (pos >= bytes.size()) return false;
    const std::size_t end = bytes.find('\n', pos);
    line = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  std::string line;
  if (!next_line(line) || line.rfind("NRRD000", 0) != 0) {
    throw ConfigError(path, "line 1: not an NRRD file (expected the magic 'NRRD000x')");
  }
  while (next_line(line)) {
    if (line.empty()) {  // the header ends at the first blank line
      h.ended = true;
      break;
    }
    require_utf8(path, line_no, line);
    if (line[0] == '#') continue;
    const std::size_t kv = line.find(":=");
    if (kv != std::string::npos) {
      h.key_values[line.substr(0, kv)] = line.substr(kv + 2);
      continue;
    }
    const std::size_t colon = line.find(": ");
    if (colon == std::string::npos) {
      throw ConfigError(path, "line " + std::to_string(line_no) +
                                  ": expected 'field: value' or 'key:=value', got '" + line + "'");
    }
    const std::string name = to_lower(line.substr(0, colon));
    if (h.fields.count(name)) {
      throw ConfigError(path, "line " + std::to_string(line_no) + ": field '" + name +
                                  "' is given twice (first on line " +
                                  std::to_string(h.field_lines[name]) + ")");
    }
    h.fields[name] = trim(line.substr(colon + 2));
    h.field_lines[name] = line_no;
  }
  h.data_offset = pos;
  return h;
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  std::string w;
  while (in >> w) out.push_back(w);
  return out;
}

// A whole word as an integer in [lo, hi]; what it is and what was expected go in the message.
long long parse_integer(const std::string& path, const std::string& what, const std::string& text,
                        long long lo, long long hi) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || v < lo || v > hi) {
    throw ConfigError(path, what + ": expected an integer in " + std::to_string(lo) + ".." +
                                std::to_string(hi) + ", got '" + text + "'");
  }
  return v;
}

// A whole word as a finite number.
double parse_finite(const std::string& path, const std::string& what, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
    throw ConfigError(path, what + ": expected a finite number, got '" + text + "'");
  }
  return v;
}

// "(a,b,c) (d,e,f) none ..." -> vectors (NaN for none)
std::vector<Eigen::Vector3d> parse_vectors(const std::string& path, const std::string& field,
                                           const std::string& value) {
  std::vector<Eigen::Vector3d> out;
  std::size_t pos = 0;
  while (pos < value.size()) {
    while (pos < value.size() && value[pos] == ' ') ++pos;
    if (pos >= value.size()) break;
    if (value.compare(pos, 4, "none") == 0) {
      out.push_back(Eigen::Vector3d::Constant(std::nan("")));
      pos += 4;
      continue;
    }
    if (value[pos] != '(') {
      throw ConfigError(path, field + ": expected (x,y,z) vectors, got '" + value + "'");
    }
    const std::size_t close = value.find(')', pos);
    if (close == std::string::npos) {
      throw ConfigError(path, field + ": unbalanced parenthesis in '" + value + "'");
    }
    const std::string inside = value.substr(pos + 1, close - pos - 1);
    std::vector<std::string> parts;
    std::istringstream in(inside);
    for (std::string part; std::getline(in, part, ',');) parts.push_back(trim(part));
    if (parts.size() != 3) {
      throw ConfigError(path, field + ": expected 3 numbers in '(" + inside + ")'");
    }
    Eigen::Vector3d v;
    for (int c = 0; c < 3; ++c) v[c] = parse_finite(path, field, parts[c]);
    out.push_back(v);
    pos = close + 1;
  }
  return out;
}

std::string read_file(const std::string& path, const char* what) {
  require_regular_file(path, what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw ConfigError(path, std::string("cannot read: ") + std::strerror(errno));
  return s.str();
}

// Every byte of the gzip stream (one member or several, as concatenated gzip files are), but no
// more than `limit`: a stream that inflates to more is reported as such without being kept.
std::string gunzip(const std::string& path, const char* data, std::size_t size, std::size_t limit) {
  std::string out;
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) throw ConfigError(path, "cannot start gzip decoding");
  std::size_t consumed = 0;
  int rc = Z_OK;
  char chunk[1 << 16];
  while (true) {
    const std::size_t in_now = std::min<std::size_t>(size - consumed, 1u << 30);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data + consumed));
    z.avail_in = static_cast<uInt>(in_now);
    z.next_out = reinterpret_cast<Bytef*>(chunk);
    z.avail_out = sizeof(chunk);
    rc = inflate(&z, Z_NO_FLUSH);
    consumed += in_now - z.avail_in;
    out.append(chunk, sizeof(chunk) - z.avail_out);
    if (out.size() > limit) break;
    if (rc == Z_STREAM_END) {
      if (consumed == size) break;
      // Another member follows, or trailing bytes that are not gzip.
      if (size - consumed < 2 || static_cast<unsigned char>(data[consumed]) != 0x1f ||
          static_cast<unsigned char>(data[consumed + 1]) != 0x8b) {
        inflateEnd(&z);
        throw ConfigError(path, std::to_string(size - consumed) +
                                    " bytes follow the end of the gzip data (expected none)");
      }
      inflateReset(&z);
      continue;
    }
    if (rc != Z_OK) break;
    if (consumed == size && z.avail_out != 0) {
      rc = Z_BUF_ERROR;  // the input ended inside the stream
      break;
    }
  }
  const std::string message = z.msg ? z.msg : "";
  inflateEnd(&z);
  if (out.size() > limit) return out;
  if (rc != Z_STREAM_END) {
    throw ConfigError(path, "gzip data is corrupt or cut short after " +
                                std::to_string(out.size()) + " decoded bytes (zlib: " +
                                (!message.empty()    ? message
                                 : rc == Z_BUF_ERROR ? std::string("unexpected end of the stream")
                                                     : "error " + std::to_string(rc)) +
                                ")");
  }
  return out;
}

template <typename T>
double read_as_double(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

double value_at(Scalar s, const char* p) {
  switch (s) {
    case Scalar::kInt8:
      return read_as_double<std::int8_t>(p);
    case Scalar::kUInt8:
      return read_as_double<std::uint8_t>(p);
    case Scalar::kInt16:
      return read_as_double<std::int16_t>(p);
    case Scalar::kUInt16:
      return read_as_double<std::uint16_t>(p);
    case Scalar::kInt32:
      return read_as_double<std::int32_t>(p);
    case Scalar::kUInt32:
      return read_as_double<std::uint32_t>(p);
    case Scalar::kFloat:
      return read_as_double<float>(p);
    case Scalar::kDouble:
      return read_as_double<double>(p);
  }
  return 0;
}

// What the header says the data is: its type, axes and how it is stored.
struct Layout {
  Scalar type = Scalar::kUInt8;
  std::string type_name;
  int dimension = 3;
  int layers = 1;  // the first axis of a 4D layered segmentation
  std::array<int, 3> shape{1, 1, 1};
  std::size_t voxels = 0;
  std::size_t bytes = 0;  // of the decoded data
  std::string encoding;
  bool big_endian = false;
};

const std::string& required(const std::string& path, const Header& h, const std::string& name) {
  auto it = h.fields.find(name);
  if (it == h.fields.end()) throw ConfigError(path, "missing required field '" + name + "'");
  return it->second;
}

Layout read_layout(const std::string& path, const Header& h) {
  Layout l;
  l.type_name = required(path, h, "type");
  l.type = parse_type(path, l.type_name);
  const std::string dimension = required(path, h, "dimension");
  if (dimension != "3" && dimension != "4") {
    throw ConfigError(path, h.where("dimension") +
                                ": expected 3 (or 4 for a layered segmentation), got '" +
                                dimension + "'");
  }
  l.dimension = dimension == "3" ? 3 : 4;
  const std::vector<std::string> size_words = words(required(path, h, "sizes"));
  if (static_cast<int>(size_words.size()) != l.dimension) {
    throw ConfigError(path, h.where("sizes") + ": expected " + std::to_string(l.dimension) +
                                " sizes, got '" + h.fields.at("sizes") + "'");
  }
  std::vector<int> sizes;
  for (const std::string& w : size_words) {
    sizes.push_back(static_cast<int>(parse_integer(path, h.where("sizes"), w, 1, 8192)));
  }
  l.layers = l.dimension == 4 ? sizes[0] : 1;
  l.shape = l.dimension == 4 ? std::array<int, 3>{sizes[1], sizes[2], sizes[3]}
                             : std::array<int, 3>{sizes[0], sizes[1], sizes[2]};
  l.voxels = std::size_t(l.shape[0]) * l.shape[1] * l.shape[2];
  l.bytes = l.voxels * l.layers * scalar_size(l.type);
  l.encoding = to_lower(h.has("encoding") ? h.fields.at("encoding") : "raw");
  if (l.encoding == "gz") l.encoding = "gzip";
  if (l.encoding != "raw" && l.encoding != "gzip") {
    throw ConfigError(path, h.where("encoding") + ": '" + l.encoding +
                                "' is not supported (expected raw or gzip)");
  }
  if (h.has("endian")) {
    const std::string endian = to_lower(h.fields.at("endian"));
    if (endian != "little" && endian != "big") {
      throw ConfigError(path, h.where("endian") + ": expected little or big, got '" +
                                  h.fields.at("endian") + "'");
    }
    l.big_endian = endian == "big";
  }
  return l;
}

// Skips `lines` lines of the data, as the header's `line skip` asks.
std::size_t skip_lines(const std::string& source, const Header& h, const char* data,
                       std::size_t available, long long lines) {
  std::size_t pos = 0;
  for (long long n = 0; n < lines; ++n) {
    const void* nl = std::memchr(data + pos, '\n', available - pos);
    if (nl == nullptr) {
      throw ConfigError(source, h.where("line skip") + ": asks to skip " + std::to_string(lines) +
                                    " lines but the data has only " + std::to_string(n));
    }
    pos = static_cast<const char*>(nl) - data + 1;
  }
  return pos;
}

// The decoded data: exactly the bytes the header promises, in the machine's byte order.
std::string read_payload(const std::string& path, const std::string& file, const Header& h,
                         const Layout& l) {
  std::string detached;
  const char* data = file.data() + h.data_offset;
  std::size_t available = file.size() - h.data_offset;
  std::string source = path;
  for (const char* key : {"data file", "datafile"}) {
    if (!h.has(key)) continue;
    const std::string name = h.fields.at(key);
    if (name.rfind("LIST", 0) == 0 || name.find('%') != std::string::npos) {
      throw ConfigError(path, h.where(key) + ": data split over several files ('" + name +
                                  "') is not supported (expected one file)");
    }
    fs::path p = name;
    if (p.is_relative()) p = fs::path(path).parent_path() / p;
    source = p.string();
    detached = read_file(source, "the NRRD's data file");
    data = detached.data();
    available = detached.size();
  }
  if (source == path && !h.ended) {
    throw ConfigError(path, "the header does not end with a blank line, so the file holds no data");
  }
  const long long line_skip =
      h.has("line skip") ? parse_integer(path, h.where("line skip"), h.fields.at("line skip"), 0,
                                         std::numeric_limits<int>::max())
                         : 0;
  const std::size_t after_lines = skip_lines(source, h, data, available, line_skip);
  data += after_lines;
  available -= after_lines;
  const long long byte_skip =
      h.has("byte skip") ? parse_integer(path, h.where("byte skip"), h.fields.at("byte skip"), -1,
                                         std::numeric_limits<long long>::max() / 2)
                         : 0;
  if (byte_skip == -1 && l.encoding != "raw") {
    throw ConfigError(path, h.where("byte skip") + ": -1 (data at the end) needs raw encoding");
  }
  const std::string sizes = "sizes " + h.fields.at("sizes") + " of " + l.type_name;
  std::string decoded;
  if (l.encoding == "gzip") {
    // The byte skip applies to the decoded data.
    const std::size_t skip = static_cast<std::size_t>(byte_skip);
    decoded = gunzip(source, data, available, skip + l.bytes);
    if (decoded.size() != skip + l.bytes) {
      throw ConfigError(
          source, "gzip data decodes to " +
                      (decoded.size() > skip + l.bytes ? "more than " : std::string()) +
                      std::to_string(decoded.size()) + " bytes but the header needs " +
                      std::to_string(l.bytes) +
                      (skip ? " after skipping " + std::to_string(skip) : std::string()) + " (" +
                      sizes + ")");
    }
    decoded.erase(0, skip);
  } else {
    if (byte_skip == -1) {
      if (available < l.bytes) {
        throw ConfigError(source, "raw data holds " + std::to_string(available) +
                                      " bytes but the header needs " + std::to_string(l.bytes) +
                                      " (" + sizes + ")");
      }
      data += available - l.bytes;  // byte skip -1: the data is the file's last bytes
      available = l.bytes;
    } else if (static_cast<unsigned long long>(byte_skip) > available) {
      throw ConfigError(source, h.where("byte skip") + ": " + std::to_string(byte_skip) +
                                    " is beyond the " + std::to_string(available) +
                                    " bytes of data");
    } else {
      data += byte_skip;
      available -= static_cast<std::size_t>(byte_skip);
    }
    if (available != l.bytes) {
      throw ConfigError(source, "raw data holds " + std::to_string(available) +
                                    " bytes but the header needs " + std::to_string(l.bytes) +
                                    " (" + sizes + ")");
    }
    decoded.assign(data, l.bytes);
  }
  if (l.big_endian && scalar_size(l.type) > 1) {
    const std::size_t w = scalar_size(l.type);
    for (std::size_t v = 0; v < decoded.size(); v += w) {
      std::reverse(&decoded[v], &decoded[v] + w);
    }
  }
  return decoded;
}

// Where the grid sits: its physical size, the patient-from-volume pose, and whether k is
// reversed to make a left-handed grid right-handed.
struct Geometry {
  Eigen::Vector3d dimensions = Eigen::Vector3d::Ones();
  Eigen::Matrix4d patient = Eigen::Matrix4d::Identity();
  bool flip_k = false;
};

double length_unit(const std::string& path, const Header& h) {
  if (!h.has("space units")) return 0.001;  // millimetres unless said otherwise
  static const std::map<std::string, double> units = {
      {"mm", 0.001}, {"m", 1.0}, {"cm", 0.01}, {"um", 1e-6}, {"\xc2\xb5m", 1e-6}};
  double unit = 0;
  for (std::string w : words(h.fields.at("space units"))) {
    w.erase(std::remove(w.begin(), w.end(), '"'), w.end());
    auto it = units.find(w);
    if (it == units.end() || (unit != 0 && it->second != unit)) {
      throw ConfigError(path, h.where("space units") + ": expected one length unit (mm, m, cm, " +
                                  "um) for every axis, got '" + h.fields.at("space units") + "'");
    }
    unit = it->second;
  }
  return unit != 0 ? unit : 0.001;
}

Geometry read_geometry(const std::string& path, const Header& h, const Layout& l) {
  // Space directions give the voxel axes, space origin the first voxel's centre.
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const double unit = length_unit(path, h);
  if (h.has("space directions")) {
    const std::string what = h.where("space directions");
    std::vector<Eigen::Vector3d> v = parse_vectors(path, what, h.fields.at("space directions"));
    if (l.dimension == 4 && v.size() == 4 && std::isnan(v[0][0])) v.erase(v.begin());
    if (v.size() != 3 || !v[0].allFinite() || !v[1].allFinite() || !v[2].allFinite()) {
      throw ConfigError(path, what + ": expected a vector for each spatial axis" +
                                  (l.dimension == 4 ? " after 'none' for the layers" : "") +
                                  ", got '" + h.fields.at("space directions") + "'");
    }
    for (int a = 0; a < 3; ++a) directions.col(a) = v[a];
  } else if (h.has("spacings")) {
    const std::string what = h.where("spacings");
    const auto w = words(h.fields.at("spacings"));
    if (static_cast<int>(w.size()) != l.dimension) {
      throw ConfigError(path, what + ": expected " + std::to_string(l.dimension) +
                                  " spacings, got '" + h.fields.at("spacings") + "'");
    }
    for (int a = 0; a < 3; ++a) {
      const double s = parse_finite(path, what, w[a + l.dimension - 3]);
      if (!(s > 0)) {
        throw ConfigError(path, what + ": spacing " + w[a + l.dimension - 3] + " of axis " +
                                    std::to_string(a) + " must be > 0");
      }
      directions(a, a) = s;
    }
  }
  if (h.has("space origin")) {
    const auto v = parse_vectors(path, h.where("space origin"), h.fields.at("space origin"));
    if (v.size() != 1 || !v[0].allFinite()) {
      throw ConfigError(path, h.where("space origin") + ": expected one (x,y,z) vector");
    }
    origin = v[0];
  }
  directions *= unit;
  origin *= unit;
  Eigen::Vector3d spacing;
  for (int a = 0; a < 3; ++a) spacing[a] = directions.col(a).norm();
  if (!(spacing.minCoeff() > 0) || !spacing.allFinite()) {
    throw ConfigError(path, h.where("space directions") + ": a direction has zero length");
  }
  // Nearest rotation to the (possibly slightly sheared) axes; a left-handed grid is made
  // right-handed by reversing k.
  Eigen::Matrix3d axes = directions * spacing.cwiseInverse().asDiagonal();
  if (std::abs(axes.determinant()) < 1e-6) {
    throw ConfigError(path, h.where("space directions") + ": the axes are (nearly) parallel");
  }
  Geometry g;
  g.flip_k = axes.determinant() < 0;
  if (g.flip_k) {
    origin += directions.col(2) * (l.shape[2] - 1);
    axes.col(2) = -axes.col(2);
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(axes, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  g.dimensions = spacing.cwiseProduct(Eigen::Vector3d(l.shape[0], l.shape[1], l.shape[2]));
  g.patient.topLeftCorner<3, 3>() = rotation;
  g.patient.topRightCorner<3, 1>() = origin + rotation * (g.dimensions / 2 - spacing / 2);
  if (!g.patient.allFinite() || !g.dimensions.allFinite()) {
    throw ConfigError(path, "space directions and origin give a non-finite geometry");
  }
  return g;
}

// The decoded samples, read by layer and voxel (i, j, k) of the right-handed grid.
struct Samples {
  const Layout& layout;
  const char* data;
  bool flip_k;

  double at(int layer, int i, int j, int k) const {
    const int kk = flip_k ? layout.shape[2] - 1 - k : k;
    const std::size_t v =
        static_cast<std::size_t>(i) +
        std::size_t(layout.shape[0]) * (std::size_t(j) + std::size_t(layout.shape[1]) * kk);
    return value_at(layout.type, data + (v * layout.layers + layer) * scalar_size(layout.type));
  }
  double linear(std::size_t n) const {
    return value_at(layout.type, data + n * scalar_size(layout.type));
  }
};

struct Segment {
  int index = 0;
  std::string name;
  std::array<std::uint8_t, 3> color{255, 255, 255};
  long long label_value = 1;
  int layer = 0;
};

std::vector<Segment> read_segments(const std::string& path, const Header& h, const Layout& l) {
  std::map<int, Segment> by_index;
  static const std::regex key("Segment([0-9]+)_(ID|Name|Color|LabelValue|Layer)");
  const auto [lowest, highest] = scalar_range(l.type);
  for (const auto& [k, v] : h.key_values) {
    std::smatch m;
    if (!std::regex_match(k, m, key)) continue;
    const std::string what = "key '" + k + "'";
    // Segment n becomes label n + 1 when label values cannot serve as ids.
    const int index =
        static_cast<int>(parse_integer(path, what + ": segment number", m[1], 0, 65534));
    Segment& s = by_index[index];
    s.index = index;
    const std::string field = m[2];
    if (field == "Name") {
      s.name = v;
    } else if (field == "Color") {
      const auto rgb = words(v);
      if (rgb.size() != 3) {
        throw ConfigError(path, what + ": expected three numbers 0..1, got '" + v + "'");
      }
      for (int c = 0; c < 3; ++c) {
        const double x = parse_finite(path, what, rgb[c]);
        s.color[c] = static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255));
      }
    } else if (field == "LabelValue") {
      s.label_value = parse_integer(path, what, trim(v), std::numeric_limits<long long>::min(),
                                    std::numeric_limits<long long>::max());
      if (is_integer(l.type) &&
          (s.label_value < std::max(1.0, lowest) || static_cast<double>(s.label_value) > highest)) {
        throw ConfigError(path, what + ": label value " + std::to_string(s.label_value) +
                                    " cannot occur in " + l.type_name + " data (expected " +
                                    std::to_string(static_cast<long long>(std::max(1.0, lowest))) +
                                    ".." + std::to_string(static_cast<long long>(highest)) + ")");
      }
    } else if (field == "Layer") {
      s.layer = static_cast<int>(parse_integer(path, what, trim(v), 0, l.layers - 1));
    }
  }
  std::vector<Segment> out;
  for (auto& [i, s] : by_index) {
    if (s.name.empty()) s.name = "Segment_" + std::to_string(i);
    out.push_back(s);
  }
  return out;
}

NrrdOptions::Kind classify(const Layout& l, const Samples& samples,
                           const std::vector<Segment>& segments) {
  if (!segments.empty()) return NrrdOptions::Kind::kSegmentation;
  if (!is_integer(l.type) || l.layers != 1) return NrrdOptions::Kind::kIntensity;
  // Integer data in 0..65535 with few distinct values is a label map.
  std::set<long> distinct;
  for (std::size_t v = 0; v < l.voxels; ++v) {
    const double x = samples.linear(v);
    if (x < 0 || x > 65535) return NrrdOptions::Kind::kIntensity;
    if (distinct.size() <= 256) distinct.insert(static_cast<long>(x));
  }
  return distinct.size() <= 256 ? NrrdOptions::Kind::kLabels : NrrdOptions::Kind::kIntensity;
}

std::shared_ptr<VolumeData> build_intensity(const std::string& path, const Layout& l,
                                            const Samples& samples, const Geometry& g,
                                            const NrrdOptions& options) {
  if (!options.threshold) {
    throw ConfigError(path, "holds intensities (type " + l.type_name +
                                "): give a threshold to segment it (e.g. 300 for bone in HU)");
  }
  if (!std::isfinite(*options.threshold)) {
    throw ArgumentError("load_nrrd: threshold must be a finite number, got " +
                        std::to_string(*options.threshold));
  }
  LabelTable table;
  table.add(Label{1, "Segmented", {255, 249, 219}, true, false});
  auto volume = std::make_shared<VolumeData>(l.shape, g.dimensions, LabelType::kUInt8, table);
  const bool wide = l.type == Scalar::kFloat || l.type == Scalar::kDouble ||
                    l.type == Scalar::kInt32 || l.type == Scalar::kUInt32;
  volume->set_intensity_type(wide ? IntensityType::kFloat32 : IntensityType::kInt16);
  auto* labels = static_cast<std::uint8_t*>(volume->label_data());
  for (int k = 0; k < l.shape[2]; ++k) {
    for (int j = 0; j < l.shape[1]; ++j) {
      for (int i = 0; i < l.shape[0]; ++i) {
        const double x = samples.at(0, i, j, k);
        if (!std::isfinite(x) || (!wide && (x < -32768 || x > 32767))) {
          throw ConfigError(path, "voxel (" + std::to_string(i) + ", " + std::to_string(j) + ", " +
                                      std::to_string(k) + ") holds " + std::to_string(x) +
                                      ", which is not a usable intensity");
        }
        const std::size_t n = volume->linear_index(i, j, k);
        if (volume->intensity_type() == IntensityType::kInt16) {
          static_cast<std::int16_t*>(volume->intensity_data())[n] = static_cast<std::int16_t>(x);
        } else {
          static_cast<float*>(volume->intensity_data())[n] = static_cast<float>(x);
        }
        labels[n] = x >= *options.threshold ? 1 : 0;
      }
    }
  }
  return volume;
}

std::shared_ptr<VolumeData> build_label_map(const std::string& path, const Layout& l,
                                            const Samples& samples, const Geometry& g) {
  if (!is_integer(l.type)) {
    throw ConfigError(path, "a label map needs an integer type, got " + l.type_name);
  }
  std::uint16_t max_id = 0;
  std::vector<bool> seen(65536, false);
  for (std::size_t v = 0; v < l.voxels; ++v) {
    const double x = samples.linear(v);
    if (x < 0 || x > 65535) {
      throw ConfigError(path, "label map value " + std::to_string(static_cast<long long>(x)) +
                                  " is outside 0..65535");
    }
    seen[static_cast<std::size_t>(x)] = true;
    max_id = std::max(max_id, static_cast<std::uint16_t>(x));
  }
  LabelTable table;
  for (int id = 1; id <= max_id; ++id) {
    if (!seen[id]) continue;
    // A colour per id that stays the same from file to file.
    const std::uint32_t hsh = static_cast<std::uint32_t>(id) * 2654435761u;
    table.add(Label{static_cast<std::uint16_t>(id),
                    "label_" + std::to_string(id),
                    {std::uint8_t(64 + (hsh >> 24) % 192), std::uint8_t(64 + (hsh >> 16) % 192),
                     std::uint8_t(64 + (hsh >> 8) % 192)},
                    true,
                    false});
  }
  auto volume = std::make_shared<VolumeData>(
      l.shape, g.dimensions, max_id > 255 ? LabelType::kUInt16 : LabelType::kUInt8, table);
  visit_labels(volume->label_type(), volume->label_data(), [&](auto* labels) {
    using T = std::remove_pointer_t<decltype(labels)>;
    for (int k = 0; k < l.shape[2]; ++k)
      for (int j = 0; j < l.shape[1]; ++j)
        for (int i = 0; i < l.shape[0]; ++i)
          labels[volume->linear_index(i, j, k)] = static_cast<T>(samples.at(0, i, j, k));
  });
  return volume;
}

// Slicer segmentation: segment s is where its layer holds its label value. In one layer with
// distinct label values those values are the ids; across layers (values repeat) the ids are the
// segment numbers + 1.
std::shared_ptr<VolumeData> build_segmentation(const std::string& path, const Layout& l,
                                               const Samples& samples, const Geometry& g,
                                               const std::vector<Segment>& segments) {
  if (segments.empty()) throw ConfigError(path, "no Segment<N>_* keys: not a segmentation");
  if (!is_integer(l.type)) throw ConfigError(path, "a segmentation needs an integer type");
  std::set<long long> values;
  bool keep_values = l.layers == 1;
  for (const Segment& s : segments) {
    keep_values = keep_values && s.label_value >= 1 && s.label_value <= 65535 &&
                  values.insert(s.label_value).second;
  }
  std::vector<std::uint16_t> ids;
  LabelTable table;
  for (const Segment& s : segments) {
    ids.push_back(static_cast<std::uint16_t>(keep_values ? s.label_value : s.index + 1));
    try {
      table.add(Label{ids.back(), s.name, s.color, true, false});
    } catch (const ArgumentError& e) {
      throw ConfigError(path, "Segment" + std::to_string(s.index) + ": " + e.what());
    }
  }
  auto volume = std::make_shared<VolumeData>(
      l.shape, g.dimensions, table.max_id() > 255 ? LabelType::kUInt16 : LabelType::kUInt8, table);
  // The label values each layer's segments declare: any other value but 0 belongs to no segment.
  std::vector<std::set<double>> declared(static_cast<std::size_t>(l.layers));
  for (const Segment& s : segments) declared[s.layer].insert(static_cast<double>(s.label_value));
  std::int64_t overlaps = 0, undeclared = 0;
  std::set<double> undeclared_values;  // the first few, for the message
  visit_labels(volume->label_type(), volume->label_data(), [&](auto* labels) {
    using T = std::remove_pointer_t<decltype(labels)>;
    for (int k = 0; k < l.shape[2]; ++k)
      for (int j = 0; j < l.shape[1]; ++j)
        for (int i = 0; i < l.shape[0]; ++i) {
          T& out = labels[volume->linear_index(i, j, k)];
          for (std::size_t n = 0; n < segments.size(); ++n) {
            const Segment& s = segments[n];
            if (samples.at(s.layer, i, j, k) != static_cast<double>(s.label_value)) continue;
            overlaps += out != 0;
            out = static_cast<T>(ids[n]);
          }
          for (int layer = 0; layer < l.layers; ++layer) {
            const double x = samples.at(layer, i, j, k);
            if (x == 0 || declared[layer].count(x) != 0) continue;
            ++undeclared;
            if (undeclared_values.size() < 6) undeclared_values.insert(x);
          }
        }
  });
  if (overlaps > 0) {
    log(LogLevel::kWarning, path + ": " + std::to_string(overlaps) +
                                " voxels belong to more than one segment; the later segment wins");
  }
  if (undeclared > 0) {
    // Slicer shows such voxels in no segment; they are kept as empty space, but said.
    std::string values;
    for (const double v : undeclared_values) {
      if (values.size() > 0 && std::count(values.begin(), values.end(), ',') == 4) {
        values += ", ...";
        break;
      }
      values += (values.empty() ? "" : ", ") + std::to_string(static_cast<long long>(v));
    }
    log(LogLevel::kWarning,
        path + ": " + std::to_string(undeclared) +
            " voxels hold a label value that no Segment<N>_LabelValue of their layer declares (" +
            values + "); they belong to no segment and load as empty (0)");
  }
  return volume;
}

}  // namespace

std::shared_ptr<VolumeData> load_nrrd(const std::string& path, const NrrdOptions& options) {
  const std::string file = read_file(path, "an NRRD file");
  const Header header = read_header(path, file);
  const Layout layout = read_layout(path, header);
  const Geometry geometry = read_geometry(path, header, layout);
  const std::vector<Segment> segments = read_segments(path, header, layout);
  const std::string payload = read_payload(path, file, header, layout);
  const Samples samples{layout, payload.data(), geometry.flip_k};

  NrrdOptions::Kind kind = options.kind;
  if (kind == NrrdOptions::Kind::kAuto) kind = classify(layout, samples, segments);
  if (layout.layers > 1 && kind != NrrdOptions::Kind::kSegmentation) {
    throw ConfigError(path,
                      "4D data is read only as a layered segmentation (Segment keys missing)");
  }
  std::shared_ptr<VolumeData> volume;
  switch (kind) {
    case NrrdOptions::Kind::kIntensity:
      volume = build_intensity(path, layout, samples, geometry, options);
      break;
    case NrrdOptions::Kind::kLabels:
      volume = build_label_map(path, layout, samples, geometry);
      break;
    default:
      volume = build_segmentation(path, layout, samples, geometry, segments);
      break;
  }
  volume->set_patient_from_volume(geometry.patient);
  volume->set_source(path);
  volume->commit();
  return volume;
}

void save_nrrd(const VolumeData& volume, const std::string& path, const std::string& what,
               bool gzip) {
  const auto& shape = volume.shape();
  const std::size_t voxels = static_cast<std::size_t>(volume.voxel_count());
  std::string type;
  const void* source = nullptr;
  std::size_t bytes = 0;
  if (what == "labels") {
    type = volume.label_type() == LabelType::kUInt8 ? "uint8" : "uint16";
    source = volume.label_data();
    bytes = voxels * (volume.label_type() == LabelType::kUInt8 ? 1 : 2);
  } else if (what == "intensity") {
    if (volume.intensity_type() == IntensityType::kNone) {
      throw ArgumentError("the volume has no intensity grid to save");
    }
    type = volume.intensity_type() == IntensityType::kInt16 ? "int16" : "float";
    source = const_cast<VolumeData&>(volume).intensity_data();
    bytes = voxels * (volume.intensity_type() == IntensityType::kInt16 ? 2 : 4);
  } else {
    throw ArgumentError("save_nrrd: what must be 'labels' or 'intensity', got '" + what + "'");
  }
  // Geometry back to millimetres in the patient frame the grid came from.
  const Eigen::Matrix4d& p = volume.patient_from_volume();
  const Eigen::Matrix3d r = p.topLeftCorner<3, 3>();
  const Eigen::Vector3d s = volume.voxel_size();
  const Eigen::Vector3d origin = p.topRightCorner<3, 1>() - r * (volume.dimensions() / 2 - s / 2);
  std::ostringstream h;
  h.precision(17);
  h << "NRRD0004\n# written by ambfplus\n"
    << "type: " << type << "\ndimension: 3\nspace: left-posterior-superior\n"
    << "sizes: " << shape[0] << " " << shape[1] << " " << shape[2] << "\n"
    << "space directions:";
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d d = r.col(a) * s[a] * 1000.0;
    h << " (" << d.x() << "," << d.y() << "," << d.z() << ")";
  }
  h << "\nkinds: domain domain domain\nendian: little\nencoding: " << (gzip ? "gzip" : "raw")
    << "\nspace origin: (" << origin.x() * 1000 << "," << origin.y() * 1000 << ","
    << origin.z() * 1000 << ")\n";
  if (what == "labels") {
    // 3D Slicer's segmentation keys, so names and colours survive a trip through Slicer.
    int n = 0;
    for (const Label& l : volume.label_table().labels()) {
      const std::string seg = "Segment" + std::to_string(n++);
      h << seg << "_Color:=" << l.color[0] / 255.0 << " " << l.color[1] / 255.0 << " "
        << l.color[2] / 255.0 << "\n"
        << seg << "_ID:=" << seg << "\n"
        << seg << "_LabelValue:=" << l.id << "\n"
        << seg << "_Layer:=0\n"
        << seg << "_Name:=" << l.name << "\n";
    }
  }
  h << "\n";
  std::string payload(static_cast<const char*>(source), bytes);
  if (gzip) {
    std::string out(compressBound(bytes) + 64, '\0');
    z_stream z{};
    if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
      throw ConfigError(path, "cannot start gzip encoding");
    }
    z.next_in = reinterpret_cast<Bytef*>(payload.data());
    z.avail_in = static_cast<uInt>(payload.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    const int rc = deflate(&z, Z_FINISH);
    out.resize(out.size() - z.avail_out);
    deflateEnd(&z);
    if (rc != Z_STREAM_END) throw ConfigError(path, "gzip encoding failed");
    payload.swap(out);
  }
  std::ofstream file(path, std::ios::binary);
  file << h.str();
  file.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  if (!file)
    throw ConfigError(path, std::string("cannot write the NRRD file: ") + std::strerror(errno));
}

}  // namespace ambfplus
