// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/experiments/ensemble.hpp (the experiments layer); this forwarding header goes after one release.
#include "asperity/experiments/ensemble.hpp"
