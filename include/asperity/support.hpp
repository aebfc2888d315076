// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/core/support.hpp (the core layer); this forwarding header goes after one release.
#include "asperity/core/support.hpp"
