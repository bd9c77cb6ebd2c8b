#include "ambfplus/scene/options.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace ambfplus {

struct OptionValue::List {
  std::vector<OptionValue> items;
};
struct OptionValue::Map {
  OptionMap entries;
};

OptionValue::OptionValue(std::vector<OptionValue> list)
    : value_(std::make_shared<List>(List{std::move(list)})) {}

OptionValue OptionValue::mapping(OptionMap map) {
  OptionValue v;
  v.value_ = std::make_shared<Map>(Map{std::move(map)});
  return v;
}

OptionValue OptionValue::from_numbers(const std::vector<double>& values) {
  std::vector<OptionValue> items(values.begin(), values.end());
  return OptionValue(std::move(items));
}

std::string OptionValue::describe() const {
  std::ostringstream s;
  switch (type()) {
    case Type::kNone:
      return "None";
    case Type::kBool:
      return std::get<bool>(value_) ? "True" : "False";
    case Type::kInteger:
      s << "the integer " << std::get<std::int64_t>(value_);
      return s.str();
    case Type::kReal:
      s << "the number " << std::get<double>(value_);
      return s.str();
    case Type::kText:
      return "the text '" + std::get<std::string>(value_) + "'";
    case Type::kList:
      s << "a list of " << std::get<std::shared_ptr<List>>(value_)->items.size();
      return s.str();
    case Type::kMap:
      return "a mapping";
    case Type::kObject:
      return "an object";
  }
  return "?";
}

void OptionValue::wrong(const std::string& key, const char* expected) const {
  throw ArgumentTypeError("'" + key + "' must be " + expected + ", got " + describe());
}

bool OptionValue::boolean(const std::string& key) const {
  // 0 and 1 too: the C API of plugins passes numbers.
  if (type() == Type::kInteger) {
    const std::int64_t v = std::get<std::int64_t>(value_);
    if (v == 0 || v == 1) return v == 1;
  }
  if (type() != Type::kBool) wrong(key, "True or False");
  return std::get<bool>(value_);
}

double OptionValue::number(const std::string& key) const {
  if (type() == Type::kReal) return std::get<double>(value_);
  if (type() == Type::kInteger) return static_cast<double>(std::get<std::int64_t>(value_));
  wrong(key, "a number");
}

int OptionValue::integer(const std::string& key) const {
  std::int64_t v = 0;
  if (type() == Type::kInteger) {
    v = std::get<std::int64_t>(value_);
  } else if (type() == Type::kReal &&
             std::floor(std::get<double>(value_)) == std::get<double>(value_)) {
    v = static_cast<std::int64_t>(std::get<double>(value_));
  } else {
    wrong(key, "an integer");
  }
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    wrong(key, "an integer in int's range");
  }
  return static_cast<int>(v);
}

const std::string& OptionValue::text(const std::string& key) const {
  if (type() != Type::kText) wrong(key, "text");
  return std::get<std::string>(value_);
}

const std::vector<OptionValue>& OptionValue::list(const std::string& key) const {
  if (type() != Type::kList) wrong(key, "a list");
  return std::get<std::shared_ptr<List>>(value_)->items;
}

const OptionMap& OptionValue::map(const std::string& key) const {
  if (type() != Type::kMap) wrong(key, "a mapping");
  return std::get<std::shared_ptr<Map>>(value_)->entries;
}

Object* OptionValue::object(const std::string& key) const {
  if (type() == Type::kNone) return nullptr;
  if (type() != Type::kObject) wrong(key, "an object of the world");
  return std::get<Object*>(value_);
}

std::vector<double> OptionValue::numbers(const std::string& key) const {
  if (type() == Type::kReal || type() == Type::kInteger) return {number(key)};  // a list of one
  if (type() != Type::kList) wrong(key, "a list of numbers");
  std::vector<double> out;
  for (const OptionValue& v : list(key)) {
    if (v.type() != Type::kReal && v.type() != Type::kInteger) wrong(key, "a list of numbers");
    out.push_back(v.number(key));
  }
  return out;
}

std::vector<int> OptionValue::integers(const std::string& key) const {
  if (type() == Type::kReal || type() == Type::kInteger) return {integer(key)};  // a list of one
  if (type() != Type::kList) wrong(key, "a list of integers");
  std::vector<int> out;
  for (const OptionValue& v : list(key)) out.push_back(v.integer(key));
  return out;
}

Eigen::Vector3d OptionValue::vector3(const std::string& key) const {
  if (type() != Type::kList || list(key).size() != 3) wrong(key, "three numbers (x, y, z)");
  const std::vector<double> v = numbers(key);
  return {v[0], v[1], v[2]};
}

Eigen::Matrix4d OptionValue::matrix4(const std::string& key) const {
  const char* expected = "a 4x4 matrix";
  if (type() != Type::kList) wrong(key, expected);
  std::vector<double> flat;
  for (const OptionValue& row : list(key)) {
    if (row.type() == Type::kList) {
      const std::vector<double> r = row.numbers(key);
      if (r.size() != 4) wrong(key, expected);
      flat.insert(flat.end(), r.begin(), r.end());
    } else {
      flat.push_back(row.number(key));
    }
  }
  if (flat.size() != 16) wrong(key, expected);
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = flat[static_cast<std::size_t>(i)];
  return m;
}

std::array<float, 4> OptionValue::rgba(const std::string& key) const {
  if (type() != Type::kList) wrong(key, "(r, g, b) or (r, g, b, a) in 0..1");
  const std::vector<double> c = numbers(key);
  if (c.size() != 3 && c.size() != 4) {
    throw ArgumentError(key + " must be (r, g, b) or (r, g, b, a) in 0..1");
  }
  std::array<float, 4> out{0, 0, 0, 1};
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!(c[i] >= 0.0 && c[i] <= 1.0)) {
      throw ArgumentError(key + " components must be in 0..1");
    }
    out[i] = static_cast<float>(c[i]);
  }
  return out;
}

const OptionValue* find_option(const OptionMap& map, const std::string& key) {
  const std::string k = option_key(key);
  for (const OptionEntry& e : map) {
    if (option_key(e.key) == k) return &e.value;
  }
  return nullptr;
}

std::string option_key(const std::string& key) {
  std::string k = key;
  for (char& c : k) {
    if (c == ' ') c = '_';
  }
  return k;
}

std::string one_of(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + names[i];
  }
  return out;
}

}  // namespace ambfplus
