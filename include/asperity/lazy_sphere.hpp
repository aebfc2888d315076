// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/core/lazy_sphere.hpp (the core layer); this forwarding header goes after one release.
#include "asperity/core/lazy_sphere.hpp"
