// miniaudio's implementation, compiled once (its symbols stay hidden in libambfplus).

#define MINIAUDIO_IMPLEMENTATION
#include "miniaudio_config.h"
