#pragma once

#include "ambfplus/export.h"

namespace ambfplus {

/// The package version (from pyproject.toml), e.g. "0.1.0".
AMBFPLUS_API const char* version();

}  // namespace ambfplus
