// SPDX-License-Identifier: GPL-3.0-or-later
// Rough spheres and orientations: determinism, uniformity, and that a biased sampler is caught.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <Random123/uniform.hpp>

#include "asperity/core/contact.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/random.hpp"
#include "asperity/laws/statistics.hpp"

using namespace asperity;

namespace {

TEST(Random, StreamsAreCounterBased) {
  Stream a(5, Purpose::test, 17), b(5, Purpose::test, 17), c(5, Purpose::test, 18), d(6, Purpose::test, 17);
  const double a0 = a.uniform();
  EXPECT_EQ(a0, b.uniform());
  EXPECT_NE(a0, c.uniform());
  EXPECT_NE(a0, d.uniform());
  for (int i = 0; i < 1000; ++i) {
    const double u = a.uniform();
    EXPECT_GT(u, 0.0);
    EXPECT_LE(u, 1.0);
  }
}

TEST(Random, StreamsAreFixed) {
  // Every stored result depends on these words (Philox4x64-10 at counter (block, sub), key (seed,
  // purpose << 56 ^ index)); pinned from the out-of-line implementation before bits() was inlined.
  Stream a(5, Purpose::test, 17, 3), b(5, Purpose::test, 17, 3);
  const std::uint64_t want[6] = {0xdf1f3fcca8d066e1ull, 0x22f3cd43cc92c70bull, 0x23d37b86253c4b46ull,
                                 0x975e452064c0231eull, 0xff545645d3c86d99ull, 0x5b85d1fec3e79d1cull};
  for (std::uint64_t w : want) {
    EXPECT_EQ(a.bits(), w);
    EXPECT_EQ(b.uniform(), r123::u01<double>(w));  // the inline uniform() is Random123's u01
  }
  EXPECT_EQ(r123::u01<double>(want[0]), 0x1.be3e7f9951a0dp-1);
  EXPECT_EQ(r123::u01<double>(~std::uint64_t{0}), 1.0);  // (0, 1]: the top word rounds to 1
  Stream c(5, Purpose::test, 1);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t w = c.bits();
    ASSERT_EQ(static_cast<double>(w) * 0x1p-64 + 0x1p-65, r123::u01<double>(w)) << w;
  }
}

TEST(RoughSphere, BitIdenticalForOneAndTwoThreads) {
  const SphereParams p{20000, 3e-3, 6.5e-7};
  omp_set_num_threads(1);
  const auto one = make_rough_sphere(p, 9, 3);
  omp_set_num_threads(2);
  const auto two = make_rough_sphere(p, 9, 3);
  ASSERT_EQ(one.centres.size(), two.centres.size());
  EXPECT_TRUE(std::equal(one.centres.begin(), one.centres.end(), two.centres.begin()));
  const auto other = make_rough_sphere(p, 9, 4);
  EXPECT_NE(one.centres[0], other.centres[0]);
}

TEST(RoughSphere, CentresAreUnitAndUniform) {
  // Uniform on the sphere <=> z uniform on [-1,1] and phi uniform, independent (Archimedes).
  // n = 10^5, KS at alpha = 0.001 on each marginal: a fixed seed makes this deterministic.
  const auto s = make_rough_sphere(SphereParams{100000, 3e-3, 6.5e-7}, 1, 0);
  std::vector<double> z, phi;
  for (const auto& u : s.centres) {
    ASSERT_NEAR(u.norm(), 1.0, 1e-15);
    z.push_back(u.z());
    phi.push_back(std::atan2(u.y(), u.x()));
  }
  std::sort(z.begin(), z.end());
  std::sort(phi.begin(), phi.end());
  EXPECT_GT(ks_one_sample(z, [](double t) { return std::clamp((t + 1) / 2, 0.0, 1.0); }).p, 1e-3);
  EXPECT_GT(ks_one_sample(phi, [](double t) { return std::clamp((t + std::numbers::pi) / (2 * std::numbers::pi), 0.0, 1.0); }).p, 1e-3);
}

TEST(RoughSphere, ValidationNamesTheValue) {
  auto msg = [](SphereParams p) {
    try {
      validate(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(msg({0, 3e-3, 1e-6}).find("asperities"), std::string::npos);
  EXPECT_NE(msg({10, -1, 1e-6}).find("-1"), std::string::npos);
  EXPECT_NE(msg({10, 3e-3, 0}).find("asperity-radius"), std::string::npos);
  EXPECT_NE(msg({10, 3e-3, 3e-3}).find("smaller"), std::string::npos);
  EXPECT_NE(msg({10, std::nan(""), 1e-6}).find("nan"), std::string::npos);
  EXPECT_NE(msg({10, 3e-3, INFINITY}).find("inf"), std::string::npos);
  EXPECT_EQ(msg({1, 3e-3, 1e-6}), "");
}

// Haar measure: the rotation angle w has density (1 - cos w)/pi on [0, pi], so
// F(w) = (w - sin w)/pi; and the rotated down direction is uniform (its z uniform on [-1,1]).
struct HaarCheck {
  double p_angle, p_down;
};
template <class Sampler>
HaarCheck check_haar(Sampler sample, std::size_t n) {
  std::vector<double> w, z;
  for (std::size_t i = 0; i < n; ++i) {
    Stream s(2024, Purpose::test, i);
    const Rotation q = sample(s);
    w.push_back(2 * std::acos(std::min(1.0, std::abs(q.w()))));
    z.push_back(body_down(q).z());
  }
  std::sort(w.begin(), w.end());
  std::sort(z.begin(), z.end());
  const double pa = ks_one_sample(w, [](double t) { return std::clamp((t - std::sin(t)) / std::numbers::pi, 0.0, 1.0); }).p;
  const double pd = ks_one_sample(z, [](double t) { return std::clamp((t + 1) / 2, 0.0, 1.0); }).p;
  return {pa, pd};
}

TEST(Orientation, ShoemakeIsHaar) {
  // n = 10^5 rotations; a correct sampler passes at alpha = 0.001 (fixed seed: deterministic).
  const auto r = check_haar([](Stream& s) { return random_rotation(s); }, 100000);
  EXPECT_GT(r.p_angle, 1e-3);
  EXPECT_GT(r.p_down, 1e-3);
}

TEST(Orientation, BiasedSamplersAreRejected) {
  // Uniform Euler angles (a classic mistake) over-sample the poles; normalising a uniform cube
  // quaternion distorts the angle law. Both must be rejected with overwhelming evidence.
  auto euler = [](Stream& s) {
    const double a = 2 * std::numbers::pi * s.uniform0(), b = std::numbers::pi * s.uniform0(),
                 c = 2 * std::numbers::pi * s.uniform0();
    return Rotation(Eigen::AngleAxisd(a, Vec3::UnitZ()) * Eigen::AngleAxisd(b, Vec3::UnitY()) *
                    Eigen::AngleAxisd(c, Vec3::UnitZ()));
  };
  auto cube = [](Stream& s) {
    Rotation q(2 * s.uniform0() - 1, 2 * s.uniform0() - 1, 2 * s.uniform0() - 1, 2 * s.uniform0() - 1);
    return q.normalized();
  };
  const auto e = check_haar(euler, 100000);
  EXPECT_LT(std::min(e.p_angle, e.p_down), 1e-6);
  const auto c = check_haar(cube, 100000);
  EXPECT_LT(c.p_angle, 1e-6);
}

TEST(Orientation, MarsagliaIsHaar) {
  // The explicit drops' trig-free draw: the same two KS tests as Shoemake's, n = 10^5 rotations,
  // alpha = 0.001 per test (fixed seed: deterministic). The wrong draws below, at the same n, must
  // be rejected: uniform Euler angles (above) and this draw with the disk rejection left out
  // (points uniform in the square, scaled the same way: not uniform on S^3).
  const auto r = check_haar([](Stream& s) { return random_rotation_marsaglia(s); }, 100000);
  EXPECT_GT(r.p_angle, 1e-3);
  EXPECT_GT(r.p_down, 1e-3);
  auto square = [](Stream& s) {
    const double x1 = 2 * s.uniform0() - 1, x2 = 2 * s.uniform0() - 1, x3 = 2 * s.uniform0() - 1,
                 x4 = 2 * s.uniform0() - 1;
    const double s1 = x1 * x1 + x2 * x2, s2 = x3 * x3 + x4 * x4;
    const double f = std::sqrt(std::abs(1 - s1) / s2);
    return Rotation(x1, x2, x3 * f, x4 * f).normalized();
  };
  const auto w = check_haar(square, 100000);
  EXPECT_LT(std::min(w.p_angle, w.p_down), 1e-6);
  std::printf("Marsaglia n = 1e5: KS p angle %.3g, down %.3g; square-not-disk draw: %.3g, %.3g\n", r.p_angle, r.p_down,
              w.p_angle, w.p_down);
}

TEST(Orientation, MarsagliaDropsHaveShoemakesContactLaw) {
  // Every field an explicit drop produces is a function of the rotation and the sphere, so two
  // exact Haar draws give one law per field. Checked on one sphere (N = 200: its own quenched law,
  // the same for both draws): two-sample KS between 10^5 Shoemake and 10^5 Marsaglia drops (other
  // seeds) of r_x, r_y, r_z, r_xy, the runner-up gap, the body-frame down z and the touching
  // asperity's index, alpha = 10^-3 each. Uniform Euler angles in place of Marsaglia's draw, same n,
  // must be rejected (p < 10^-6 in some field).
  SphereParams sp;
  sp.asperities = 200;
  const RoughSphere body = make_rough_sphere(sp, 4, 0);
  const double R = sp.radius, a = sp.asperity_radius;
  constexpr std::size_t kN = 100000, kF = 7;
  auto fields = [&](auto draw, std::uint64_t seed) {
    std::vector<std::vector<double>> f(kF);
    for (std::size_t i = 0; i < kN; ++i) {
      Stream st(seed, Purpose::test, i);
      const Rotation q = draw(st);
      const Vec3 d = body_down(q);
      const Nearest nn = brute_lowest(body.centres, d);
      const Contact c = make_contact(nn, body.centres[nn.index], q, R, a);
      const double v[kF] = {c.r.x(), c.r.y(), c.r.z(), c.r_xy, c.gap, d.z(), double(c.index)};
      for (std::size_t k = 0; k < kF; ++k) f[k].push_back(v[k]);
    }
    for (auto& x : f) std::sort(x.begin(), x.end());
    return f;
  };
  auto shoemake = [](Stream& st) { return random_rotation(st); };
  auto marsaglia = [](Stream& st) { return random_rotation_marsaglia(st); };
  auto euler = [](Stream& st) {
    const double x = 2 * std::numbers::pi * st.uniform0(), y = std::numbers::pi * st.uniform0(),
                 z = 2 * std::numbers::pi * st.uniform0();
    return Rotation(Eigen::AngleAxisd(x, Vec3::UnitZ()) * Eigen::AngleAxisd(y, Vec3::UnitY()) *
                    Eigen::AngleAxisd(z, Vec3::UnitZ()));
  };
  const auto ref = fields(shoemake, 11), good = fields(marsaglia, 12), bad = fields(euler, 13);
  double worst_bad = 1;
  std::printf("Shoemake vs Marsaglia drops, two-sample KS p (r_x r_y r_z r_xy gap down_z index):");
  for (std::size_t k = 0; k < kF; ++k) {
    const double p = ks_two_sample(ref[k], good[k]).p;
    std::printf(" %.3g", p);
    EXPECT_GT(p, 1e-3) << "field " << k;
    worst_bad = std::min(worst_bad, ks_two_sample(ref[k], bad[k]).p);
  }
  std::printf("; Euler angles, smallest p %.3g\n", worst_bad);
  EXPECT_LT(worst_bad, 1e-6);
}

TEST(Orientation, MarsagliaUnitAndCalibrated) {
  // |q| = 1 within a few ulp (the draw does not normalise; the grid accepts | |d|^2 - 1 | <= 1e-12).
  // Calibration of the Haar check: 400 independent replicates of n = 500 rotations, each test at
  // alpha = 0.05; under the true law the rejections are Binomial(400, 0.05): mean 20, sd 4.4.
  // [8, 34] holds with probability > 0.998 for each of the two tests.
  for (std::uint64_t i = 0; i < 1000; ++i) {
    Stream s(7, Purpose::test, i);
    EXPECT_NEAR(random_rotation_marsaglia(s).squaredNorm(), 1.0, 1e-15);
  }
  int ra = 0, rd = 0;
  for (std::uint64_t rep = 0; rep < 400; ++rep) {
    std::vector<double> w, z;
    for (std::uint64_t i = 0; i < 500; ++i) {
      Stream s(rep + 1, Purpose::test, i);
      const Rotation q = random_rotation_marsaglia(s);
      w.push_back(2 * std::acos(std::min(1.0, std::abs(q.w()))));
      z.push_back(body_down(q).z());
    }
    std::sort(w.begin(), w.end());
    std::sort(z.begin(), z.end());
    ra += ks_one_sample(w, [](double t) { return std::clamp((t - std::sin(t)) / std::numbers::pi, 0.0, 1.0); }).p < 0.05;
    rd += ks_one_sample(z, [](double t) { return std::clamp((t + 1) / 2, 0.0, 1.0); }).p < 0.05;
  }
  std::printf("Marsaglia calibration: 400 x n = 500, alpha 0.05: angle rejected %d, down rejected %d\n", ra, rd);
  EXPECT_GE(ra, 8);
  EXPECT_LE(ra, 34);
  EXPECT_GE(rd, 8);
  EXPECT_LE(rd, 34);
}

}  // namespace
