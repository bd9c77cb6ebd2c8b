#pragma once

// Symbols are hidden by default; AMBFPLUS_API marks the public ones of libambfplus.
#if defined(_WIN32)
#define AMBFPLUS_API __declspec(dllexport)
#else
#define AMBFPLUS_API __attribute__((visibility("default")))
#endif
