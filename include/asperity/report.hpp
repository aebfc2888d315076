// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/app/report.hpp (the app layer); this forwarding header goes after one release.
#include "asperity/app/report.hpp"
