#pragma once

// Keyword options: how Python's keywords and a file's keys set the fields of a spec. One table
// per spec maps each key to a setter; both the bindings (from kwargs) and the ADF loader (from a
// block's keys, where they are the same) go through it, so a key means the same everywhere and a
// bad value gets the same message.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "ambfplus/errors.h"
#include "ambfplus/export.h"

namespace ambfplus {

class Object;
struct OptionEntry;
/// A mapping of options in the order given (a Python dict, a YAML mapping).
using OptionMap = std::vector<OptionEntry>;

/// One option's value as a caller gave it: nothing, a boolean, an integer, a real number, text, a
/// list, a mapping or an object of a world. The typed reads throw ArgumentTypeError naming the
/// key and what was expected.
class AMBFPLUS_API OptionValue {
 public:
  enum class Type { kNone, kBool, kInteger, kReal, kText, kList, kMap, kObject };

  OptionValue() = default;
  OptionValue(bool value) : value_(value) {}                      // NOLINT: implicit on purpose
  OptionValue(int value) : value_(std::int64_t{value}) {}         // NOLINT
  OptionValue(std::int64_t value) : value_(value) {}              // NOLINT
  OptionValue(double value) : value_(value) {}                    // NOLINT
  OptionValue(std::string value) : value_(std::move(value)) {}    // NOLINT
  OptionValue(const char* value) : value_(std::string(value)) {}  // NOLINT
  OptionValue(std::vector<OptionValue> list);                     // NOLINT
  OptionValue(Object* object) : value_(object) {}                 // NOLINT
  /// A mapping of keys to values.
  static OptionValue mapping(OptionMap map);
  /// A list of numbers.
  static OptionValue from_numbers(const std::vector<double>& values);

  Type type() const { return static_cast<Type>(value_.index()); }
  bool is_none() const { return type() == Type::kNone; }
  bool is_list() const { return type() == Type::kList; }
  bool is_map() const { return type() == Type::kMap; }
  bool is_text() const { return type() == Type::kText; }

  /// True or False (or the integers 1 and 0).
  bool boolean(const std::string& key) const;
  /// A real number (an integer is one too); not checked for finiteness (validate() does that).
  double number(const std::string& key) const;
  /// A whole number within int's range (a real number without a fraction is one too).
  int integer(const std::string& key) const;
  const std::string& text(const std::string& key) const;
  const std::vector<OptionValue>& list(const std::string& key) const;
  const OptionMap& map(const std::string& key) const;
  /// An object, or nullptr for none.
  Object* object(const std::string& key) const;

  /// A list of numbers of any length (one number is a list of one).
  std::vector<double> numbers(const std::string& key) const;
  std::vector<int> integers(const std::string& key) const;
  /// (x, y, z): a list of three numbers.
  Eigen::Vector3d vector3(const std::string& key) const;
  /// A 4x4 matrix: four rows of four numbers (or 16 numbers, row by row).
  Eigen::Matrix4d matrix4(const std::string& key) const;
  /// RGB or RGBA in 0..1 (alpha 1 when three are given).
  std::array<float, 4> rgba(const std::string& key) const;

  /// What the value is, for messages: "the number 3", "the text 'x'", "a list of 2".
  std::string describe() const;

 private:
  struct List;
  struct Map;
  [[noreturn]] void wrong(const std::string& key, const char* expected) const;
  std::variant<std::monostate, bool, std::int64_t, double, std::string, std::shared_ptr<List>,
               std::shared_ptr<Map>, Object*>
      value_;
};

/// One key and its value.
struct AMBFPLUS_API OptionEntry {
  std::string key;
  OptionValue value;
};

/// The value under key in a mapping, or nullptr.
AMBFPLUS_API const OptionValue* find_option(const OptionMap& map, const std::string& key);

/// Keys are matched with spaces and underscores alike ("burr diameters" is "burr_diameters").
AMBFPLUS_API std::string option_key(const std::string& key);

/// The keyword options of one spec: each key's setter, its type (as Python writes it, for docs
/// and stubs) and a line of help; an unknown key is refused naming the known ones.
template <typename Spec>
class OptionTable {
 public:
  using Setter = std::function<void(Spec&, const OptionValue&, const std::string& key)>;
  struct Option {
    std::string key;   ///< Python's name (underscores)
    std::string type;  ///< Python's type annotation, e.g. "float" or "tuple[float, float, float]"
    std::string help;  ///< one line
    Setter set;
    std::vector<std::string> aliases{};  ///< other names of the same key (a file's)
  };
  /// Cross-key rules after every option is set, told which keys were given (Python's names).
  using Finish = std::function<void(Spec&, const std::vector<std::string>& given)>;

  /// caller names the options in messages: a function ("add_body()") or what a mapping is
  /// ("controller").
  OptionTable(std::string caller, std::vector<Option> options, Finish finish = {})
      : caller_(std::move(caller)), options_(std::move(options)), finish_(std::move(finish)) {}

  /// Sets every option given (None leaves a field as it is), then applies the cross-key rules.
  void apply(Spec& spec, const OptionMap& options) const {
    std::vector<std::string> given;
    for (const OptionEntry& e : options) {
      if (e.value.is_none()) continue;
      given.push_back(set(spec, e.key, e.value));
    }
    if (finish_) finish_(spec, given);
  }

  /// Sets one option; returns its name (Python's). ArgumentTypeError for an unknown key.
  std::string set(Spec& spec, const std::string& key, const OptionValue& value) const {
    const Option* option = find(key);
    if (option == nullptr) {
      // Keywords of a function ("add_body()") as Python words it; keys of a mapping otherwise.
      if (!caller_.empty() && caller_.back() == ')') {
        throw ArgumentTypeError(caller_ + " got an unexpected keyword argument '" + key +
                                "'; it takes " + known_keys());
      }
      throw ArgumentTypeError("unknown " + caller_ + " key '" + key + "': expected " +
                              known_keys());
    }
    option->set(spec, value, key);
    return option->key;
  }

  /// The option a key names (Python's name or an alias; spaces and underscores alike).
  const Option* find(const std::string& key) const {
    const std::string k = option_key(key);
    for (const Option& o : options_) {
      if (o.key == k) return &o;
      for (const std::string& a : o.aliases) {
        if (option_key(a) == k) return &o;
      }
    }
    return nullptr;
  }

  const std::string& caller() const { return caller_; }
  const std::vector<Option>& options() const { return options_; }
  /// "a, b and c".
  std::string known_keys() const {
    std::string out;
    for (std::size_t i = 0; i < options_.size(); ++i) {
      out += (i == 0 ? "" : (i + 1 == options_.size() ? " and " : ", ")) + options_[i].key;
    }
    return out;
  }

 private:
  std::string caller_;
  std::vector<Option> options_;
  Finish finish_;
};

/// The name of an option's kind, for listings: "box, sphere or cylinder".
AMBFPLUS_API std::string one_of(const std::vector<std::string>& names);

}  // namespace ambfplus
