// Tangential laws in runs: the scene key material.tangential (parsed, refused where it does not
// apply, written back by to_toml), and what the laws do to mesh bodies: Stronge's law never lets an
// impact gain kinetic energy, single or in bounce sequences, where the paper's kinematic law and
// the algebraic Walton law do (the power check that the count can see a gain at all).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "asperity/app/mesh_io.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/experiments/body_bounce.hpp"
#include "asperity/experiments/body_experiments.hpp"

using namespace asperity;

namespace {

const std::filesystem::path kMeshes = ASPERITY_MESH_DIR;

std::string mesh_scene(const std::string& material) {
  return "format = 1\n[body]\nkind = \"mesh\"\nmesh = \"" + (kMeshes / "ellipsoid.off").string() +
         "\"\nsmooth = [4e-3, 3e-3, 2.25e-3]\n[material]\n" + material +
         "\n[asperities]\ncount = 2000\nradius = { distribution = \"fixed\", value = 6.5e-7 }\n"
         "[ensemble]\nmode = \"fixed\"\nspheres = 2\ndrops = 400\n[experiment]\nkind = \"impact\"\nV = [0, 0, -1.3]\n"
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
  // A sphere run would silently keep the kinematic law: refused, naming the key.
  std::string sphere = mesh_scene("tangential = { model = \"stronge\", mu = 0.3 }");
  sphere.replace(sphere.find("kind = \"mesh\""), 13, "kind = \"sphere\"\nradius = 3e-3");
  sphere.erase(sphere.find("mesh = \""), sphere.find("[material]") - sphere.find("mesh = \""));
  EXPECT_NE(refusal(sphere).find("material.tangential.model"), std::string::npos) << refusal(sphere);
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
  // impacts (README "Bounces of rough bodies"), Stronge's law in none.
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
