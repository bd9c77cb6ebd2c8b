// NRRD reading and writing (the format of 3D Slicer volumes and segmentations), from the format's
// public specification: a text header of "field: value" and "key:=value" lines, a blank line, then
// raw or gzip data (or a detached data file).

#include <zlib.h>
#include <cerrno>
#include <cstring>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/volume/volume_io.h"
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

struct Header {
  std::map<std::string, std::string> fields;      // lower-case field names
  std::map<std::string, std::string> key_values;  // key:=value pairs
  std::size_t data_offset = 0;                    // bytes to the data in the same file
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
    if (line.empty()) break;  // the header ends at the first blank line
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
    h.fields[to_lower(line.substr(0, colon))] = trim(line.substr(colon + 2));
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
      throw ConfigError(path,
                        "field '" + field + "': expected (x,y,z) vectors, got '" + value + "'");
    }
    const std::size_t close = value.find(')', pos);
    if (close == std::string::npos) {
      throw ConfigError(path, "field '" + field + "': unbalanced parenthesis in '" + value + "'");
    }
    std::string inside = value.substr(pos + 1, close - pos - 1);
    std::replace(inside.begin(), inside.end(), ',', ' ');
    std::istringstream in(inside);
    Eigen::Vector3d v;
    if (!(in >> v[0] >> v[1] >> v[2])) {
      throw ConfigError(path, "field '" + field + "': expected 3 numbers in '(" + inside + ")'");
    }
    out.push_back(v);
    pos = close + 1;
  }
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw AssetNotFound(path, "NRRD");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string gunzip(const std::string& path, const char* data, std::size_t size,
                   std::size_t expected) {
  std::string out(expected, '\0');
  z_stream z{};
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
  z.avail_in = static_cast<uInt>(size);
  if (inflateInit2(&z, 15 + 32) != Z_OK) throw ConfigError(path, "cannot start gzip decoding");
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(expected);
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t produced = expected - z.avail_out;
  inflateEnd(&z);
  if (rc != Z_STREAM_END && !(rc == Z_BUF_ERROR && produced == expected)) {
    throw ConfigError(path, "gzip data is corrupt or shorter than the header says: got " +
                                std::to_string(produced) + " of " + std::to_string(expected) +
                                " bytes (zlib: " + (z.msg ? z.msg : std::to_string(rc)) + ")");
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

struct Segment {
  int index = 0;
  std::string name;
  std::array<std::uint8_t, 3> color{255, 255, 255};
  int label_value = 1;
  int layer = 0;
};

std::vector<Segment> read_segments(const std::string& path, const Header& h) {
  std::map<int, Segment> by_index;
  static const std::regex key("Segment([0-9]+)_(ID|Name|Color|LabelValue|Layer)");
  for (const auto& [k, v] : h.key_values) {
    std::smatch m;
    if (!std::regex_match(k, m, key)) continue;
    Segment& s = by_index[std::stoi(m[1])];
    s.index = std::stoi(m[1]);
    const std::string what = m[2];
    try {
      if (what == "Name") {
        s.name = v;
      } else if (what == "Color") {
        std::istringstream in(v);
        double rgb[3];
        if (!(in >> rgb[0] >> rgb[1] >> rgb[2])) throw ArgumentError("colour");
        for (int c = 0; c < 3; ++c) {
          s.color[c] = static_cast<std::uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255));
        }
      } else if (what == "LabelValue") {
        s.label_value = std::stoi(v);
      } else if (what == "Layer") {
        s.layer = std::stoi(v);
      }
    } catch (const std::exception&) {
      throw ConfigError(path, "key '" + k + "': cannot read '" + v + "'");
    }
  }
  std::vector<Segment> out;
  for (auto& [i, s] : by_index) {
    if (s.name.empty()) s.name = "Segment_" + std::to_string(i);
    out.push_back(s);
  }
  return out;
}

}  // namespace

std::shared_ptr<VolumeData> load_nrrd(const std::string& path, const NrrdOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw AssetNotFound(path, "NRRD");
  const std::string file = read_file(path);
  const Header h = read_header(path, file);
  auto field = [&](const char* name) -> const std::string& {
    auto it = h.fields.find(name);
    if (it == h.fields.end())
      throw ConfigError(path, std::string("missing required field '") + name + "'");
    return it->second;
  };
  const Scalar type = parse_type(path, field("type"));
  const int dimension = std::atoi(field("dimension").c_str());
  const std::vector<std::string> size_words = words(field("sizes"));
  if (dimension != 3 && dimension != 4) {
    throw ConfigError(path,
                      "field 'dimension': expected 3 (or 4 for a layered segmentation), got " +
                          field("dimension"));
  }
  if (static_cast<int>(size_words.size()) != dimension) {
    throw ConfigError(path, "field 'sizes': expected " + std::to_string(dimension) +
                                " sizes, got '" + field("sizes") + "'");
  }
  std::vector<int> sizes;
  for (const std::string& w : size_words) {
    const long v = std::strtol(w.c_str(), nullptr, 10);
    if (v <= 0 || v > 8192) throw ConfigError(path, "field 'sizes': bad size '" + w + "'");
    sizes.push_back(static_cast<int>(v));
  }
  const int layers = dimension == 4 ? sizes[0] : 1;
  const std::array<int, 3> shape = dimension == 4
                                       ? std::array<int, 3>{sizes[1], sizes[2], sizes[3]}
                                       : std::array<int, 3>{sizes[0], sizes[1], sizes[2]};
  const std::string encoding =
      to_lower(h.fields.count("encoding") ? h.fields.at("encoding") : "raw");
  const bool big_endian = h.fields.count("endian") && to_lower(h.fields.at("endian")) == "big";
  const std::size_t voxels = std::size_t(shape[0]) * shape[1] * shape[2];
  const std::size_t bytes = voxels * layers * scalar_size(type);

  // The data: attached after the header, or in a detached file next to it.
  std::string detached;
  const char* data = file.data() + h.data_offset;
  std::size_t available = file.size() - h.data_offset;
  std::string data_source = path;
  for (const char* key : {"data file", "datafile"}) {
    if (!h.fields.count(key)) continue;
    fs::path p = h.fields.at(key);
    if (p.is_relative()) p = fs::path(path).parent_path() / p;
    data_source = p.string();
    detached = read_file(data_source);
    data = detached.data();
    available = detached.size();
  }
  std::string decoded;
  if (encoding == "gzip" || encoding == "gz") {
    decoded = gunzip(data_source, data, available, bytes);
    data = decoded.data();
    available = decoded.size();
  } else if (encoding == "raw") {
    // Raw data may follow extra bytes: it is the last `bytes` of the file.
    if (available < bytes) {
      throw ConfigError(data_source, "raw data holds " + std::to_string(available) +
                                         " bytes but the header needs " + std::to_string(bytes) +
                                         " (sizes " + field("sizes") + " of " + field("type") +
                                         ")");
    }
    data += available - bytes;
  } else {
    throw ConfigError(path, "field 'encoding': '" + encoding + "' is not supported (raw or gzip)");
  }
  std::string swapped;
  if (big_endian && scalar_size(type) > 1) {
    swapped.assign(data, bytes);
    const std::size_t w = scalar_size(type);
    for (std::size_t v = 0; v < bytes; v += w) std::reverse(&swapped[v], &swapped[v + w]);
    data = swapped.data();
  }

  // Geometry: space directions give the voxel axes (mm), space origin the first voxel's centre.
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double unit = 0.001;  // millimetres unless said otherwise
  if (h.fields.count("space units")) {
    const auto u = words(h.fields.at("space units"));
    if (!u.empty() && (u[0] == "\"m\"" || u[0] == "m")) unit = 1.0;
  }
  if (h.fields.count("space directions")) {
    std::vector<Eigen::Vector3d> v =
        parse_vectors(path, "space directions", h.fields.at("space directions"));
    if (dimension == 4 && !v.empty() && std::isnan(v[0][0])) v.erase(v.begin());
    if (v.size() != 3 || !v[0].allFinite() || !v[1].allFinite() || !v[2].allFinite()) {
      throw ConfigError(path,
                        "field 'space directions': expected three (x,y,z) vectors for the "
                        "spatial axes, got '" +
                            h.fields.at("space directions") + "'");
    }
    for (int a = 0; a < 3; ++a) directions.col(a) = v[a];
  } else if (h.fields.count("spacings")) {
    const auto w = words(h.fields.at("spacings"));
    for (int a = 0; a < 3 && a + (dimension - 3) < static_cast<int>(w.size()); ++a) {
      directions(a, a) = std::atof(w[a + dimension - 3].c_str());
    }
  }
  if (h.fields.count("space origin")) {
    const auto v = parse_vectors(path, "space origin", h.fields.at("space origin"));
    if (v.size() != 1 || !v[0].allFinite()) {
      throw ConfigError(path, "field 'space origin': expected one (x,y,z) vector");
    }
    origin = v[0];
  }
  directions *= unit;
  origin *= unit;
  Eigen::Vector3d spacing;
  for (int a = 0; a < 3; ++a) spacing[a] = directions.col(a).norm();
  if (!(spacing.minCoeff() > 0)) throw ConfigError(path, "a space direction has zero length");
  // Nearest rotation to the (possibly slightly sheared) axes; a left-handed grid is made
  // right-handed by reversing k.
  Eigen::Matrix3d axes = directions * spacing.cwiseInverse().asDiagonal();
  bool flip_k = axes.determinant() < 0;
  if (flip_k) {
    origin += directions.col(2) * (shape[2] - 1);
    axes.col(2) = -axes.col(2);
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(axes, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  const Eigen::Vector3d dims = spacing.cwiseProduct(Eigen::Vector3d(shape[0], shape[1], shape[2]));
  Eigen::Matrix4d patient = Eigen::Matrix4d::Identity();
  patient.topLeftCorner<3, 3>() = rotation;
  patient.topRightCorner<3, 1>() = origin + rotation * (dims / 2 - spacing / 2);

  auto at = [&](std::size_t layer, int i, int j, int k) {
    const int kk = flip_k ? shape[2] - 1 - k : k;
    const std::size_t v = static_cast<std::size_t>(i) +
                          std::size_t(shape[0]) * (std::size_t(j) + std::size_t(shape[1]) * kk);
    return value_at(type, data + (v * layers + layer) * scalar_size(type));
  };

  // What the file is.
  std::vector<Segment> segments = read_segments(path, h);
  NrrdOptions::Kind kind = options.kind;
  double lo = 0, hi = 0;
  std::set<long> distinct;
  if (kind == NrrdOptions::Kind::kAuto) {
    if (!segments.empty()) {
      kind = NrrdOptions::Kind::kSegmentation;
    } else {
      lo = hi = at(0, 0, 0, 0);
      bool integral = is_integer(type);
      for (std::size_t v = 0; v < voxels * layers && integral; ++v) {
        const double x = value_at(type, data + v * scalar_size(type));
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        if (distinct.size() <= 256) distinct.insert(static_cast<long>(x));
      }
      kind = integral && layers == 1 && lo >= 0 && hi <= 65535 && distinct.size() <= 256
                 ? NrrdOptions::Kind::kLabels
                 : NrrdOptions::Kind::kIntensity;
    }
  }
  if (layers > 1 && kind != NrrdOptions::Kind::kSegmentation) {
    throw ConfigError(path,
                      "4D data is read only as a layered segmentation (Segment keys missing)");
  }

  std::shared_ptr<VolumeData> volume;
  if (kind == NrrdOptions::Kind::kIntensity) {
    if (!options.threshold) {
      throw ConfigError(path, "holds intensities (type " + field("type") +
                                  "): give a threshold to segment it (e.g. 300 for bone in HU)");
    }
    LabelTable table;
    table.add(Label{1, "Segmented", {255, 249, 219}, true, false});
    volume = std::make_shared<VolumeData>(shape, dims, LabelType::kUInt8, table);
    volume->set_intensity_type(type == Scalar::kFloat || type == Scalar::kDouble ||
                                       type == Scalar::kInt32 || type == Scalar::kUInt32
                                   ? IntensityType::kFloat32
                                   : IntensityType::kInt16);
    auto* labels = static_cast<std::uint8_t*>(volume->label_data());
    for (int k = 0; k < shape[2]; ++k) {
      for (int j = 0; j < shape[1]; ++j) {
        for (int i = 0; i < shape[0]; ++i) {
          const double x = at(0, i, j, k);
          const std::size_t n = volume->linear_index(i, j, k);
          if (volume->intensity_type() == IntensityType::kInt16) {
            static_cast<std::int16_t*>(volume->intensity_data())[n] =
                static_cast<std::int16_t>(std::clamp(x, -32768.0, 32767.0));
          } else {
            static_cast<float*>(volume->intensity_data())[n] = static_cast<float>(x);
          }
          labels[n] = x >= *options.threshold ? 1 : 0;
        }
      }
    }
  } else if (kind == NrrdOptions::Kind::kLabels) {
    if (!is_integer(type))
      throw ConfigError(path, "a label map needs an integer type, got " + field("type"));
    LabelTable table;
    std::uint16_t max_id = 0;
    std::vector<bool> seen(65536, false);
    for (std::size_t v = 0; v < voxels; ++v) {
      const double x = value_at(type, data + v * scalar_size(type));
      if (x < 0 || x > 65535) {
        throw ConfigError(path, "label map value " + std::to_string(static_cast<long>(x)) +
                                    " is outside 0..65535");
      }
      seen[static_cast<std::size_t>(x)] = true;
      max_id = std::max(max_id, static_cast<std::uint16_t>(x));
    }
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
    volume = std::make_shared<VolumeData>(
        shape, dims, max_id > 255 ? LabelType::kUInt16 : LabelType::kUInt8, table);
    visit_labels(volume->label_type(), volume->label_data(), [&](auto* labels) {
      using T = std::remove_pointer_t<decltype(labels)>;
      for (int k = 0; k < shape[2]; ++k)
        for (int j = 0; j < shape[1]; ++j)
          for (int i = 0; i < shape[0]; ++i)
            labels[volume->linear_index(i, j, k)] = static_cast<T>(at(0, i, j, k));
    });
  } else {
    // Slicer segmentation: segment s is where its layer holds its label value. In one layer
    // with distinct label values those values are the ids; across layers (values repeat) the
    // ids are the segment numbers + 1.
    if (segments.empty()) throw ConfigError(path, "no Segment<N>_* keys: not a segmentation");
    if (!is_integer(type)) throw ConfigError(path, "a segmentation needs an integer type");
    std::set<int> values;
    bool keep_values = layers == 1;
    for (const Segment& s : segments) {
      if (s.layer < 0 || s.layer >= layers) {
        throw ConfigError(path, "Segment" + std::to_string(s.index) + "_Layer is " +
                                    std::to_string(s.layer) + " but the file has " +
                                    std::to_string(layers) + " layer(s)");
      }
      keep_values = keep_values && s.label_value >= 1 && s.label_value <= 65535 &&
                    values.insert(s.label_value).second;
    }
    std::vector<std::uint16_t> ids;
    LabelTable table;
    for (const Segment& s : segments) {
      ids.push_back(static_cast<std::uint16_t>(keep_values ? s.label_value : s.index + 1));
      table.add(Label{ids.back(), s.name, s.color, true, false});
    }
    volume = std::make_shared<VolumeData>(
        shape, dims, table.max_id() > 255 ? LabelType::kUInt16 : LabelType::kUInt8, table);
    std::int64_t overlaps = 0;
    visit_labels(volume->label_type(), volume->label_data(), [&](auto* labels) {
      using T = std::remove_pointer_t<decltype(labels)>;
      for (int k = 0; k < shape[2]; ++k)
        for (int j = 0; j < shape[1]; ++j)
          for (int i = 0; i < shape[0]; ++i) {
            T& out = labels[volume->linear_index(i, j, k)];
            for (std::size_t n = 0; n < segments.size(); ++n) {
              const Segment& s = segments[n];
              if (at(s.layer, i, j, k) != s.label_value) continue;
              overlaps += out != 0;
              out = static_cast<T>(ids[n]);
            }
          }
    });
    if (overlaps > 0) {
      log(LogLevel::kWarning,
          path + ": " + std::to_string(overlaps) +
              " voxels belong to more than one segment; the later segment wins");
    }
  }
  volume->set_patient_from_volume(patient);
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
