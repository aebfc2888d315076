// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved to asperity/app/scene.hpp (the app layer); this forwarding header goes after one release.
#include "asperity/app/scene.hpp"
