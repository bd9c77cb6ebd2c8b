#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

class Object;

/// The columns a step log keeps for one object: its pose (the 4x4 world-from-object matrix, row
/// by row: exact, so a replay can set it back) unless a system leaves it out, then the columns
/// the world's systems add (System::add_step_log_columns), named "<object>.<field>".
class AMBFPLUS_API StepLogColumns {
 public:
  /// Appends one step's values of a column for the object: exactly its width.
  using Recorder = std::function<void(const Object& object, std::vector<double>& out)>;
  struct Field {
    std::string name;  ///< "goal", "force", ...
    int width = 1;     ///< values per step
    Recorder record;
  };

  explicit StepLogColumns(const Object& object) : object_(&object) {}
  const Object& object() const { return *object_; }
  /// Adds the column "<object>.<name>", width values per step. Throws ArgumentError for a
  /// width below 1 or no recorder.
  void add(std::string name, int width, Recorder record);
  /// Leaves the pose column out (an object whose state is not a pose of its own).
  void drop_pose() { pose_ = false; }
  bool pose() const { return pose_; }
  const std::vector<Field>& fields() const { return fields_; }

 private:
  const Object* object_;
  bool pose_ = true;
  std::vector<Field> fields_;
};

/// What a world appends after every step while it logs (World::start_step_log), for
/// recordings: the step, its time, and for each chosen object the columns of its StepLogColumns.
/// With the engine's systems (ambfplus/engine) these are every object's pose but an input
/// device's, plus for a drill its goal (a pose), the force fed back and the sum over its cursors
/// (N), whether the burr spins, the burr index and the leading cursor; for an input device its
/// reading (position, orientation x y z w, buttons) and the force sent to it (N): "drill.pose",
/// "drill.goal", "drill.force", "drill.total_force", "drill.on", "drill.burr", "drill.leading",
/// "hand.position", "hand.orientation", "hand.buttons", "hand.force".
class AMBFPLUS_API StepLog {
 public:
  struct Column {
    std::string name;
    int width = 1;               ///< values per step
    std::vector<double> values;  ///< width per step, step after step
  };

  /// Objects of one world with their columns, logged in this order.
  explicit StepLog(std::vector<StepLogColumns> objects);
  /// Appends the row of a finished step (the world calls it, under its state lock).
  void record(std::int64_t step, double time);
  std::int64_t rows() const { return static_cast<std::int64_t>(steps_.size()); }
  const std::vector<std::int64_t>& steps() const { return steps_; }
  const std::vector<double>& times() const { return times_; }
  const std::vector<Column>& columns() const { return columns_; }
  /// Moves the rows out (a recorder drains them) and starts afresh with the same columns.
  StepLog take();
  /// Whether it logs this object (a removed object must stop being logged first).
  bool logs(const Object& object) const;
  /// Values held in all columns.
  std::size_t values() const;
  /// Drops the n oldest rows (a log nobody drains, at its cap) and counts them.
  void drop_oldest(std::int64_t n);
  /// Rows dropped so far because nobody took them in time.
  std::int64_t dropped() const { return dropped_; }

 private:
  StepLog() = default;
  std::vector<StepLogColumns> objects_;
  std::vector<std::int64_t> steps_;
  std::vector<double> times_;
  std::vector<Column> columns_;
  std::int64_t dropped_ = 0;
};

}  // namespace ambfplus
