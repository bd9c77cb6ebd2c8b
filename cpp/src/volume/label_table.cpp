#include "ambfplus/volume/label_table.h"

#include <yaml-cpp/yaml.h>
#include <cctype>
#include <cerrno>
#include <cstring>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ambfplus/errors.h"
#include "util/files.h"
#include "util/strings.h"

namespace ambfplus {

LabelTable::LabelTable(std::vector<Label> labels) {
  for (const Label& l : labels) add(l);
}

void LabelTable::add(const Label& label) {
  if (label.id == 0) throw ArgumentError("label '" + label.name + "': id 0 means no label");
  if (find(label.id)) {
    throw ArgumentError("label id " + std::to_string(label.id) + " is used twice");
  }
  if (!label.name.empty() && find(label.name)) {
    throw ArgumentError("label name '" + label.name + "' is used twice");
  }
  labels_.push_back(label);
}

const Label* LabelTable::find(std::uint16_t id) const {
  for (const Label& l : labels_) {
    if (l.id == id) return &l;
  }
  return nullptr;
}

const Label* LabelTable::find(const std::string& name) const {
  for (const Label& l : labels_) {
    if (l.name == name) return &l;
  }
  return nullptr;
}

std::uint16_t resolve_label(const LabelTable& table, const std::string& name,
                            const std::string& what) {
  if (const Label* l = table.find(name)) return l->id;
  // An id written as a number.
  if (!name.empty() && name.find_first_not_of("0123456789") == std::string::npos &&
      name.size() < 6) {
    const long id = std::stol(name);
    if (id > 0 && id <= 65535 && table.find(static_cast<std::uint16_t>(id))) {
      return static_cast<std::uint16_t>(id);
    }
  }
  std::ostringstream message;
  message << what << ": no label '" << name << "' in the volume's table; it has";
  const char* sep = " ";
  for (const Label& l : table.labels()) {
    message << sep << l.id << " '" << l.name << "'";
    sep = ", ";
  }
  if (table.empty()) message << " no labels";
  throw NotFound(message.str());
}

bool is_bone(const LabelTable& table, const Label& label) {
  if (table.size() == 1) return true;
  std::string name = label.name;
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const char* const kBony[] = {"bone",   "bony",   "osse",      "ossic",   "malleus",
                                      "incus",  "stapes", "labyrinth", "cochlea", "mastoid",
                                      "cortex", "tegmen", "petrous",   "skull",   "zygom",
                                      "mandib", "condyl", "vertebr"};
  for (const char* word : kBony) {
    if (name.find(word) != std::string::npos) return true;
  }
  return false;
}

std::uint16_t LabelTable::max_id() const {
  std::uint16_t m = 0;
  for (const Label& l : labels_) m = std::max(m, l.id);
  return m;
}

std::uint16_t LabelTable::nearest(const std::array<std::uint8_t, 3>& rgb) const {
  std::uint16_t best = 0;
  int best_d = std::numeric_limits<int>::max();
  for (const Label& l : labels_) {
    int d = 0;
    for (int c = 0; c < 3; ++c) {
      const int e = int(l.color[c]) - int(rgb[c]);
      d += e * e;
    }
    if (d < best_d) {
      best_d = d;
      best = l.id;
    }
  }
  return best;
}

namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream s(line);
  while (std::getline(s, cell, ',')) {
    const auto a = cell.find_first_not_of(" \t\r\"");
    const auto b = cell.find_last_not_of(" \t\r\"");
    out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  return out;
}

bool parse_bool(const std::string& v, const std::string& path, int line) {
  const std::string s = to_lower(v);
  if (s == "1" || s == "true" || s == "yes") return true;
  if (s == "0" || s == "false" || s == "no" || s.empty()) return false;
  throw ConfigError(path,
                    "line " + std::to_string(line) + ": expected true/false, got '" + v + "'");
}

int parse_int(const std::string& v, int lo, int hi, const std::string& path, int line,
              const char* what) {
  try {
    std::size_t used = 0;
    const int x = std::stoi(v, &used);
    if (used == v.size() && x >= lo && x <= hi) return x;
  } catch (const std::exception&) {
  }
  throw ConfigError(path, "line " + std::to_string(line) + ": " + what + " must be an integer in " +
                              std::to_string(lo) + ".." + std::to_string(hi) + ", got '" + v + "'");
}

LabelTable read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // a UTF-8 byte-order mark
  require_utf8(path, 1, text);
  const std::vector<std::string> header = split_csv(text);
  auto column = [&](const char* name) {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (to_lower(header[i]) == name) return static_cast<int>(i);
    }
    return -1;
  };
  const int c_id = column("id"), c_name = column("name"), c_r = column("r"), c_g = column("g"),
            c_b = column("b"), c_removable = column("removable"), c_critical = column("critical");
  if (c_name < 0 || c_r < 0 || c_g < 0 || c_b < 0) {
    throw ConfigError(path,
                      "line 1: expected a header with columns name,r,g,b (and optionally "
                      "id, removable, critical), got '" +
                          text + "'");
  }
  LabelTable table;
  int line = 1;
  int next_id = 1;
  while (std::getline(in, text)) {
    ++line;
    require_utf8(path, line, text);
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> cells = split_csv(text);
    const int needed = std::max({c_id, c_name, c_r, c_g, c_b, c_removable, c_critical}) + 1;
    if (static_cast<int>(cells.size()) < std::max({c_name, c_r, c_g, c_b}) + 1) {
      throw ConfigError(path, "line " + std::to_string(line) + ": expected " +
                                  std::to_string(needed) + " columns, got " +
                                  std::to_string(cells.size()));
    }
    Label l;
    l.id = static_cast<std::uint16_t>(c_id >= 0 ? parse_int(cells[c_id], 1, 65535, path, line, "id")
                                                : next_id);
    next_id = l.id + 1;
    l.name = cells[c_name];
    l.color = {static_cast<std::uint8_t>(parse_int(cells[c_r], 0, 255, path, line, "r")),
               static_cast<std::uint8_t>(parse_int(cells[c_g], 0, 255, path, line, "g")),
               static_cast<std::uint8_t>(parse_int(cells[c_b], 0, 255, path, line, "b"))};
    if (c_removable >= 0 && c_removable < static_cast<int>(cells.size())) {
      l.removable = parse_bool(cells[c_removable], path, line);
    }
    if (c_critical >= 0 && c_critical < static_cast<int>(cells.size())) {
      l.critical = parse_bool(cells[c_critical], path, line);
    }
    try {
      table.add(l);
    } catch (const ArgumentError& e) {
      throw ConfigError(path, "line " + std::to_string(line) + ": " + e.what());
    }
  }
  if (table.empty()) throw ConfigError(path, "no labels after the header");
  return table;
}

LabelTable read_yaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const YAML::Node list = root.IsMap() && root["labels"] ? root["labels"] : root;
  if (!list.IsSequence()) throw ConfigError(path, "expected a list of labels (or labels: [...])");
  LabelTable table;
  for (const YAML::Node& n : list) {
    const std::string where = "line " + std::to_string(n.Mark().line + 1) + ": ";
    try {
      Label l;
      if (!n["id"] || !n["name"] || !n["color"]) {
        throw ConfigError(path, where + "a label needs id, name and color");
      }
      const int id = n["id"].as<int>();
      if (id < 1 || id > 65535) throw ConfigError(path, where + "id must be in 1..65535");
      l.id = static_cast<std::uint16_t>(id);
      l.name = n["name"].as<std::string>();
      require_utf8(path, n["name"].Mark().line + 1, l.name);
      const YAML::Node c = n["color"];
      if (!c.IsSequence() || c.size() != 3) {
        throw ConfigError(path, where + "color must be [r, g, b] in 0..255");
      }
      for (int i = 0; i < 3; ++i) {
        const int v = c[i].as<int>();
        if (v < 0 || v > 255) throw ConfigError(path, where + "color must be [r, g, b] in 0..255");
        l.color[i] = static_cast<std::uint8_t>(v);
      }
      if (n["removable"]) l.removable = n["removable"].as<bool>();
      if (n["critical"]) l.critical = n["critical"].as<bool>();
      table.add(l);
    } catch (const YAML::Exception& e) {
      throw ConfigError(path, where + e.msg);
    } catch (const ArgumentError& e) {
      throw ConfigError(path, where + e.what());
    }
  }
  return table;
}

}  // namespace

LabelTable read_label_table(const std::string& path) {
  require_regular_file(path, "label table");
  const std::string ext = to_lower(std::filesystem::path(path).extension().string());
  if (ext == ".csv") return read_csv(path);
  if (ext == ".yaml" || ext == ".yml") return read_yaml(path);
  throw ConfigError(path, "a label table must be .csv or .yaml, got '" + ext + "'");
}

void write_label_table(const std::string& path, const LabelTable& table) {
  std::ofstream out(path);
  if (!out)
    throw ConfigError(path, std::string("cannot write the label table: ") + std::strerror(errno));
  out << "id,name,r,g,b,removable,critical\n";
  for (const Label& l : table.labels()) {
    out << l.id << "," << l.name << "," << int(l.color[0]) << "," << int(l.color[1]) << ","
        << int(l.color[2]) << "," << (l.removable ? 1 : 0) << "," << (l.critical ? 1 : 0) << "\n";
  }
  if (!out)
    throw ConfigError(path, std::string("cannot write the label table: ") + std::strerror(errno));
}

}  // namespace ambfplus
