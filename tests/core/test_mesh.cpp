// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh bodies: reading and checks, mass properties against exact and analytic values, area-uniform
// tiling, the exact support query on flat faces, impacts with the full inertia tensor, PLY export.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "app/io/mesh_io.hpp"
#include "asperity/core/body_impact.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/core/support.hpp"

using namespace asperity;

namespace {

const std::filesystem::path kMeshes = ASPERITY_MESH_DIR;

// Axis-aligned box [o, o + (a,b,c)] as 12 outward triangles.
TriangleMesh box(Vec3 o, double a, double b, double c) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back(o + Vec3(i & 1 ? a : 0, i & 2 ? b : 0, i & 4 ? c : 0));
  m.faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
             {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

std::filesystem::path temp_file(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("asperity-test-mesh-" + std::to_string(::getpid()) + "-" + name);
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST(Mesh, ReadsTheCommittedMeshes) {
  for (const char* name : {"icosphere.off", "ellipsoid.off", "rounded_cube.off"}) {
    const TriangleMesh m = read_mesh(kMeshes / name);
    EXPECT_GE(m.faces.size(), 1000u) << name;
    EXPECT_LE(m.faces.size(), 5000u) << name;
    EXPECT_EQ(m.vertices.size() + m.faces.size() / 2, m.faces.size() + 2) << name;  // Euler: V - E + F = 2
  }
}

TEST(Mesh, RefusesBadMeshesNamingTheFile) {
  auto expect_error = [](const std::filesystem::path& p, const std::string& what) {
    try {
      read_mesh(p);
      FAIL() << "no error for " << p;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error("/nonexistent/x.off", "does not exist");
  expect_error(temp_file("open.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "not closed");
  // The box with every face flipped: closed, but inward.
  const TriangleMesh b = box(Vec3::Zero(), 1, 1, 1);
  std::ostringstream os;
  os << "OFF\n8 12 0\n";
  for (const auto& v : b.vertices) os << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& f : b.faces) os << "3 " << f[0] << " " << f[2] << " " << f[1] << "\n";
  expect_error(temp_file("inward.off", os.str()), "outward");
  expect_error(temp_file("garbage.off", "this is no mesh\n"), "could not be read");
  EXPECT_THROW(read_mesh(kMeshes / "icosphere.off", -1.0), std::invalid_argument);
}

TEST(Mesh, MassPropertiesOfABoxAreExact) {
  const double a = 2e-3, b = 3e-3, c = 5e-3, rho = 7850;
  const Vec3 o(0.1, -0.2, 0.3);  // far from the origin: no cancellation
  const MassProperties p = mass_properties(box(o, a, b, c), rho);
  const double M = rho * a * b * c;
  EXPECT_NEAR(p.volume, a * b * c, 1e-12 * a * b * c);
  EXPECT_NEAR(p.mass, M, 1e-12 * M);
  EXPECT_NEAR(p.area, 2 * (a * b + b * c + a * c), 1e-12 * a * b);
  EXPECT_NEAR((p.centroid - (o + Vec3(a, b, c) / 2)).norm(), 0.0, 1e-13);
  const Eigen::Matrix3d J = Eigen::Vector3d(M / 12 * (b * b + c * c), M / 12 * (a * a + c * c), M / 12 * (a * a + b * b)).asDiagonal();
  EXPECT_LT((p.inertia - J).norm(), 1e-9 * J.norm());
  EXPECT_THROW(mass_properties(box(o, a, b, c), 0.0), std::invalid_argument);
}

TEST(Mesh, MassPropertiesApproachTheAnalyticSphereAndEllipsoid) {
  // Inscribed polyhedra of 1280 faces: volume and inertia a little below the smooth body's
  // (measured: sphere volume -1.2%), so 2.5% tolerance; the centroid is at the origin by symmetry.
  const double rho = 1000;
  const MassProperties s = mass_properties(read_mesh(kMeshes / "icosphere.off"), rho);
  const double R = 3e-3, Ms = rho * 4.0 / 3.0 * std::numbers::pi * R * R * R;
  EXPECT_NEAR(s.mass / Ms, 1.0, 0.025);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.inertia(k, k) / (0.4 * Ms * R * R), 1.0, 0.04);
  EXPECT_LT(s.centroid.norm(), 1e-12);
  const MassProperties e = mass_properties(read_mesh(kMeshes / "ellipsoid.off"), rho);
  const double A = 4e-3, B = 3e-3, C = 2.25e-3, Me = rho * 4.0 / 3.0 * std::numbers::pi * A * B * C;
  EXPECT_NEAR(e.mass / Me, 1.0, 0.025);
  EXPECT_NEAR(e.inertia(0, 0) / (Me / 5 * (B * B + C * C)), 1.0, 0.04);
  EXPECT_NEAR(e.inertia(1, 1) / (Me / 5 * (A * A + C * C)), 1.0, 0.04);
  EXPECT_NEAR(e.inertia(2, 2) / (Me / 5 * (A * A + B * B)), 1.0, 0.04);
  EXPECT_LT(std::abs(e.inertia(0, 1)), 1e-6 * e.inertia(0, 0));
  // Deliberately wrong: the sphere's law for the ellipsoid is far outside the tolerance.
  EXPECT_GT(std::abs(e.inertia(0, 0) / (0.4 * Me * A * A) - 1.0), 0.1);
}

TEST(Mesh, AsperitiesAreUniformByAreaAndReproducible) {
  // A 1 x 2 x 4 box: face areas 2, 4, 8 (x2). Fraction of centres on each face pair vs area
  // fraction, binomial, 5 sigma at n = 20000.
  const TriangleMesh m = box(Vec3::Zero(), 1e-3, 2e-3, 4e-3);
  const std::uint64_t n = 20000;
  omp_set_num_threads(1);
  const RoughBody b1 = make_rough_mesh_body(m, n, RadiusDistribution::fixed(1e-6), 1000, 3, 1);
  omp_set_num_threads(2);
  const RoughBody b2 = make_rough_mesh_body(m, n, RadiusDistribution::fixed(1e-6), 1000, 3, 1);
  ASSERT_EQ(b1.centres, b2.centres);
  int on_x = 0, on_y = 0, on_z = 0;
  for (const Vec3& c : b1.centres) {
    const Vec3 p = c + Vec3(0.5e-3, 1e-3, 2e-3);  // back to box coordinates
    on_x += std::abs(p.x()) < 1e-12 || std::abs(p.x() - 1e-3) < 1e-12;
    on_y += std::abs(p.y()) < 1e-12 || std::abs(p.y() - 2e-3) < 1e-12;
    on_z += std::abs(p.z()) < 1e-12 || std::abs(p.z() - 4e-3) < 1e-12;
  }
  const double total = 2 * (2 + 4 + 8);
  auto check = [&](int count, double area) {
    const double f = 2 * area / total;
    EXPECT_NEAR(count, f * n, 5 * std::sqrt(n * f * (1 - f)));
  };
  check(on_x, 8.0);  // faces normal to x: 2 x 4
  check(on_y, 4.0);
  check(on_z, 2.0);
  // Ellipsoid map: every centre on the smooth ellipsoid.
  const RoughBody e = make_rough_mesh_body(read_mesh(kMeshes / "ellipsoid.off"), 2000, RadiusDistribution::fixed(1e-6), 1000,
                                           3, 1, ellipsoid_surface(4e-3, 3e-3, 2.25e-3));
  const MassProperties mp = mass_properties(read_mesh(kMeshes / "ellipsoid.off"), 1000);
  for (const Vec3& c : e.centres) {
    const Vec3 p = c + mp.centroid;
    ASSERT_NEAR(std::pow(p.x() / 4e-3, 2) + std::pow(p.y() / 3e-3, 2) + std::pow(p.z() / 2.25e-3, 2), 1.0, 1e-12);
  }
}

TEST(Mesh, SupportQueryIsExactOnFlatFaces) {
  // Rounded cube with equal radii: directions along a face normal tie the whole face up to
  // rounding; the tree must still equal the brute-force scan.
  const RoughBody b = make_rough_mesh_body(read_mesh(kMeshes / "rounded_cube.off"), 20000, RadiusDistribution::fixed(1e-6),
                                           1000, 5, 1);
  const auto q = make_support_tree(b.centres, b.radii);
  std::vector<Vec3> dirs{{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {0, -1, 0}, Vec3(1, 1, 0).normalized(), Vec3(1, 1, 1).normalized()};
  for (int k = 0; k < 2000; ++k) {
    Stream s(1, Purpose::test, k);
    dirs.push_back(uniform_on_sphere(s.uniform0(), s.uniform0()));
  }
  for (const Vec3& d : dirs) ASSERT_EQ(q->support(d), brute_support(b.centres, b.radii, d));
}

TEST(Mesh, ImpactUsesTheFullInertiaTensor) {
  // Angular momentum about the contact point is conserved by the impulse:
  // J_w (Omega' - Omega) = r x M (V' - V) with J_w = Q J Q^T; a wrong frame for J breaks it.
  const RoughBody b = make_rough_mesh_body(read_mesh(kMeshes / "ellipsoid.off"), 5000,
                                           RadiusDistribution::discrete({1e-6, 5e-7}, {0.3, 0.7}), 7850, 2, 1,
                                           ellipsoid_surface(4e-3, 3e-3, 2.25e-3));
  const auto q = make_support_tree(b.centres, b.radii);
  const auto eps = viscoelastic_pade14();
  int impacts = 0;
  for (int k = 0; k < 200; ++k) {
    Stream s(2, Purpose::test, k);
    const Rotation rot = random_rotation(s);
    const BodyImpact bi = body_impact(b, *q, rot, Vec3(0, 0, -1.3), Vec3(0.2, 0.1, 0), *eps);
    if (!bi.result) continue;
    ++impacts;
    const auto& res = *bi.result;
    const Eigen::Matrix3d J = world_rigid_body(b, rot).inertia;
    const Vec3 dL = J * (res.Omega_after - Vec3(0.2, 0.1, 0));
    const Vec3 want = bi.contact.r.cross(b.mass * (res.V_after - Vec3(0, 0, -1.3)));
    ASSERT_LT((dL - want).norm(), 1e-9 * want.norm() + 1e-20);
    // The body-frame inertia instead of the world-frame one violates it (power of this check).
    if (k < 20) {
      EXPECT_GT((b.inertia * (res.Omega_after - Vec3(0.2, 0.1, 0)) - want).norm(), 1e-6 * want.norm());
    }
    // Energy does not grow (eps_n <= 1, eps_t = 1).
    const double E0 = 0.5 * b.mass * 1.3 * 1.3 + 0.5 * Vec3(0.2, 0.1, 0).dot(J * Vec3(0.2, 0.1, 0));
    const double E1 = 0.5 * b.mass * res.V_after.squaredNorm() + 0.5 * res.Omega_after.dot(J * res.Omega_after);
    ASSERT_LE(E1, E0 * (1 + 1e-12));
  }
  EXPECT_GT(impacts, 150);
}

TEST(Mesh, PlyExport) {
  const TriangleMesh m = read_mesh(kMeshes / "icosphere.off");
  const RoughBody b = make_rough_mesh_body(m, 50, RadiusDistribution::fixed(5e-5), 1000, 1, 1);
  const auto dir = std::filesystem::temp_directory_path() / ("asperity-ply-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  write_ply(dir / "points.ply", b, PlyStyle::points);
  std::ifstream in(dir / "points.ply");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("element vertex 50\n"), std::string::npos);
  EXPECT_NE(text.find("property double radius"), std::string::npos);
  write_ply(dir / "spheres.ply", b, PlyStyle::spheres, 2.0, &m, -mass_properties(m, 1000).centroid);
  // Header counts match the body: 12 vertices and 20 faces per asperity, plus the base mesh; and
  // the file has exactly that many data lines.
  std::ifstream sp(dir / "spheres.ply");
  std::string line;
  std::size_t lines = 0, header = 0;
  bool in_header = true;
  while (std::getline(sp, line)) {
    ++lines;
    if (in_header) ++header;
    if (line == "end_header") in_header = false;
  }
  const std::size_t nv = 12 * 50 + m.vertices.size(), nf = 20 * 50 + m.faces.size();
  std::ifstream sp2(dir / "spheres.ply");
  std::string all((std::istreambuf_iterator<char>(sp2)), {});
  EXPECT_NE(all.find("element vertex " + std::to_string(nv) + "\n"), std::string::npos);
  EXPECT_NE(all.find("element face " + std::to_string(nf) + "\n"), std::string::npos);
  EXPECT_EQ(lines - header, nv + nf);
  EXPECT_THROW(write_ply(dir / "x.ply", b, PlyStyle::spheres, -1.0), std::invalid_argument);
  // Issue 33 item 5: the body's name (its mesh file's) cannot write header lines of its own: a
  // newline, a control character, a backslash or a non-ASCII byte is escaped in the comment line.
  RoughBody named = b;
  named.name = "ply\nelement vertex 0\nend_header\x1b[2J\\\xc3\xa9.off";
  write_ply(dir / "named.ply", named, PlyStyle::points);
  std::ifstream nin(dir / "named.ply");
  std::vector<std::string> head;
  for (std::string l; std::getline(nin, l) && l != "end_header";) head.push_back(l);
  ASSERT_EQ(head.size(), 8u) << "one comment line, no injected lines";
  EXPECT_EQ(head[2], "comment asperity rough body 'ply\\x0aelement vertex 0\\x0aend_header\\x1b[2J\\\\\\xc3\\xa9.off', body frame, metres");
  for (const auto& l : head)
    for (char c : l) EXPECT_LT(static_cast<unsigned char>(c), 0x80) << l;
  std::filesystem::remove_all(dir);
}
