// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Moved: the mesh types to asperity/core/mesh.hpp, reading and PLY export to asperity/app/mesh_io.hpp;
// this forwarding header goes after one release.
#include "asperity/core/mesh.hpp"
#include "asperity/app/mesh_io.hpp"
