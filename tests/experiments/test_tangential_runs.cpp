// SPDX-License-Identifier: GPL-3.0-or-later
// Tangential laws in runs: the scene key material.tangential (parsed, refused where it does not
// apply, written back by to_toml), and what the laws do to mesh bodies: Stronge's law never lets an
// impact gain kinetic energy, single or in bounce sequences, where the paper's kinematic law and
// the algebraic Walton law do (the power check that the count can see a gain at all).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "app/io/mesh_io.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/experiments/body_bounce.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "asperity/experiments/bounce.hpp"
#include "asperity/experiments/ensemble.hpp"

using namespace asperity;

namespace {

const std::filesystem::path kMeshes = ASPERITY_MESH_DIR;

std::string mesh_scene(const std::string& material) {
  return "format = 1\n[body]\nkind = \"mesh\"\nmesh = \"" + (kMeshes / "ellipsoid.off").string() +
         "\"\nsmooth = [4e-3, 3e-3, 2.25e-3]\n[material]\n" + material +
         "\n[asperities]\ncount = 2000\nradius = { distribution = \"fixed\", value = 6.5e-7 }\n"
         "[ensemble]\nmode = \"explicit\"\nspheres = 2\ndrops = 400\n[experiment]\nkind = \"impact\"\nV = [0, 0, -1.3]\n"
         "Omega = [0.2, 0, 0]\n[outputs]\nplots = false\n";
}

std::string refusal(const std::string& text) {
  try {
    parse_scene(text);
  } catch (const SceneError& e) {
    return e.key() + ": " + e.what();
  }
  return "accepted";
}

MeshImpactExperiment small_mesh_run(const TangentialLaw& law) {
  MeshImpactExperiment e;
  e.mesh = kMeshes / "ellipsoid.off";
  e.smooth_ellipsoid = {4e-3, 3e-3, 2.25e-3};
  e.asperities = 3000;
  e.bodies = 2;
  e.drops = 1000;
  e.plots = false;
  e.tangential = law;
  return e;
}

}  // namespace

TEST(TangentialScene, ParsedRoundTrippedAndRefusedByKey) {
  const Scene s = parse_scene(mesh_scene("tangential = { model = \"stronge\", mu = 0.3 }"));
  const TangentialLaw& t = s.ensemble.impact.tangential;
  EXPECT_EQ(t.model, TangentialLaw::Model::coulomb);
  EXPECT_EQ(t.normal, TangentialLaw::Normal::energetic);
  EXPECT_EQ(t.mu, 0.3);
  const Scene back = parse_scene(to_toml(s));
  EXPECT_EQ(back.ensemble.impact.tangential.describe(), t.describe());
  const Scene w = parse_scene(mesh_scene("tangential = { model = \"walton\", mu = 0.2, beta0 = -0.5 }"));
  EXPECT_EQ(parse_scene(to_toml(w)).ensemble.impact.tangential.describe(), "walton (mu = 0.2, beta0 = -0.5)");
  const Scene k = parse_scene(mesh_scene("tangential = { model = \"kinematic\", eps_t = 0.5 }"));
  EXPECT_EQ(k.ensemble.impact.eps_t, 0.5);

  EXPECT_NE(refusal(mesh_scene("tangential = { model = \"stronge\", mu = -1 }")).find("material.tangential.mu"), std::string::npos);
  EXPECT_NE(refusal(mesh_scene("tangential = { model = \"walton\", mu = 0.1, beta0 = 2 }")).find("material.tangential.beta0"),
            std::string::npos);
  EXPECT_NE(refusal(mesh_scene("tangential = { model = \"coulomb\", mu = 0.1 }")).find("material.tangential.restitution"),
            std::string::npos);
  EXPECT_NE(refusal(mesh_scene("tangential = { model = \"friction\" }")).find("material.tangential.model"), std::string::npos);
  EXPECT_NE(refusal(mesh_scene("eps_t = 1.0\ntangential = { model = \"stronge\", mu = 0.3 }")).find("material.eps_t"),
            std::string::npos);
  // Sphere impacts take the law (issue 18); the paper's bounce procedure (its own kinematic law) and
  // a contact-only run (no impact to act in) refuse it, naming the key.
  std::string sphere = mesh_scene("tangential = { model = \"stronge\", mu = 0.3 }");
  sphere.replace(sphere.find("kind = \"mesh\""), 13, "kind = \"sphere\"\nradius = 3e-3");
  sphere.erase(sphere.find("mesh = \""), sphere.find("[material]") - sphere.find("mesh = \""));
  EXPECT_EQ(refusal(sphere), "accepted");
  EXPECT_EQ(parse_scene(sphere).ensemble.impact.tangential.describe(), "coulomb (mu = 0.3, energetic)");
  auto with_experiment = [&](const std::string& experiment) {
    std::string t = sphere;
    const auto a = t.find("[experiment]"), b = t.find("[outputs]");
    t.replace(a, b - a, experiment);
    if (experiment.find("\"bounce\"") != std::string::npos)  // a sphere's bounce takes seed and threads only
      for (const char* k : {"mode = \"explicit\"\n", "drops = 400\n", "spheres = 2\n"})
        if (const auto at = t.find(k); at != std::string::npos) t.erase(at, std::string(k).size());
    return t;
  };
  auto any_refusal = [](const std::string& text) -> std::string {
    try {
      parse_scene(text);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string bounce = "[experiment]\nkind = \"bounce\"\nsequences = 10\nvariants = \"";
  EXPECT_EQ(any_refusal(with_experiment(bounce + "random-orientation,dynamic\"\n")), "accepted");
  const std::string paper = any_refusal(with_experiment(bounce + "paper,dynamic\"\n"));
  EXPECT_NE(paper.find("material.tangential.model"), std::string::npos) << paper;
  EXPECT_NE(paper.find("\"paper\""), std::string::npos) << paper;
  const std::string contacts = any_refusal(with_experiment("[experiment]\nkind = \"contact\"\n"));
  EXPECT_NE(contacts.find("material.tangential.model"), std::string::npos) << contacts;
}

TEST(TangentialRuns, RoughSphereImpactsAndBouncesTakeTheLaw) {
  // Single impacts (fig4's regime, N = 1e4, u = 1.3 m/s, Omega_x = 0.2 rad/s, 2000 sampled drops):
  // Coulomb with mu -> inf and Newton's rule sticks, which for a sphere is the kinematic law with
  // eps_t = 0, drop by drop; Stronge at mu = 0.3 also sticks here (the initial slip Omega R ~ 6e-4
  // m/s is stopped by a fraction of mu P), so its Omega'_x differs from the paper's eps_t = 1 (which
  // keeps that slip) while eps changes per drop by at most 6 % of the roughness scatter (measured 0.064).
  EnsembleConfig c;
  c.sphere = {10000, 3e-3, 5e-7};
  c.mode = Mode::sampled;
  c.drops = 2000;
  c.seed = 5;
  c.impact.enabled = true;
  c.impact.speed = 1.3;
  c.impact.omega = Vec3(0.2, 0, 0);
  auto run = [&](const TangentialLaw& law, double eps_t) {
    auto x = c;
    x.impact.tangential = law, x.impact.eps_t = eps_t;
    return run_contact_ensemble(x);
  };
  const auto kin0 = run(TangentialLaw::kinematic(0.0), 0.0);
  const auto stick = run(TangentialLaw::coulomb(1e6, TangentialLaw::Normal::newton), 1.0);
  const auto paper = run(TangentialLaw::kinematic(1.0), 1.0);
  const auto str = run(TangentialLaw::stronge(0.3), 1.0);
  ASSERT_EQ(kin0.eps.size(), stick.eps.size());
  ASSERT_EQ(paper.eps.size(), str.eps.size());
  double d_stick = 0, d_eps = 0, d_wx = 0, sd_eps = 0;
  for (std::size_t i = 0; i < kin0.eps.size(); ++i) {
    d_stick = std::max({d_stick, std::abs(kin0.eps[i] - stick.eps[i]), std::abs(kin0.omega_x_after[i] - stick.omega_x_after[i])});
    d_eps = std::max(d_eps, std::abs(paper.eps[i] - str.eps[i]));
    d_wx = std::max(d_wx, std::abs(paper.omega_x_after[i] - str.omega_x_after[i]));
    sd_eps += (paper.eps[i] - paper.eps_n[i]) * (paper.eps[i] - paper.eps_n[i]);
  }
  sd_eps = std::sqrt(sd_eps / static_cast<double>(paper.eps.size()));
  EXPECT_LT(d_stick, 1e-6);
  EXPECT_LT(d_eps, 0.1 * sd_eps) << d_eps << " vs the roughness scale " << sd_eps;
  EXPECT_GT(d_wx, 0.01) << "the law must reach the impacts: Stronge stops the slip that eps_t = 1 keeps";

  // Bounce sequences (random-orientation, N = 1e5, 200 sequences down to 0.6 m/s): before the first
  // impact nothing slips (Omega = 0, V vertical), so every law sticks and k = 1 equals the kinematic
  // law; later impacts differ. The paper's procedure refuses the law.
  BounceExperiment b;
  b.enabled = true, b.sequences = 200, b.stop_speed = 0.6, b.bootstrap = 0;
  const SphereParams sphere{100000, 3e-3, 5e-7};
  const auto k0 = run_bounces(sphere, b, BounceVariant::random_orientation, 3);
  b.tangential = TangentialLaw::stronge(0.3);
  const auto s0 = run_bounces(sphere, b, BounceVariant::random_orientation, 3);
  ASSERT_EQ(k0.eps.size(), s0.eps.size());
  double first = 0, later = 0;
  for (std::size_t j = 0; j < k0.eps.size(); ++j)
    (k0.number[j] == 1 ? first : later) = std::max(k0.number[j] == 1 ? first : later, std::abs(k0.eps[j] - s0.eps[j]));
  EXPECT_LT(first, 1e-12);
  // Later impacts: the contact point's slip stays ~|Omega| x (the change of the few-micrometre
  // contact offset), which any law leaves small: |d eps| <= 4.0e-8 measured, 1e-3 of the roughness
  // scatter (~5e-5 at N = 1e5); the bound 1e-6 still fails a law that lost the sticking.
  EXPECT_GT(later, first);
  EXPECT_LT(later, 1e-6);
  EXPECT_THROW(run_bounces(sphere, b, BounceVariant::paper, 3), std::invalid_argument);
}

TEST(TangentialRuns, StrongeNeverGainsEnergyWaltonDoesOnAnEllipsoid) {
  // 2 bodies x 500 rotations of a rough ellipsoid (N = 3000), V = 1.3 m/s, Omega_x = 0.2 rad/s,
  // mu = 0.3. Walton's algebraic sliding impulse overshoots off-centre (the slip direction is fixed
  // at the initial one) and gains energy in about a fifth of these impacts.
  const TriangleMesh mesh = read_mesh(kMeshes / "ellipsoid.off");
  const MeshImpactReport st = run_mesh_impacts(small_mesh_run(TangentialLaw::stronge(0.3)), mesh);
  const MeshImpactReport wa = run_mesh_impacts(small_mesh_run(TangentialLaw::walton(0.3, 0.0)), mesh);
  EXPECT_EQ(st.energy_gain_fraction, 0.0);
  EXPECT_LT(st.energy_gain_max, 0.0);
  EXPECT_GT(wa.energy_gain_fraction, 0.05);
}

TEST(TangentialRuns, StrongeBounceSequencesNeverGainEnergyTheKinematicLawDoes) {
  // 40 sequences of rough ellipsoids from 1 m/s: the kinematic law gains energy in a third of the
  // impacts (docs/science-beyond.md "Bounces of rough bodies"), Stronge's law in none.
  const TriangleMesh mesh = read_mesh(kMeshes / "ellipsoid.off");
  std::vector<RoughBody> bodies;
  for (std::uint64_t k = 0; k < 2; ++k)
    bodies.push_back(make_rough_mesh_body(mesh, 3000, RadiusDistribution::fixed(5e-7), 7850, 1, k,
                                          smooth_surface({4e-3, 3e-3, 2.25e-3}), "ellipsoid"));
  BodyBounceOptions o;
  o.bounce.sequences = 40;
  o.bounce.speed = 1.0;
  o.bounce.stop_speed = 0.1;
  o.bounce.variants = {BounceVariant::dynamic};
  o.bounce.bootstrap = 0;
  const BodyBounceReport kin = analyse_body_bounces(run_body_bounces(bodies, o, 1), o.bounce, 1);
  o.tangential = TangentialLaw::stronge(0.3);
  const BodyBounceReport str = analyse_body_bounces(run_body_bounces(bodies, o, 1), o.bounce, 1);
  EXPECT_GT(kin.energy_gain_fraction, 0.05);
  EXPECT_EQ(str.energy_gain_fraction, 0.0);
}
