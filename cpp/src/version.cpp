#include "ambfplus/version.h"

namespace ambfplus {

const char* version() { return AMBFPLUS_VERSION_STRING; }

}  // namespace ambfplus
