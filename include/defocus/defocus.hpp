// The whole public API of libdefocus: find_package(defocus) + target defocus::defocus, or
// pkg-config defocus. See Filter.hpp for the filter and Settings.hpp for what it takes.
#pragma once

#include "defocus/Filter.hpp"
#include "defocus/Settings.hpp"
