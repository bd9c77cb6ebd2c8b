#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

/// One anatomical structure of a segmented volume. Id 0 means "no label" and is never in a table.
struct AMBFPLUS_API Label {
  std::uint16_t id = 0;
  std::string name;
  std::array<std::uint8_t, 3> color{255, 255, 255};  ///< RGB, as in the slice images
  bool removable = true;                             ///< the drill may remove it
  bool critical = false;                             ///< touching it is an error (nerves, vessels)
};

/// The labels of a volume, by id. Ids are unique and >= 1; names are unique.
class AMBFPLUS_API LabelTable {
 public:
  LabelTable() = default;
  /// Throws ArgumentError for a duplicate or zero id, or a duplicate name.
  explicit LabelTable(std::vector<Label> labels);

  const std::vector<Label>& labels() const { return labels_; }
  bool empty() const { return labels_.empty(); }
  std::size_t size() const { return labels_.size(); }
  /// The label with this id, or nullptr.
  const Label* find(std::uint16_t id) const;
  /// The label with this name, or nullptr.
  const Label* find(const std::string& name) const;
  /// The largest id in the table (0 when empty).
  std::uint16_t max_id() const;
  /// The id whose colour is nearest (Euclidean in RGB) to this one; 0 if the table is empty.
  std::uint16_t nearest(const std::array<std::uint8_t, 3>& rgb) const;
  /// Adds a label; throws ArgumentError on a duplicate id or name.
  void add(const Label& label);

 private:
  std::vector<Label> labels_;
};

/// The id of a structure named by its label name or by its id written as a number ("3"), for
/// every caller that lets users name structures (distance fields, metrics, tasks). Throws
/// NotFound naming `what` and the table's names when there is no such label.
AMBFPLUS_API std::uint16_t resolve_label(const LabelTable& table, const std::string& name,
                                         const std::string& what);

/// Whether a label is bone, for the looks' bone texture (Camera::looks): its name names a bone
/// or a bony structure (a word of "bone", "bony", "osse", "ossic", "malleus", "incus", "stapes",
/// "labyrinth", "cochlea", "mastoid", "cortex", "tegmen", "petrous", "skull", "zygom", "mandib",
/// "condyl", "vertebr", case ignored), or it is the only label of its table (a one-material
/// volume such as a thresholded CT). Nerves, vessels, dura, canals and joints are not.
AMBFPLUS_API bool is_bone(const LabelTable& table, const Label& label);

/// Reads a label table from CSV or YAML (by extension). CSV: a header row, then rows of
/// `name,r,g,b` (ids 1, 2, ... in file order) or with an `id` column and optional `removable` and
/// `critical` columns. YAML: a list (or `labels:` list) of {id, name, color: [r, g, b], removable,
/// critical}. Throws AssetNotFound or ConfigError naming the file and line.
AMBFPLUS_API LabelTable read_label_table(const std::string& path);

/// Writes a label table as CSV (`id,name,r,g,b,removable,critical`).
AMBFPLUS_API void write_label_table(const std::string& path, const LabelTable& table);

}  // namespace ambfplus
