// SPDX-License-Identifier: GPL-3.0-or-later
// Keeps the check from finding no files.
#include "core/format.hpp"
