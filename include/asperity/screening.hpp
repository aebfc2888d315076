// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/core/screening.hpp (the core layer); this forwarding header goes after one release.
#include "asperity/core/screening.hpp"
