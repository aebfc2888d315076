// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/laws/theory.hpp (the laws layer); this forwarding header goes after one release.
#include "asperity/laws/theory.hpp"
