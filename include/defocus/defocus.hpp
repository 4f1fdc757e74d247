// SPDX-License-Identifier: LGPL-2.1-or-later
// The whole public API of libdefocus: find_package(defocus) + target defocus::defocus, or
// pkg-config defocus. See Filter.hpp for the filter, Settings.hpp for what it takes, Source.hpp
// for reading the inputs the command line reads (as Frame.hpp's frames), Focus.hpp for choosing
// the focus from depth yourself, Log.hpp for where its messages go.
#pragma once

#include "defocus/Filter.hpp"
#include "defocus/Focus.hpp"
#include "defocus/Frame.hpp"
#include "defocus/Log.hpp"
#include "defocus/Settings.hpp"
#include "defocus/Source.hpp"
