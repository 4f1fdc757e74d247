// SPDX-License-Identifier: LGPL-2.1-or-later
// Shared by the fuzz targets: a check that survives NDEBUG and reports what broke.
#pragma once

#include <cstdio>
#include <cstdlib>

/// Aborts (a crash for libFuzzer, with the input saved) when an invariant does not hold.
#define FUZZ_CHECK(condition, ...)                                                                  \
    do {                                                                                            \
        if (!(condition)) {                                                                         \
            std::fprintf(stderr, "FUZZ_CHECK failed at %s:%d: %s\n", __FILE__, __LINE__, #condition); \
            std::fprintf(stderr, __VA_ARGS__);                                                      \
            std::fputc('\n', stderr);                                                               \
            std::abort();                                                                           \
        }                                                                                           \
    } while (false)
