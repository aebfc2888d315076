// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Deliberately wrong: a core header that reaches up into app/. cmake/check_layers.cmake must refuse
// this tree (ctest layers.includes.power expects it to fail).
#include "asperity/app/report.hpp"
