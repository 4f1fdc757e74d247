// SPDX-License-Identifier: LGPL-2.1-or-later
// DEFOCUS_API marks what libdefocus exports; everything else in the library is hidden.
#pragma once

#if defined(_WIN32)
#define DEFOCUS_API
#else
#define DEFOCUS_API __attribute__((visibility("default")))
#endif
