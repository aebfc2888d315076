// SPDX-License-Identifier: GPL-3.0-or-later
// Fuzz target: the mesh reader (asperity::read_mesh) on OFF and PLY files, their list counts above
// all (issue 33 item 2: one face line claiming 4e9 indices made CGAL allocate 12.7 GB).
// Input: the first byte picks the format (even: .off, odd: .ply), the rest is the file.
// Contract: read_mesh returns a mesh or throws std::invalid_argument with a message; any other
// exception, crash or sanitizer report is a bug, and so is an allocation that libFuzzer's
// -malloc_limit_mb (the -rss_limit_mb, 2 GB by default) catches: every count is bounded by the
// bytes of a file of at most 4 kB here.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "app/io/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1 || size > 4096) return 0;
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("asperity-fuzz-mesh-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::filesystem::path file = dir / (data[0] % 2 == 0 ? "m.off" : "m.ply");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const asperity::TriangleMesh m = asperity::read_mesh(file);
    if (m.vertices.empty() || m.faces.empty()) {
      std::fprintf(stderr, "read_mesh returned an empty mesh\n");
      std::abort();
    }
  } catch (const std::invalid_argument& ex) {
    if (std::string(ex.what()).empty()) {
      std::fprintf(stderr, "std::invalid_argument without a message\n");
      std::abort();
    }
  }
  std::filesystem::remove(file);
  return 0;  // any other exception escapes: libFuzzer reports it as a crash
}
