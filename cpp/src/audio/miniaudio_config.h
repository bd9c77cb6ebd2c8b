#pragma once

// miniaudio as the engine uses it: playback only, without its decoders, encoders, generators,
// node graph and engine, and without the backends of other systems. Every file that includes it
// includes it through this header, so all agree on the configuration.

#define MA_NO_DECODING
#define MA_NO_ENCODING
#define MA_NO_GENERATION
#define MA_NO_RESOURCE_MANAGER
#define MA_NO_NODE_GRAPH
#define MA_NO_ENGINE
#define MA_ENABLE_ONLY_SPECIFIC_BACKENDS
#define MA_ENABLE_PULSEAUDIO
#define MA_ENABLE_ALSA
#define MA_ENABLE_JACK
#define MA_ENABLE_NULL
#define MA_ENABLE_CUSTOM  // the engine's virtual output (drill_sound.cpp)

#include "miniaudio/miniaudio.h"
