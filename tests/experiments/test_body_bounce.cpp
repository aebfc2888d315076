// SPDX-License-Identifier: GPL-3.0-or-later
// Bounce sequences of general rough bodies: energy in flight and at impacts, the landing search
// against a brute dense scan (and a too-optimistic bound that must miss contacts), the rough
// sphere's first impacts against the corrected Eq. 28, thread-count independence.
#include <gtest/gtest.h>

#include "sanitized.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>

#include "asperity/experiments/body_bounce.hpp"
#include "asperity/core/body_impact.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/theory_impact.hpp"
#include "core/free_rotation_reference.hpp"

using namespace asperity;

namespace {

// A rough solid ellipsoid (semi-axes A > B > C): n asperity centres on its surface (radial
// projection of uniform directions: not area-uniform, which nothing here needs), radii rho.
RoughBody rough_ellipsoid(std::uint64_t n, double A, double B, double C, double rho, std::uint64_t id) {
  RoughBody b;
  b.name = "test-ellipsoid";
  const double density = 7850;
  b.mass = density * 4.0 / 3.0 * std::numbers::pi * A * B * C;
  b.inertia = Eigen::Vector3d(b.mass / 5 * (B * B + C * C), b.mass / 5 * (A * A + C * C), b.mass / 5 * (A * A + B * B)).asDiagonal();
  for (std::uint64_t i = 0; i < n; ++i) {
    Stream s(7, Purpose::test, id, i);
    const double zc = 2 * s.uniform0() - 1, ph = 2 * std::numbers::pi * s.uniform0(), rr = std::sqrt(1 - zc * zc);
    const Vec3 u(rr * std::cos(ph), rr * std::sin(ph), zc);
    const double k = 1.0 / std::sqrt(std::pow(u.x() / A, 2) + std::pow(u.y() / B, 2) + std::pow(u.z() / C, 2));
    b.centres.push_back(k * u);
    b.radii.push_back(rho);
  }
  return b;
}

// Brute force: the gap z(t) - D(q(t)) with the linear support scan, and the orientation from the
// independent Boost.Odeint integration of Euler's equations (src/free_rotation_reference.hpp), not
// from the closed form the search uses: agreement tests both (and the scan stays fast).
struct Brute {
  const RoughBody& b;
  Rotation q0;
  Vec3 w0;
  FlightStart st;
  double gap(double t, Support* sup = nullptr) const {
    const Support s = brute_support(b.centres, b.radii, body_down(detail::reference_free_rotation(b.inertia, q0, w0, t).q));
    if (sup) *sup = s;
    return st.z + st.vz * t - 0.5 * st.gravity * t * t - s.h;
  }
  // First grid time j*dt (j >= 1) with gap <= 0.
  double first_contact(double dt, double t_end) const {
    for (double j = 1;; ++j) {
      const double t = j * dt;
      if (t > t_end) return std::numeric_limits<double>::infinity();
      if (gap(t) <= 0) return t;
    }
  }
};

// One flight right after an impact at a random orientation: (body state, FreeRotation, start).
struct Case {
  Rotation q;
  Vec3 V, W;
  double z;
};

Case after_impact(const RoughBody& b, const SupportQuery& idx, std::uint64_t i, double speed, const Vec3& spin) {
  Stream s(3, Purpose::test, 1000 + i);
  Case c;
  c.q = random_rotation(s);
  c.z = idx.support(body_down(c.q)).h;
  const auto en = constant_restitution(0.9);
  const BodyImpact bi = body_impact(b, idx, c.q, Vec3(0, 0, -speed), spin, *en);
  if (!bi.result) {
    c.V = Vec3(0, 0, -speed), c.W = spin;  // no impact: caller skips
    c.z = -1;
    return c;
  }
  c.V = bi.result->V_after, c.W = bi.result->Omega_after;
  return c;
}

}  // namespace

TEST(BodyBounce, FlightConservesEnergyAndMomentum) {
  const RoughBody b = rough_ellipsoid(2000, 4e-3, 3e-3, 2.25e-3, 5e-7, 1);
  const auto idx = make_support_tree(b.centres, b.radii);
  const BodyBounds bb = BodyBounds::of(b);
  int flights = 0;
  for (std::uint64_t i = 0; i < 6; ++i) {
    const Case c = after_impact(b, *idx, i, 0.5, Vec3(3, -2, 1));
    if (c.z < 0) continue;
    const FreeRotation rot(b.inertia, c.q, c.W);
    const double g = 9.81;
    const Landing L = next_landing(b, bb, *idx, rot, {c.z, c.V.z(), g});
    ASSERT_TRUE(L.found);
    ASSERT_GT(L.time, 0);
    const double E0 = body_energy(b, c.q, c.V, c.W, c.z, g);
    const double E1 = body_energy(b, L.rotation.q, Vec3(c.V.x(), c.V.y(), L.vz), L.rotation.omega, L.z, g);
    EXPECT_NEAR(E1, E0, 1e-12 * E0) << i;
    // World angular momentum and rotational energy at the landing, recomputed from the state.
    const Eigen::Matrix3d Q = L.rotation.q.toRotationMatrix();
    const Vec3 Lw = Q * b.inertia * Q.transpose() * L.rotation.omega;
    EXPECT_LT((Lw - rot.angular_momentum()).norm(), 1e-12 * rot.angular_momentum().norm()) << i;
    EXPECT_NEAR(0.5 * L.rotation.omega.dot(Lw), rot.kinetic_energy(), 1e-12 * rot.kinetic_energy()) << i;
    ++flights;
  }
  EXPECT_GE(flights, 4);
}

TEST(BodyBounce, WorkIdentityAndFlightEnergyInSequences) {
  // Two ellipsoids and a sphere with unequal (level) radii: any RoughBody bounces.
  SphereParams sp;
  sp.asperities = 5000, sp.radius = 3e-3;
  std::vector<RoughBody> bodies{rough_ellipsoid(3000, 4e-3, 3e-3, 2.25e-3, 5e-7, 2), rough_ellipsoid(3000, 4e-3, 3e-3, 2.25e-3, 5e-7, 3),
                                make_rough_sphere_body(sp, RadiusDistribution::discrete({2e-6, 5e-7}, {0.2, 0.8}), 3, 0)};
  BodyBounceOptions o;
  o.bounce.variants = {BounceVariant::dynamic};
  o.bounce.sequences = 9;
  o.bounce.speed = 0.6;
  o.bounce.stop_speed = 0.2;
  o.bounce.max_impacts = 40;
  const BodyBounceSamples s = run_body_bounces(bodies, o, 5, 2);
  ASSERT_GE(s.base.eps.size(), 12u);
  int gains = 0;
  for (std::size_t j = 0; j < s.base.eps.size(); ++j) {
    const double E = s.energy_before[j];
    // Delta E = P . (v + v')/2: the impulse's work on the contact point.
    EXPECT_NEAR(s.energy_after[j] - s.energy_before[j], s.work[j], 1e-12 * E) << j;
    gains += s.energy_after[j] > s.energy_before[j];
    if (j + 1 < s.base.eps.size() && s.base.sequence[j + 1] == s.base.sequence[j]) {
      EXPECT_NEAR(s.energy_before[j + 1], s.energy_after[j], 1e-12 * E) << j;  // flight conserves E
    }
  }
  // eps_t = 1 (the paper's v'_t = v_t) is no dissipative law for an off-centre contact: keeping v_t
  // takes a tangential impulse whose work P_t . v_t has either sign, so some ellipsoid impacts GAIN
  // energy although eps_n < 1 (the identity above still holds). Documented, not a defect.
  EXPECT_GT(gains, 0);
  const BodyBounceReport r = analyse_body_bounces(s, o.bounce, 5);
  EXPECT_LT(r.work_identity_max, 1e-12);
  EXPECT_LT(r.flight_energy_max, 1e-12);
  const auto& c = r.stops;
  EXPECT_EQ(c.slow + c.no_approach + c.max_impacts + c.max_time + c.max_steps, o.bounce.sequences);
}

// The landing of conservative advancement against a dense brute scan (grid dt, brute_support):
// the brute first contact t_b is the first grid time with gap <= 0, so the exact first contact lies
// in (t_b - dt, t_b] unless the gap dips below zero and back within one grid step (the scan then
// misses it too: dt is chosen far below the rocking time scale). The rigorous bound must land in
// that interval every time; the bound without rotation terms must land later in some cases.
TEST(BodyBounce, LandingMatchesBruteScanAndOptimisticBoundMisses) {
  const double g = 9.81, dt = 2e-5;
  int cases = 0, optimistic_missed = 0, rocking = 0;
  for (std::uint64_t bi = 0; bi < 3; ++bi) {
    const RoughBody b = rough_ellipsoid(150, 4e-3, 3e-3, 2.25e-3, 2e-4, 10 + bi);  // big asperities: a bumpy body
    const auto idx = make_support_tree(b.centres, b.radii);
    const BodyBounds bb = BodyBounds::of(b);
    for (std::uint64_t i = 0; i < 5; ++i) {
      Stream s(4, Purpose::test, 100 * bi + i);
      Case c;
      FlightStart st{0, 0, g};
      if (i < 3) {  // after a real impact, slow drop, random spin
        const Vec3 spin(40 * (s.uniform() - 0.5), 40 * (s.uniform() - 0.5), 40 * (s.uniform() - 0.5));
        c = after_impact(b, *idx, 50 * bi + i, 0.15, spin);
        if (c.z < 0) continue;
      } else {  // rocking: lying flat (C axis vertical), tipped about the long axis, barely lifted
        c.q = Rotation(Eigen::AngleAxisd(0.05 * (i == 3 ? 1 : -1), Vec3::UnitX()));
        c.z = idx->support(body_down(c.q)).h + 1e-7;
        c.V = Vec3(0, 0, 0.005);
        c.W = Vec3(i == 3 ? -6.0 : 6.0, 0.3, 0.0);
      }
      st.z = c.z, st.vz = c.V.z();
      const FreeRotation rot(b.inertia, c.q, c.W);
      const Brute brute{b, c.q, c.W, st};
      const Landing L = next_landing(b, bb, *idx, rot, st);
      ASSERT_TRUE(L.found);
      const double tb = brute.first_contact(dt, L.time + 10 * dt);
      ASSERT_TRUE(std::isfinite(tb)) << "brute scan finds no contact up to " << L.time;
      EXPECT_GE(L.time, tb - dt - 1e-12) << bi << " " << i;
      EXPECT_LE(L.time, tb + 1e-12) << bi << " " << i;
      // The touching asperity: brute force at the landing orientation, and the approaching one.
      const Support sb = brute_support(b.centres, b.radii, body_down(L.rotation.q));
      EXPECT_EQ(L.support.index, sb.index);
      EXPECT_LE(std::abs(L.gap), 1e-11);
      rocking += i >= 3 && L.time < 0.02;
      LandingOptions bad;
      bad.rotation_bound_scale = 0;
      const Landing Lb = next_landing(b, bb, *idx, rot, st, bad);
      optimistic_missed += Lb.found && Lb.time > tb + 1e-9;
      ++cases;
    }
  }
  std::cerr << "cases " << cases << " rocking " << rocking << " missed " << optimistic_missed << "\n";
  EXPECT_GE(cases, 12);
  EXPECT_GE(rocking, 4);  // the rocking starts re-contact quickly
  EXPECT_GE(optimistic_missed, 2) << "the bound without rotation terms must step over some contacts";
}

// A rough SPHERE body's first impacts follow the corrected Eq. 28 (theory_impact.hpp): K explicit
// spheres x random orientations, V = (0, 0, -1.3), Omega = (0.2, 0, 0) as Fig. 4. KS at alpha 0.01,
// n = 16000 first impacts (pooled over 16 bodies: the contact patches of different orientations
// are disjoint caps of a Poisson field, so the draws are iid); alpha x 1.05 (a law 5% too
// narrow) must be rejected at the same n. Flights of the second impacts follow the ballistic
// formula 2 V'_z / g: the sphere's depth changes by < 1e-9 m between contacts.
TEST(BodyBounce, RoughSphereFirstImpactFollowsEq28) {
  SphereParams p;
  p.asperities = 100000, p.radius = 3e-3, p.asperity_radius = 6.5e-7;
  // Under the sanitizers: 4 bodies and 800 first impacts check memory on the same paths; the law
  // and its power are asserted in Release (16 bodies, 16000 impacts).
  const bool full = !asperity::testing::kSanitized;
  std::vector<RoughBody> bodies;
  for (std::uint64_t k = 0; k < (full ? 16u : 4u); ++k)
    bodies.push_back(make_rough_sphere_body(p, RadiusDistribution::fixed(6.5e-7), 9, k));
  BodyBounceOptions o;
  o.bounce.variants = {BounceVariant::dynamic};
  o.bounce.sequences = full ? 16000 : 800;
  o.bounce.speed = 1.3;
  o.bounce.max_impacts = 1;
  o.bounce.omega = Vec3(0.2, 0, 0);
  const BodyBounceSamples s = run_body_bounces(bodies, o, 21, 2);
  ASSERT_EQ(s.base.eps.size(), o.bounce.sequences);
  auto eps = s.base.eps;
  std::sort(eps.begin(), eps.end());
  ImpactScene sc;
  sc.asperities = p.asperities, sc.radius = p.radius, sc.asperity_radius = p.asperity_radius, sc.speed = 1.3, sc.omega_x = 0.2;
  const KsResult good = ks_one_sample(eps, eq28_corrected(sc).cdf);
  const KsResult bad = ks_one_sample(eps, eq28_corrected(sc, 1.05).cdf);
  std::cerr << "Eq. 28 corrected: D = " << good.D << ", p = " << good.p << "; alpha x 1.05: D = " << bad.D << ", p = " << bad.p
            << "\n";
  if (full) {
    EXPECT_GT(good.p, 0.01) << "D = " << good.D;
    EXPECT_LT(bad.p, 0.01) << "D = " << bad.D;
  }

  o.bounce.sequences = 40, o.bounce.max_impacts = 3;
  const BodyBounceSamples f = run_body_bounces(bodies, o, 22, 2);
  int checked = 0;
  for (std::size_t j = 0; j + 1 < f.base.eps.size(); ++j) {
    if (!std::isfinite(f.flight[j]) || f.base.sequence[j + 1] != f.base.sequence[j]) continue;
    const double vz = f.base.eps[j] * f.base.speed[j];  // V'_z
    // Lift-off at height -r_z of this contact, landing at -r_z of the next: the ballistic formula
    // to the search tolerance; and 2 V'_z/g within the sphere's depth variation (~1e-7 m).
    EXPECT_NEAR(f.flight[j], ballistic_flight(-f.r[j].z(), vz, -f.r[j + 1].z(), 9.81).time, 1e-11) << j;
    EXPECT_NEAR(f.flight[j], 2 * vz / 9.81, 1e-6 * f.flight[j]) << j;
    ++checked;
  }
  EXPECT_GE(checked, 60);
}

TEST(BodyBounce, OneAndTwoThreadsAreBitIdentical) {
  std::vector<RoughBody> bodies{rough_ellipsoid(2000, 4e-3, 3e-3, 2.25e-3, 5e-7, 4), rough_ellipsoid(2000, 4e-3, 3e-3, 2.25e-3, 5e-7, 5),
                                rough_ellipsoid(2000, 4e-3, 3e-3, 2.25e-3, 5e-7, 6)};
  BodyBounceOptions o;
  o.bounce.variants = {BounceVariant::dynamic};
  o.bounce.sequences = 8;
  o.bounce.speed = 0.5;
  o.bounce.stop_speed = 0.2;
  o.bounce.max_impacts = 20;
  o.bounce.omega = Vec3(1, 2, 0);
  const auto a = run_body_bounces(bodies, o, 3, 1), c = run_body_bounces(bodies, o, 3, 2);
  EXPECT_EQ(a.base.sequence, c.base.sequence);
  EXPECT_EQ(a.base.eps, c.base.eps);
  ASSERT_EQ(a.flight.size(), c.flight.size());  // NaN after a sequence's last impact: compare bits
  EXPECT_EQ(0, std::memcmp(a.flight.data(), c.flight.data(), a.flight.size() * sizeof(double)));
  EXPECT_EQ(a.energy_after, c.energy_after);
  EXPECT_EQ(a.r, c.r);
  EXPECT_EQ(a.omega_after, c.omega_after);
  EXPECT_EQ(a.support_queries, c.support_queries);
}

TEST(BodyBounce, RefusesBadOptions) {
  BodyBounceOptions o;
  o.bounce.variants = {BounceVariant::dynamic};
  EXPECT_NO_THROW(validate(o));
  o.bounce.variants = {BounceVariant::paper};
  EXPECT_THROW(validate(o), std::invalid_argument);
  o.bounce.variants = {BounceVariant::dynamic};
  o.max_time = 0;
  EXPECT_THROW(validate(o), std::invalid_argument);
  o.max_time = 1;
  o.bounce.omega = Vec3(std::nan(""), 0, 0);
  EXPECT_THROW(validate(o), std::invalid_argument);
  o.bounce.omega = Vec3::Zero();
  EXPECT_THROW(run_body_bounces(std::vector<RoughBody>{}, o, 1), std::invalid_argument);
}

// The energy bookkeeping of body_energy against a contact law that must conserve it: eps_n = 1 and
// eps_t = -1 reverse the whole contact velocity (v' = -v), and with P = K^-1 (v' - v) the kinetic
// energy change P.(v + v')/2 is then exactly 0 for ANY inertia. The paper's eps_t = 1 at the same
// contacts changes the energy (either sign): the law, not the bookkeeping, creates it.
TEST(BodyBounce, EnergyIsConservedByTheReversingLawAndNotByEpsT1) {
  const RoughBody b = rough_ellipsoid(3000, 4e-3, 3e-3, 2.25e-3, 5e-7, 7);
  const auto idx = make_support_tree(b.centres, b.radii);
  const auto e1 = constant_restitution(1.0);
  int n = 0, changed = 0;
  for (std::uint64_t i = 0; i < 200; ++i) {
    Stream s(8, Purpose::test, i);
    const Rotation q = random_rotation(s);
    const Vec3 V(0.3 * (s.uniform() - 0.5), 0.3 * (s.uniform() - 0.5), -1.0);
    const Vec3 W(200 * (s.uniform() - 0.5), 200 * (s.uniform() - 0.5), 200 * (s.uniform() - 0.5));
    const double z = idx->support(body_down(q)).h, g = 9.81;
    const BodyImpact rev = body_impact(b, *idx, q, V, W, *e1, -1.0);
    const BodyImpact pap = body_impact(b, *idx, q, V, W, *e1, 1.0);
    if (!rev.result || !pap.result) continue;
    const double E = body_energy(b, q, V, W, z, g);
    EXPECT_NEAR(body_energy(b, q, rev.result->V_after, rev.result->Omega_after, z, g), E, 1e-12 * E) << i;
    changed += std::abs(body_energy(b, q, pap.result->V_after, pap.result->Omega_after, z, g) - E) > 1e-6 * E;
    ++n;
  }
  EXPECT_GE(n, 100);
  EXPECT_GE(changed, n / 2);
}
