// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/experiments/body_bounce.hpp (the experiments layer); its tables, JSON and figures to
// asperity/app/experiment_reports.hpp. This forwarding header goes after one release.
#include "asperity/experiments/body_bounce.hpp"
#include "asperity/app/experiment_reports.hpp"
