#pragma once

#include <string>

#include "ambfplus/export.h"
#include "ambfplus/scene/options.h"

namespace ambfplus {

/// A forbidden-region virtual fixture around one structure of a drill's volume. Distances are
/// from the burr's surface to the structure (as Drill::critical_distances() reports them): below
/// `start` the fixture pushes the burr away along the structure's distance field with
/// max_force x (1 - d / start); below `stop` (when > 0) nothing is cut and the burr's goal is
/// held back, so the burr ends `stop` from the structure however hard it is pushed.
struct AMBFPLUS_API FixtureSpec {
  std::string structure;   ///< a label name, or its id written as a number
  double start = 0.001;    ///< m
  double max_force = 1.0;  ///< N at the structure
  double stop = 0.0;       ///< m; 0 for no hard stop
  bool enabled = true;

  /// Throws ArgumentError naming `who` and the value unless start > 0, max_force >= 0 and
  /// 0 <= stop, all finite, and a structure is named.
  void validate(const std::string& who) const;
};

/// A fixture's keys (the entries of a DRILL block's `fixtures` list and of set_fixtures):
/// structure, start, max_force, stop (None for none), enabled.
AMBFPLUS_API const OptionTable<FixtureSpec>& fixture_options();

}  // namespace ambfplus
