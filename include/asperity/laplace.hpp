// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/laws/laplace.hpp (the laws layer); this forwarding header goes after one release.
#include "asperity/laws/laplace.hpp"
