// SPDX-License-Identifier: GPL-3.0-or-later
// A deliberate violation for layers.includes.io_power: I/O including the plan.
#include "asperity/app/plan.hpp"
