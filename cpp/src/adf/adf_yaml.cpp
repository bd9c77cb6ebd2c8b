#include "adf/adf_yaml.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include <Eigen/Geometry>

#include "ambfplus/log.h"
#include "util/files.h"
#include "util/strings.h"

namespace ambfplus::adf {

namespace {

std::string line_of(const YAML::Node& node) {
  const std::string a = at(node);
  return a.empty() ? "an earlier line" : a.substr(0, a.size() - 2);
}

/// Whether a and b hold the same value (the same scalars, in the same order for lists, under the
/// same keys for mappings). budget bounds the work on aliased input; once spent, "different".
bool same_value(const YAML::Node& a, const YAML::Node& b, long& budget) {
  if (--budget < 0) return false;
  if (a.is(b)) return true;
  if (a.Type() != b.Type()) return false;
  switch (a.Type()) {
    case YAML::NodeType::Scalar:
      return a.Scalar() == b.Scalar();
    case YAML::NodeType::Sequence: {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (!same_value(a[i], b[i], budget)) return false;
      }
      return true;
    }
    case YAML::NodeType::Map: {
      if (a.size() != b.size()) return false;
      for (const auto& entry : a) {
        if (!entry.first.IsScalar()) return false;
        const YAML::Node other = b[entry.first.Scalar()];
        if (!other || !same_value(entry.second, other, budget)) return false;
      }
      return true;
    }
    default:
      return true;  // null or undefined on both sides
  }
}

/// Keys written twice in one mapping of node (and the mappings inside it), each mapping visited
/// once however often aliases name it: yaml-cpp (and so AMBF) keeps both and reads the first.
void check_repeated_keys(const Doc& doc, const YAML::Node& node, Diagnostics* diag,
                         std::set<std::size_t>& visited, long& budget) {
  if (!node.IsMap() && !node.IsSequence()) return;
  if (!node.Mark().is_null() && !visited.insert(static_cast<std::size_t>(node.Mark().pos)).second) {
    return;
  }
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) check_repeated_keys(doc, item, diag, visited, budget);
    return;
  }
  std::map<std::string, std::pair<YAML::Node, YAML::Node>> first;  // key -> (key, value)
  for (const auto& entry : node) {
    check_repeated_keys(doc, entry.second, diag, visited, budget);
    if (!entry.first.IsScalar()) continue;
    const std::string key = entry.first.Scalar();
    const auto [seen, fresh] = first.try_emplace(key, entry.first, entry.second);
    if (fresh) continue;
    const std::string earlier = line_of(seen->second.first);
    if (!same_value(seen->second.second, entry.second, budget)) {
      fail(doc, entry.first, "",
           "key '" + key + "' is given twice in one mapping (first on " + earlier +
               ") with different values; AMBF would silently use the first: keep one");
    }
    if (diag != nullptr) {
      diag->warn(doc.path, at(entry.first) + "key '" + key + "' is given twice in one mapping " +
                               "(first on " + earlier + "), with the same value; read once");
    }
  }
}

}  // namespace

Doc load(const std::string& path, const std::string& what, Diagnostics* diag) {
  require_regular_file(path, what);
  Doc doc{path, fs::absolute(fs::path(path)).parent_path().lexically_normal(), {}};
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  if (!file) throw ConfigError(path, what + ": cannot be read");
  // Names and messages made from the file must reach Python as text; a second document (a
  // '---' line after content) would be ignored by YAML::Load, so it is refused. (YAML::LoadAll
  // is not used: it loops without end on some malformed input, such as a lone ',').
  std::istringstream lines(text.str());
  std::string line;
  bool content = false;
  for (int number = 1; std::getline(lines, line); ++number) {
    require_utf8(path, number, line);
    const bool marker = line.rfind("---", 0) == 0 &&
                        (line.size() == 3 || std::isspace(static_cast<unsigned char>(line[3])));
    if (marker && content) {
      throw ConfigError(path, "line " + std::to_string(number) + ": " + what +
                                  ": a second YAML document ('---'); an ADF file holds one");
    }
    const std::size_t first = line.find_first_not_of(" \t\r");
    content |=
        !marker && first != std::string::npos && line[first] != '#' && line.rfind("%", 0) != 0;
  }
  try {
    doc.root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!doc.root.IsMap()) throw ConfigError(path, what + ": expected a mapping of keys at the top");
  std::set<std::size_t> visited;
  long budget = 1000000;
  check_repeated_keys(doc, doc.root, diag, visited, budget);
  if (const YAML::Node version = doc.root["adf version"]) {
    const std::string v = as<std::string>(doc, version, what, "adf version", "a string");
    if (v != "1.0" && v != "1") {
      fail(doc, version, what, "'adf version' " + v + " is not supported (only 1.0)");
    }
  }
  return doc;
}

std::string at(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? std::string() : "line " + std::to_string(mark.line + 1) + ": ";
}

void fail(const Doc& doc, const YAML::Node& node, const std::string& where,
          const std::string& message) {
  throw ConfigError(doc.path, at(node) + (where.empty() ? "" : where + ": ") + message);
}

double number(const Doc& doc, const YAML::Node& node, const std::string& where,
              const std::string& key) {
  const double value = as<double>(doc, node, where, key, "a number");
  // yaml-cpp reads .nan and .inf as numbers; no ADF value means either.
  if (!std::isfinite(value)) {
    fail(doc, node, where, "'" + key + "' must be a finite number, got " + node.Scalar());
  }
  return value;
}

int integer(const Doc& doc, const YAML::Node& node, const std::string& where,
            const std::string& key) {
  return as<int>(doc, node, where, key, "an integer");
}

int integer_or(const Doc& doc, const YAML::Node& parent, const char* key, const std::string& where,
               const std::string& parent_key, int fallback) {
  const YAML::Node n = parent[key];
  return n ? integer(doc, n, where, parent_key + "." + key) : fallback;
}

YAML::Node mapping(const Doc& doc, const YAML::Node& block, const char* key,
                   const std::string& where, const std::string& prefix) {
  if (!block.IsMap()) return YAML::Node();
  const YAML::Node node = block[key];
  if (node && !node.IsMap() && !node.IsNull()) {
    const std::string got = node.IsScalar() ? "'" + node.Scalar() + "'" : "a list";
    fail(doc, node, where, "'" + prefix + key + "' must be a mapping of keys ({...}), got " + got);
  }
  return node;
}

bool boolean(const Doc& doc, const YAML::Node& node, const std::string& where,
             const std::string& key) {
  return as<bool>(doc, node, where, key, "true or false");
}

std::string text(const Doc& doc, const YAML::Node& node, const std::string& where,
                 const std::string& key) {
  if (!node.IsScalar()) fail(doc, node, where, "'" + key + "' must be a string");
  std::string value = node.as<std::string>();
  // A quoted "\0" would cut the name short where the file system reads it.
  if (const std::size_t nul = value.find('\0'); nul != std::string::npos) {
    fail(doc, node, where,
         "'" + key + "' holds a NUL character (\\0) after '" + value.substr(0, nul) +
             "'; names and paths cannot contain one");
  }
  return value;
}

double number_or(const Doc& doc, const YAML::Node& parent, const char* key,
                 const std::string& where, double fallback) {
  if (parent && !parent.IsMap() && !parent.IsNull()) {
    fail(doc, parent, where, std::string("expected a mapping of keys holding '") + key + "'");
  }
  if (!parent.IsMap()) return fallback;
  const YAML::Node n = parent[key];
  return n ? number(doc, n, where, key) : fallback;
}

double scale_of(const Doc& doc, const YAML::Node& block, const std::string& where) {
  const double scale = number_or(doc, block, "scale", where, 1.0);
  if (!(scale > 0) || scale > kMaxScale) {
    fail(doc, block["scale"], where,
         "'scale' must be > 0 and at most 1e6, got " + block["scale"].Scalar() +
             " (a scaled mesh or shape beyond that is past Bullet's and the renderer's precision)");
  }
  return scale;
}

double mass_of(const Doc& doc, const YAML::Node& node, const std::string& where) {
  const double mass = number(doc, node, where, "mass");
  if (!(mass >= 0)) fail(doc, node, where, "'mass' must be >= 0 (0: static), got " + node.Scalar());
  if (mass > kMaxMass) {
    fail(doc, node, where,
         "'mass' is " + node.Scalar() +
             " kg; at most 1e9 kg is taken (beyond it the inertia and contact forces overflow "
             "Bullet's solver; use mass 0 for a body that never moves)");
  }
  return mass;
}

Eigen::Vector3d xyz(const Doc& doc, const YAML::Node& node, const std::string& where,
                    const std::string& key, const Eigen::Vector3d& fallback) {
  if (!node) return fallback;
  if (!node.IsMap()) fail(doc, node, where, "'" + key + "' must be {x, y, z}");
  Eigen::Vector3d v = fallback;
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    // AMBF reads all three; a missing one would be a silent 0 here.
    if (!node[axes[a]]) {
      fail(doc, node, where,
           "'" + key + "' needs x, y and z; '" + axes[a] + "' is missing (AMBF reads all three)");
    }
    v[a] = number(doc, node[axes[a]], where, key + "." + axes[a]);
  }
  return v;
}

Eigen::Matrix3d rpy(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix4d frame(const Doc& doc, const YAML::Node& node, const std::string& where,
                      const std::string& key, double scale) {
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  if (!node) return pose;
  if (!node.IsMap()) fail(doc, node, where, "'" + key + "' must be {position, orientation}");
  const YAML::Node position = node["position"];
  const Eigen::Vector3d p = xyz(doc, position, where, key + ".position", Eigen::Vector3d::Zero());
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    // Far beyond any scene, where Bullet's and the renderer's precision is gone.
    if (std::abs(p[a]) > kMaxPosition) {
      fail(doc, position[axes[a]], where,
           "'" + key + ".position." + axes[a] + "' is " + position[axes[a]].Scalar() +
               " m; positions must be within 1e6 m of the origin");
    }
  }
  pose.topRightCorner<3, 1>() = p * scale;
  if (const YAML::Node o = node["orientation"]) {
    if (!o.IsMap()) fail(doc, o, where, "'" + key + ".orientation' must be {r, p, y}");
    double rpy_values[3] = {0.0, 0.0, 0.0};
    const char* names[3] = {"r", "p", "y"};
    for (int a = 0; a < 3; ++a) {
      if (!o[names[a]]) {
        fail(doc, o, where,
             "'" + key + ".orientation' needs r, p and y; '" + names[a] +
                 "' is missing (AMBF reads all three)");
      }
      rpy_values[a] = number(doc, o[names[a]], where, key + ".orientation." + names[a]);
    }
    pose.topLeftCorner<3, 3>() = rpy(rpy_values[0], rpy_values[1], rpy_values[2]);
  }
  return pose;
}

std::vector<std::pair<std::string, YAML::Node>> listed(const Doc& doc,
                                                       const std::string& list_key) {
  std::vector<std::pair<std::string, YAML::Node>> out;
  const YAML::Node list = doc.root[list_key];
  if (!list || list.IsNull()) return out;
  if (!list.IsSequence()) fail(doc, list, "", "'" + list_key + "' must be a list of block names");
  std::set<std::string> seen;
  for (const YAML::Node& entry : list) {
    const std::string id = text(doc, entry, list_key, list_key);
    // The same block named again is the same block (repeated_entries warns of it).
    if (!seen.insert(id).second) continue;
    const YAML::Node block = doc.root[id];
    if (!block || !block.IsMap()) {
      fail(doc, entry, "",
           "'" + list_key + "' lists '" + id + "' but the file has no block of that name");
    }
    out.emplace_back(id, block);
  }
  return out;
}

std::string remove_spaces(std::string s) {
  s.erase(std::remove(s.begin(), s.end(), ' '), s.end());
  return s;
}

std::string block_name(const Doc& doc, const std::string& id, const YAML::Node& block) {
  if (const YAML::Node n = block["name"]) return remove_spaces(text(doc, n, id, "name"));
  return remove_spaces(id.substr(id.find(' ') == std::string::npos ? 0 : id.find(' ') + 1));
}

std::string resolve(const fs::path& dir, const std::string& path) {
  const fs::path p(path);
  return (p.is_absolute() ? p : dir / p).lexically_normal().string();
}

void Diagnostics::unknown_top_level(const Doc& doc, const std::set<std::string>& known,
                                    std::initializer_list<const char*> list_keys) {
  std::set<std::string> blocks;  // identifiers some list names
  std::string lists;
  for (const char* list_key : list_keys) {
    lists += (lists.empty() ? "" : ", ") + std::string(list_key);
    const YAML::Node list = doc.root[list_key];
    if (!list || !list.IsSequence()) continue;  // listed() reports it where it is read
    for (const YAML::Node& entry : list) {
      if (entry.IsScalar()) blocks.insert(entry.Scalar());
    }
  }
  for (const auto& entry : doc.root) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "?";
    if (known.count(key) != 0 || blocks.count(key) != 0) continue;
    // A mapping may be a block that its list forgot: say which lists were searched.
    const std::string block =
        entry.second.IsMap() ? " (a block that none of " + lists + " names)" : "";
    warn(doc.path, at(entry.first) + "unknown key '" + key + "' ignored" + block);
  }
}

void Diagnostics::repeated_names(const Doc& doc, std::initializer_list<const char*> list_keys) {
  std::map<std::string, std::pair<std::string, std::string>> first;  // name -> (id, line)
  for (const char* list_key : list_keys) {
    for (const auto& [id, block] : listed(doc, list_key)) {
      const std::string name = block_name(doc, id, block);
      const std::string line =
          at(block).empty() ? "" : " (" + at(block).substr(0, at(block).size() - 2) + ")";
      const auto [seen, fresh] = first.try_emplace(name, id, line);
      if (fresh) continue;
      warn(doc.path, at(block) + id + ": its name '" + name + "' is also that of '" +
                         seen->second.first + "'" + seen->second.second +
                         "; it is renamed with a number suffix, as AMBF does for repeated names");
    }
  }
}

void Diagnostics::repeated_entries(const Doc& doc, std::initializer_list<const char*> list_keys) {
  for (const char* list_key : list_keys) {
    const YAML::Node list = doc.root[list_key];
    if (!list || !list.IsSequence()) continue;  // listed() reports it where it is read
    std::map<std::string, YAML::Node> first;
    for (const YAML::Node& entry : list) {
      if (!entry.IsScalar()) continue;
      const auto [seen, fresh] = first.try_emplace(entry.Scalar(), entry);
      if (fresh) continue;
      warn(doc.path, at(entry) + "'" + list_key + "' names '" + entry.Scalar() +
                         "' again (first on " + line_of(seen->second) +
                         "); it is the same block, made once");
    }
  }
}

void Diagnostics::not_applied(const Doc& doc, const char* list_key,
                              std::initializer_list<const char*> keys, const std::string& why) {
  for (const char* key : keys) {
    std::vector<std::string> blocks;
    std::string first_line;
    for (const auto& [id, block] : listed(doc, list_key)) {
      if (!block.IsMap() || !block[key]) continue;
      if (blocks.empty()) first_line = at(block[key]);
      blocks.push_back(id);
    }
    if (blocks.empty()) continue;
    std::string names;
    for (std::size_t i = 0; i < blocks.size() && i < 3; ++i) names += (i ? ", " : "") + blocks[i];
    if (blocks.size() > 3) names += " and " + std::to_string(blocks.size() - 3) + " more";
    warn(doc.path,
         first_line + "'" + key + "' of " + names + " is read by AMBF but not applied: " + why);
  }
}

void yaml_error(const std::string& path, const YAML::Exception& e) {
  const std::string line = e.mark.is_null() ? "" : "line " + std::to_string(e.mark.line + 1) + ": ";
  // BadSubscript: yaml-cpp's "operator[] call on a scalar (key: ...)".
  if (dynamic_cast<const YAML::BadSubscript*>(&e) != nullptr) {
    throw ConfigError(
        path, line + "expected a mapping of keys here, found a single value (" + e.msg + ")");
  }
  throw ConfigError(path, line + e.msg);
}

void Diagnostics::warn(const std::string& file, const std::string& message) {
  log(LogLevel::kWarning, file.empty() ? message : file + ": " + message);
  warnings_.push_back({file, message});
}

void Diagnostics::error(const std::string& file, const std::string& message) {
  log(LogLevel::kError, file.empty() ? message : file + ": " + message);
  errors_.push_back({file, message});
}

void Diagnostics::unknown_keys(const Doc& doc, const std::string& where, const YAML::Node& block,
                               std::initializer_list<const char*> known) {
  const std::set<std::string> names(known.begin(), known.end());
  std::set<std::string> seen;
  for (const auto& entry : block) {
    if (!entry.first.IsScalar()) continue;
    const std::string key = entry.first.as<std::string>();
    if (names.count(key) == 0 && seen.insert(key).second) {
      warn(doc.path, at(entry.first) + where + ": unknown key '" + key + "' ignored");
    }
  }
}

std::optional<YAML::Node> non_finite(const YAML::Node& node) {
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) {
      if (auto bad = non_finite(item)) return bad;
    }
  } else if (node.IsMap()) {
    for (const auto& entry : node) {
      if (auto bad = non_finite(entry.second)) return bad;
    }
  } else if (node.IsScalar() && !node.Scalar().empty()) {
    double value = 0.0;
    char* end = nullptr;
    const double parsed = std::strtod(node.Scalar().c_str(), &end);
    const bool by_strtod = *end == '\0';
    if ((by_strtod && !std::isfinite(parsed)) ||
        (YAML::convert<double>::decode(node, value) && !std::isfinite(value))) {
      return node;
    }
  }
  return std::nullopt;
}

OptionValue option_value(const YAML::Node& node) {
  if (!node || node.IsNull()) return {};
  if (node.IsSequence()) {
    std::vector<OptionValue> items;
    for (const YAML::Node& item : node) items.push_back(option_value(item));
    return OptionValue(std::move(items));
  }
  if (node.IsMap()) {
    OptionMap entries;
    for (const auto& entry : node) {
      entries.push_back({entry.first.as<std::string>(), option_value(entry.second)});
    }
    return OptionValue::mapping(std::move(entries));
  }
  const std::string& text = node.Scalar();
  if (!text.empty()) {
    char* end = nullptr;
    const long long i = std::strtoll(text.c_str(), &end, 10);
    if (*end == '\0') return OptionValue(static_cast<std::int64_t>(i));
    const double d = std::strtod(text.c_str(), &end);
    if (*end == '\0') return OptionValue(d);
  }
  // YAML's booleans as yaml-cpp reads them, but for the one-letter y and n (an axis is "y").
  bool b = false;
  if (text.size() > 1 && YAML::convert<bool>::decode(node, b)) return OptionValue(b);
  return OptionValue(text);
}

}  // namespace ambfplus::adf
