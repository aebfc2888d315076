// SPDX-License-Identifier: GPL-3.0-or-later
// Scene files: the presets as files reproduce the presets as they were written in C++, every bad
// key or value is an error naming the key, unsupported features are refused, and to_toml
// round-trips.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "asperity/app/scene_file.hpp"

using namespace asperity;

namespace {

// The presets exactly as src/scene.cpp defined them in C++ before they became files (the one
// difference: fig5's a is the literal 3e-7 m, not R x 1e-4 = 3.0000000000000004e-7 m).
Scene reference_preset(const std::string& name) {
  Scene s;
  s.ensemble.sphere = SphereParams{100000, 3e-3, 6.5e-7};
  s.ensemble.drops = 1000000;
  s.ensemble.seed = 1;
  s.name = name;
  // Since issue 13 fig3, fig4, fig5 run explicit spheres (K from the error budget: spheres = "auto").
  s.ensemble.mode = Mode::explicit_spheres;
  if (name == "fig3") {
  } else if (name == "fig3-fixed") {
    s.ensemble.spheres = 100;
    s.spheres_auto = false;
    s.ensemble.backend = Backend::grid;
    s.backend_auto = false;  // the file names its backend
  } else if (name == "fig4") {
    s.ensemble.impact.enabled = true;
    s.ensemble.impact.speed = 1.3;
    s.ensemble.impact.omega = Vec3(0.2, 0.0, 0.0);
  } else if (name == "fig5") {
    s.ensemble.sphere.asperity_radius = 3e-7;
    s.ensemble.impact.enabled = true;
    s.ensemble.impact.speed = 1.0;
    s.ensemble.impact.omega = Vec3(0.0, 0.0, 0.0);
  } else if (name == "fig6") {
    s.ensemble.sphere = SphereParams{1000000, 3e-3, 5e-7};
    s.bounce.enabled = true;  // BounceExperiment's defaults are the paper's Sec. V
    s.spheres_auto = false;   // every sequence bounces its own sphere
  } else {
    ADD_FAILURE() << "no reference for preset " << name;
  }
  return s;
}

const std::filesystem::path kScenes = SCENES_DIR;

// A valid small scene; tests replace one line to break it.
const std::string kGood = R"(format = 1
name = "tiny"
[body]
kind = "sphere"
radius = 3e-3
[material]
density = 7850.0
eps_t = 1.0
restitution = { model = "viscoelastic", beta = 0.0467 }
[asperities]
count = 1000
radius = { distribution = "fixed", value = 6.5e-7 }
[ensemble]
mode = "explicit"
drops = 2000
spheres = 10
seed = 7
backend = "auto"
threads = 0
[experiment]
kind = "impact"
V = [0.0, 0.0, -1.3]
Omega = [0.2, 0.0, 0.0]
[outputs]
contact = true
restitution = true
plots = false
alpha = 0.01
dir = "out"
report = "report.json"
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) ADD_FAILURE() << "test bug: '" << from << "' not in the scene";
  else text.replace(at, from.size(), to);
  return text;
}

// The text must be rejected with a SceneError whose key and message name `key` (and `also`).
void expect_error(const std::string& text, const std::string& key, const std::string& also = "") {
  try {
    parse_scene(text, "test.toml");
    ADD_FAILURE() << "accepted, expected an error naming " << key << ":\n" << text;
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.key(), key) << what;
    EXPECT_NE(what.find(key), std::string::npos) << "message does not name " << key << ": " << what;
    EXPECT_NE(what.find("test.toml:"), std::string::npos) << what;
    if (!also.empty()) {
      EXPECT_NE(what.find(also), std::string::npos) << "message does not name " << also << ": " << what;
    }
  }
}

// parse_scene(to_toml(s)) == s for each scene.
void expect_round_trips(const std::vector<Scene>& scenes) {
  for (const auto& s : scenes) {
    const std::string text = to_toml(s);
    Scene back;
    ASSERT_NO_THROW(back = parse_scene(text, "round-trip")) << text;
    EXPECT_TRUE(back == s) << text;
  }
}

}  // namespace

TEST(SceneFile, EveryPresetFileEqualsThePresetAsDefinedInCode) {
  const std::vector<std::string> expected{"fig3", "fig3-fixed", "fig4", "fig5", "fig6"};
  EXPECT_EQ(preset_names(), expected);
  for (const auto& name : preset_names()) {
    const Scene from_file = load_scene(kScenes / (name + ".toml"));
    EXPECT_TRUE(from_file == reference_preset(name)) << name << "\n" << to_toml(from_file);
    EXPECT_TRUE(preset(name) == from_file) << name << ": the embedded text differs from scenes/" << name << ".toml";
  }
  EXPECT_THROW(preset("fig99"), std::invalid_argument);
}

TEST(SceneFile, RoundTripsThroughToToml) {
  std::vector<Scene> scenes;
  for (const auto& name : preset_names()) scenes.push_back(preset(name));
  const std::string good = kGood;
  scenes.push_back(parse_scene(good));
  Scene odd = parse_scene(good);
  odd.name = "quote \" backslash \\ tab \t";
  odd.ensemble.seed = 18446744073709551615ull;  // beyond TOML's int64: written as a string
  odd.ensemble.sphere.radius = 0.1 + 0.2;       // needs all 17 digits
  odd.ensemble.impact.omega = Vec3(-1e-300, 5e3, 1.0 / 3.0);
  odd.ensemble.backend = Backend::cgal;
  odd.backend_auto = false;
  odd.ensemble.kernel = Kernel::scalar;
  odd.contact_stats = false;
  odd.plots = true;
  scenes.push_back(odd);
  Scene contact_only = preset("fig3");
  contact_only.restitution_stats = false;
  scenes.push_back(contact_only);
  // Unused settings are not written: they read back as defaults.
  Scene fresh_with_spheres = preset("fig3");
  fresh_with_spheres.ensemble.mode = Mode::sampled;
  fresh_with_spheres.ensemble.spheres = 100;  // e.g. fig3-fixed --mode sampled
  EXPECT_EQ(parse_scene(to_toml(fresh_with_spheres)).ensemble.spheres, 1u);
  Scene fixed_k = preset("fig3");
  fixed_k.ensemble.spheres = 40;
  fixed_k.spheres_auto = false;
  scenes.push_back(fixed_k);
  Scene fresh_with_backend = preset("fig3");
  fresh_with_backend.ensemble.mode = Mode::sampled;
  fresh_with_backend.ensemble.backend = Backend::grid;
  fresh_with_backend.backend_auto = false;
  EXPECT_TRUE(parse_scene(to_toml(fresh_with_backend)).backend_auto);
  // ensemble.kernel: read, and refused where it cannot apply (sampled drops run no drop kernel).
  EXPECT_EQ(parse_scene(replace(good, "[ensemble]", "[ensemble]\nkernel = \"scalar\"")).ensemble.kernel, Kernel::scalar);
  try {
    parse_scene(replace(replace(replace(good, "mode = \"explicit\"", "mode = \"sampled\""), "spheres = 10\n", ""),
                        "[ensemble]", "[ensemble]\nkernel = \"scalar\""));
    ADD_FAILURE() << "kernel with mode = \"sampled\" was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("ensemble.kernel"), std::string::npos) << e.what();
  }
  expect_round_trips(scenes);
}

TEST(SceneFile, ExampleFileAndMinimalFileParse) {
  const Scene ex = load_scene(kScenes / "example.toml");
  EXPECT_EQ(ex.name, "example");
  const Scene minimal = parse_scene("format = 1\n");
  EXPECT_EQ(minimal.name, "custom");
  Scene defaults;
  defaults.name = "custom";
  EXPECT_TRUE(minimal == defaults) << "an absent key takes the documented Scene default";
  // A count may be written as an exact float; areal density gives the count on the sphere.
  EXPECT_EQ(parse_scene(replace(kGood, "count = 1000", "count = 1e3")).ensemble.sphere.asperities, 1000u);
  const Scene eta = parse_scene(replace(kGood, "count = 1000", "areal_density = 1e10"));
  EXPECT_EQ(eta.ensemble.sphere.asperities, 1130973u);  // round(1e10 * 4 pi (3e-3)^2)
  // Standard tables are the same as inline tables.
  const Scene std_table = parse_scene(replace(kGood, "restitution = { model = \"viscoelastic\", beta = 0.0467 }\n", "") +
                                      "[material.restitution]\nmodel = \"viscoelastic\"\nbeta = 0.05\n");
  EXPECT_EQ(std_table.ensemble.impact.beta, 0.05);
}

TEST(SceneFile, UnknownKeysAnywhereAreErrorsNamingTheDottedKey) {
  expect_error(kGood + "colour = 3\n", "outputs.colour");  // after [outputs]
  expect_error("format = 1\nfoo = 1\n", "foo");
  expect_error("format = 1\n[bodi]\nkind = \"sphere\"\n", "bodi");
  expect_error(replace(kGood, "kind = \"sphere\"", "kind = \"sphere\"\ncolor = \"red\""), "body.color");
  expect_error(replace(kGood, "beta = 0.0467", "beta = 0.0467, gamma = 2"), "material.restitution.gamma");
  expect_error(replace(kGood, "value = 6.5e-7", "value = 6.5e-7, vaule = 1"), "asperities.radius.vaule");
  expect_error(replace(kGood, "seed = 7", "seed = 7\nsed = 8"), "ensemble.sed");
  expect_error(replace(kGood, "Omega = [0.2, 0.0, 0.0]", "Omega = [0.2, 0.0, 0.0]\nomega = 1"), "experiment.omega");
}

TEST(SceneFile, WrongTypesAreErrorsNamingKeyAndValue) {
  expect_error(replace(kGood, "radius = 3e-3", "radius = \"3mm\""), "body.radius", "\"3mm\"");
  expect_error(replace(kGood, "count = 1000", "count = \"1000\""), "asperities.count", "\"1000\"");
  expect_error(replace(kGood, "count = 1000", "count = 1000.5"), "asperities.count", "1000.5");
  expect_error(replace(kGood, "plots = false", "plots = 0"), "outputs.plots", "0");
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = 1"), "ensemble.mode");
  expect_error(replace(kGood, "V = [0.0, 0.0, -1.3]", "V = [0.0, -1.3]"), "experiment.V");
  expect_error(replace(kGood, "V = [0.0, 0.0, -1.3]", "V = [0.0, \"a\", -1.3]"), "experiment.V", "\"a\"");
  expect_error(replace(kGood, "[body]\nkind", "body = 3\n[bodyx]\nkind"), "body", "3");
  expect_error(replace(kGood, "seed = 7", "seed = 7.5"), "ensemble.seed", "7.5");
  expect_error(replace(kGood, "seed = 7", "seed = \"x1\""), "ensemble.seed", "x1");
}

TEST(SceneFile, NanInfAndOutOfRangeValuesAreErrorsNamingKeyAndValue) {
  expect_error(replace(kGood, "radius = 3e-3", "radius = nan"), "body.radius", "nan");
  expect_error(replace(kGood, "radius = 3e-3", "radius = inf"), "body.radius", "inf");
  expect_error(replace(kGood, "radius = 3e-3", "radius = -3e-3"), "body.radius", "-0.003");
  expect_error(replace(kGood, "density = 7850.0", "density = -inf"), "material.density", "-inf");
  expect_error(replace(kGood, "eps_t = 1.0", "eps_t = 1.5"), "material.eps_t", "1.5");
  expect_error(replace(kGood, "beta = 0.0467", "beta = 0"), "material.restitution.beta", "0");
  expect_error(replace(kGood, "value = 6.5e-7", "value = nan"), "asperities.radius.value", "nan");
  expect_error(replace(kGood, "value = 6.5e-7", "value = 0.01"), "asperities.radius.value", "0.01");
  expect_error(replace(kGood, "count = 1000", "count = 0"), "asperities.count", "0");
  expect_error(replace(kGood, "count = 1000", "count = -5"), "asperities.count", "-5");
  expect_error(replace(kGood, "count = 1000", "count = 5000000000"), "asperities.count", "5000000000");
  expect_error(replace(kGood, "count = 1000", "count = 1e300"), "asperities.count", "1e+300");
  expect_error(replace(kGood, "count = 1000", "count = 1000\nareal_density = 1e9"), "asperities.areal_density");
  expect_error(replace(kGood, "count = 1000", "areal_density = 1"), "asperities.areal_density");
  expect_error(replace(kGood, "drops = 2000", "drops = 1"), "ensemble.drops", "1");
  expect_error(replace(kGood, "drops = 2000", "drops = 2001"), "ensemble.drops", "multiple");
  expect_error(replace(kGood, "drops = 2000", "drops = 9223372036854775807"), "ensemble.drops");
  expect_error(replace(kGood, "spheres = 10", "spheres = 0"), "ensemble.spheres", "0");
  expect_error(replace(kGood, "threads = 0", "threads = -1"), "ensemble.threads", "-1");
  expect_error(replace(kGood, "seed = 7", "seed = -3"), "ensemble.seed", "-3");
  expect_error(replace(kGood, "V = [0.0, 0.0, -1.3]", "V = [0.0, 0.0, 1.3]"), "experiment.V", "1.3");
  expect_error(replace(kGood, "Omega = [0.2, 0.0, 0.0]", "Omega = [nan, 0.0, 0.0]"), "experiment.Omega", "nan");
  expect_error(replace(kGood, "alpha = 0.01", "alpha = 1"), "outputs.alpha", "1");
  expect_error(replace(kGood, "report = \"report.json\"", "report = \"../x.json\""), "outputs.report", "../x.json");
  expect_error(replace(kGood, "format = 1", "format = 2"), "format", "2");
  expect_error("name = \"x\"\n", "format");
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = \"frozen\""), "ensemble.mode", "frozen");
  expect_error(replace(kGood, "backend = \"auto\"", "backend = \"octree\""), "ensemble.backend", "octree");
  // A backend for sampled drops would be ignored: refused, naming the key and the value.
  const std::string fresh = replace(replace(kGood, "mode = \"explicit\"", "mode = \"sampled\""), "spheres = 10", "spheres = 1");
  EXPECT_NO_THROW(parse_scene(fresh));
  expect_error(replace(fresh, "backend = \"auto\"", "backend = \"grid\""), "ensemble.backend", "grid");
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = \"sampled\""), "ensemble.spheres", "sampled");
  // The names removed in 2.0.0 are refused, saying what to write instead.
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = \"fresh\""), "ensemble.mode", "\"sampled\"");
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = \"fixed\""), "ensemble.mode", "use \"explicit\"");
  EXPECT_EQ(parse_scene(kGood).ensemble.mode, Mode::explicit_spheres);
  EXPECT_TRUE(parse_scene(replace(kGood, "spheres = 10", "spheres = \"auto\"")).spheres_auto);
  expect_error(replace(kGood, "spheres = 10", "spheres = \"many\""), "ensemble.spheres", "many");
  expect_error(replace(kGood, "kind = \"impact\"\nV = [0.0, 0.0, -1.3]\nOmega = [0.2, 0.0, 0.0]", "kind = \"contact\""),
               "outputs.restitution", "impact");
  expect_error(replace(replace(kGood, "contact = true", "contact = false"), "restitution = true", "restitution = false"),
               "outputs.contact", "nothing");
}

TEST(SceneFile, EmptyStringsAreErrorsNamingTheKey) {
  expect_error(replace(kGood, "name = \"tiny\"", "name = \"\""), "name");
  expect_error(replace(kGood, "kind = \"sphere\"", "kind = \"\""), "body.kind");
  expect_error(replace(kGood, "mode = \"explicit\"", "mode = \"\""), "ensemble.mode");
  expect_error(replace(kGood, "dir = \"out\"", "dir = \"\""), "outputs.dir");
  expect_error(replace(kGood, "report = \"report.json\"", "report = \"\""), "outputs.report");
  expect_error(replace(kGood, "backend = \"auto\"", "backend = \"\""), "ensemble.backend");
}

TEST(SceneFile, FeaturesTheEngineLacksAreNotSupportedYetErrors) {
  const auto unsupported = [](const std::string& text, const std::string& key) {
    expect_error(text, key, "not supported yet: " + key);
  };
  unsupported(replace(kGood, "{ model = \"viscoelastic\", beta = 0.0467 }", "{ model = \"constant\", value = 0.9 }"),
              "material.restitution.model");
  unsupported(replace(kGood, "V = [0.0, 0.0, -1.3]", "V = [0.1, 0.0, -1.3]"), "experiment.V");
  // ... but a bad value inside an unsupported feature is reported as the bad value it is.
  expect_error(replace(kGood, "{ distribution = \"fixed\", value = 6.5e-7 }",
                       "{ distribution = \"levels\", radii = [1e-6, 1e-7], fractions = [0.5, 0.6] }"),
               "asperities.radius.fractions", "sum");
  expect_error(replace(kGood, "kind = \"sphere\"", "kind = \"mesh\"\nmesh = \"\""), "body.mesh");
  expect_error(replace(kGood, "kind = \"sphere\"", "kind = \"sphere\"\nmesh = \"a.ply\""), "body.mesh", "mesh");
}

TEST(SceneFile, SyntaxErrorsAndUnreadableFilesAreSceneErrors) {
  try {
    parse_scene("format = 1\n[body\n", "broken.toml");
    ADD_FAILURE() << "accepted a syntax error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.toml:2"), std::string::npos) << e.what();
  }
  // Table headers that trip an assertion inside toml++ 3.3 (upstream PR #301) are refused first.
  for (const char* text : {"[\n", "format = 1\n[\t\nx = 1\n", "[[\n", "[[=", "[[[1]]]\n", "[[[]]\n", "  [ ]\n"}) {
    try {
      parse_scene(text, "hdr.toml");
      ADD_FAILURE() << "accepted " << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("hdr.toml:"), std::string::npos) << e.what();
    }
  }
  // ... while brackets inside values, strings and comments are not headers.
  EXPECT_EQ(parse_scene("format = 1\nname = \"\"\"a\n[\n\"\"\"\n# [\n[experiment]\nkind = \"impact\"\n"
                        "V = [\n0.0,\n0.0,\n-1.0,\n]\nOmega = [0, 0, 0]\n")
                .name,
            "a\n[\n");
  EXPECT_THROW(parse_scene(std::string("format = 1\nname = \"a\xff\"\n")), SceneError);  // not UTF-8
  EXPECT_THROW(parse_scene("format = 1\nformat = 1\n"), SceneError);                  // duplicate key
  EXPECT_THROW(load_scene("/nonexistent/scene.toml"), SceneError);
  EXPECT_THROW(load_scene(kScenes), SceneError);  // a directory
}

// Mesh bodies and unequal asperity radii (body_experiments.hpp) wired into the format.
namespace {

// A small valid scene of each kind; tests replace one line to break it.
const std::string kLevels = R"(format = 1
name = "lv"
[body]
radius = 3e-3
[asperities]
count = 2000
radius = { distribution = "levels", radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8] }
[screening]
bodies = 2
directions = 1000
[ensemble]
drops = 3000
seed = 3
[outputs]
plots = false
)";

const std::string kMesh = R"(format = 1
name = "m"
[body]
kind = "mesh"
mesh = "../meshes/ellipsoid.off"
scale = 1.0
smooth = [4e-3, 3e-3, 2.25e-3]
[asperities]
count = 2000
radius = { distribution = "fixed", value = 6.5e-7 }
[ensemble]
mode = "explicit"
spheres = 2
drops = 200
[experiment]
kind = "impact"
V = [0.0, 0.0, -1.3]
Omega = [0.2, 0.0, 0.0]
[outputs]
plots = false
export_ply = "m.ply"
)";

}  // namespace

TEST(SceneFileBodies, ExampleScenesParseIntoTheExpectedFields) {
  const Scene lv = load_scene(kScenes / "two-levels.toml");
  EXPECT_EQ(lv.name, "two-levels");
  EXPECT_FALSE(lv.mesh.has_value());
  ASSERT_TRUE(lv.radii.has_value());
  EXPECT_TRUE(lv.radii->radii == RadiusDistribution::discrete({1.3e-6, 6.5e-7}, {0.2, 0.8}));
  EXPECT_EQ(lv.radii->screen_bodies, 2u);
  EXPECT_EQ(lv.radii->screen_directions, 100000u);
  EXPECT_EQ(lv.ensemble.sphere.asperities, 100000u);
  EXPECT_EQ(lv.ensemble.sphere.radius, 3e-3);
  EXPECT_EQ(lv.ensemble.mode, Mode::sampled);
  EXPECT_EQ(lv.ensemble.drops, 100000u);
  EXPECT_FALSE(lv.ensemble.impact.enabled);

  const Scene el = load_scene(kScenes / "ellipsoid.toml");
  EXPECT_EQ(el.name, "ellipsoid");
  EXPECT_FALSE(el.radii.has_value());
  ASSERT_TRUE(el.mesh.has_value());
  // Resolved relative to the scene file's directory.
  EXPECT_TRUE(std::filesystem::equivalent(el.mesh->file, kScenes / ".." / "meshes" / "ellipsoid.off")) << el.mesh->file;
  EXPECT_EQ(el.mesh->scale, 1.0);
  EXPECT_EQ(el.mesh->smooth, (std::vector<double>{4e-3, 3e-3, 2.25e-3}));
  EXPECT_EQ(el.mesh->export_ply, "ellipsoid.ply");
  EXPECT_TRUE(el.mesh->export_points);
  EXPECT_FALSE(parse_scene(kMesh).mesh->export_points);
  EXPECT_EQ(el.ensemble.sphere.asperities, 100000u);
  EXPECT_EQ(el.ensemble.sphere.asperity_radius, 6.5e-7);
  EXPECT_EQ(el.ensemble.mode, Mode::explicit_spheres);
  EXPECT_EQ(el.ensemble.spheres, 10u);
  EXPECT_EQ(el.ensemble.drops, 100000u);
  EXPECT_TRUE(el.ensemble.impact.enabled);
  EXPECT_EQ(el.ensemble.impact.speed, 1.3);
  EXPECT_EQ(el.ensemble.impact.omega, Vec3(0.2, 0.0, 0.0));

  // Lognormal radii; defaults of [screening].
  const Scene ln = parse_scene(replace(replace(kLevels, "radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8]", "median = 6.5e-7, sigma = 0.3"),
                                       "levels", "lognormal"));
  ASSERT_TRUE(ln.radii.has_value());
  EXPECT_TRUE(ln.radii->radii == RadiusDistribution::lognormal(6.5e-7, 0.3));
  const Scene dflt = parse_scene(replace(kLevels, "[screening]\nbodies = 2\ndirections = 1000\n", ""));
  EXPECT_TRUE(dflt.radii == RadiiScene{RadiusDistribution::discrete({1.3e-6, 6.5e-7}, {0.2, 0.8})});
  // [screening] on a mesh body with unequal radii (screen_body of its first bodies).
  const Scene ms = parse_scene(replace(kMesh, "radius = { distribution = \"fixed\", value = 6.5e-7 }",
                                       "radius = { distribution = \"levels\", radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8] }") +
                               "[screening]\nbodies = 1\ndirections = 5000\n");
  ASSERT_TRUE(ms.mesh.has_value() && ms.radii.has_value());
  EXPECT_EQ(ms.radii->screen_bodies, 1u);
  EXPECT_EQ(ms.radii->screen_directions, 5000u);
  // parse_scene does not touch the file system: the path stays as written.
  EXPECT_EQ(parse_scene(kMesh).mesh->file, "../meshes/ellipsoid.off");
}

TEST(SceneFileBodies, RoundTripsThroughToToml) {
  std::vector<Scene> scenes{load_scene(kScenes / "two-levels.toml"), load_scene(kScenes / "ellipsoid.toml"),
                            parse_scene(kLevels), parse_scene(kMesh)};
  scenes.push_back(parse_scene(replace(replace(kLevels, "radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8]",
                                               "median = 6.5e-7, sigma = 0.3"),
                                       "levels", "lognormal")));
  Scene mesh_levels = parse_scene(kMesh);
  mesh_levels.radii = RadiiScene{RadiusDistribution::discrete({1e-6, 5e-7}, {0.5, 0.5})};
  mesh_levels.mesh->smooth = {2.5e-3, 2.5e-3, 2.5e-3, 8.0};
  mesh_levels.mesh->export_ply.clear();
  mesh_levels.mesh->scale = 1e-3;
  scenes.push_back(mesh_levels);
  expect_round_trips(scenes);
}

TEST(SceneFileBodies, BadKeysInTheNewSectionsNameTheKeyAndValue) {
  const auto lognormal = [](const std::string& radius) {
    return replace(replace(kLevels, "radii = [1.3e-6, 6.5e-7], fractions = [0.2, 0.8]", radius), "\"levels\"",
                   "\"lognormal\"");
  };
  // Unknown keys.
  expect_error(replace(kMesh, "scale = 1.0", "scale = 1.0\nscael = 2"), "body.scael");
  expect_error(replace(kLevels, "directions = 1000", "directions = 1000\nbody = 3"), "screening.body");
  expect_error(replace(kLevels, "fractions = [0.2, 0.8]", "fractions = [0.2, 0.8], weights = [1]"), "asperities.radius.weights");
  expect_error(lognormal("median = 6.5e-7, sigma = 0.3, mu = 1"), "asperities.radius.mu");
  // Bad values.
  expect_error(replace(kMesh, "scale = 1.0", "scale = -1.0"), "body.scale", "-1");
  expect_error(replace(kMesh, "scale = 1.0", "scale = nan"), "body.scale", "nan");
  expect_error(replace(kMesh, "smooth = [4e-3, 3e-3, 2.25e-3]", "smooth = [4e-3, 3e-3]"), "body.smooth", "2 numbers");
  expect_error(replace(kMesh, "smooth = [4e-3, 3e-3, 2.25e-3]", "smooth = [4e-3, -3e-3, 2.25e-3]"), "body.smooth", "-0.003");
  expect_error(replace(kMesh, "mesh = \"../meshes/ellipsoid.off\"", "mesh = 3"), "body.mesh", "3");
  expect_error(replace(kMesh, "mesh = \"../meshes/ellipsoid.off\"\n", ""), "body.mesh", "missing");
  expect_error(replace(kMesh, "scale = 1.0", "scale = 1.0\nradius = 3e-3"), "body.radius", "sphere");
  expect_error(replace(kLevels, "radius = 3e-3", "radius = 3e-3\nsmooth = [1, 1, 1]"), "body.smooth", "mesh");
  expect_error(replace(kLevels, "fractions = [0.2, 0.8]", "fractions = [0.2, 0.7, 0.1]"), "asperities.radius.fractions", "(2)");
  expect_error(replace(kLevels, "radii = [1.3e-6, 6.5e-7]", "radii = [1.3e-6, -6.5e-7]"), "asperities.radius.radii", "-6.5e-07");
  expect_error(replace(kLevels, "radii = [1.3e-6, 6.5e-7]", "radii = [1.3e-6, 0.01]"), "asperities.radius.radii", "0.01");
  expect_error(replace(kLevels, "radii = [1.3e-6, 6.5e-7], ", ""), "asperities.radius.radii", "missing");
  expect_error(lognormal("median = 6.5e-7, sigma = -0.3"), "asperities.radius.sigma", "-0.3");
  expect_error(lognormal("median = 0, sigma = 0.3"), "asperities.radius.median", "0");
  expect_error(lognormal("median = 6.5e-7"), "asperities.radius.sigma", "missing");
  expect_error(replace(kLevels, "bodies = 2", "bodies = 0"), "screening.bodies", "0");
  expect_error(replace(kLevels, "directions = 1000", "directions = 1.5"), "screening.directions", "1.5");
  expect_error(replace(kMesh, "export_ply = \"m.ply\"", "export_ply = \"../m.ply\""), "outputs.export_ply", "../m.ply");
  expect_error(replace(kLevels, "plots = false", "plots = false\nexport_ply = \"x.ply\""), "outputs.export_ply", "mesh");
  expect_error(replace(kMesh, "export_ply = \"m.ply\"", "export_ply = \"m.ply\"\nexport_style = \"dots\""),
               "outputs.export_style", "dots");
  expect_error(replace(kMesh, "export_ply = \"m.ply\"", "export_style = \"points\""), "outputs.export_style", "export_ply");
  // Combinations the runs cannot honour are refused, naming the key.
  expect_error(replace(kMesh, "mode = \"explicit\"\nspheres = 2", "mode = \"sampled\""), "ensemble.mode", "explicit");
  expect_error(replace(kMesh, "kind = \"impact\"\nV = [0.0, 0.0, -1.3]\nOmega = [0.2, 0.0, 0.0]", "kind = \"contact\""),
               "experiment.kind", "impact");
  expect_error(replace(kMesh, "count = 2000", "areal_density = 1e10"), "asperities.areal_density", "count");
  expect_error(replace(kLevels, "seed = 3", "seed = 3\nbackend = \"grid\""), "ensemble.backend", "grid");
  expect_error(replace(kLevels, "drops = 3000", "drops = 3000\nmode = \"explicit\""), "ensemble.mode", "explicit");
  expect_error(replace(kLevels, "drops = 3000", "drops = 3000\nmode = \"explicit\""), "ensemble.mode", "sampled");
  // Every kind of run writes its report through the same writer: the report name is free.
  EXPECT_EQ(parse_scene(replace(kLevels, "plots = false", "plots = false\nreport = \"x.json\""), "t").report, "x.json");
  expect_error(replace(kMesh, "plots = false", "plots = false\nrestitution = false"), "outputs.restitution");
  expect_error(kGood + "[screening]\nbodies = 2\n", "screening");
  expect_error(kMesh + "[screening]\nbodies = 2\n", "screening");  // equal radii: nothing to screen
  expect_error(replace(lognormal("median = 6.5e-7, sigma = 0.3"), "drops = 3000", "drops = 3001"), "ensemble.drops", "3001");
  // A mesh file that is not there: load_scene names the key and the value.
  const auto f = std::filesystem::temp_directory_path() / "asperity-scene-nomesh.toml";
  {
    std::ofstream(f) << replace(kMesh, "../meshes/ellipsoid.off", "no-such-mesh.off");
  }
  try {
    load_scene(f);
    ADD_FAILURE() << "a missing mesh file was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.key(), "body.mesh");
    EXPECT_NE(std::string(e.what()).find("no-such-mesh.off"), std::string::npos) << e.what();
  }
  std::filesystem::remove(f);
  // ... while a bare file name is found in the source tree's meshes/.
  {
    std::ofstream(f) << replace(kMesh, "../meshes/ellipsoid.off", "icosphere.off");
  }
  EXPECT_TRUE(std::filesystem::is_regular_file(load_scene(f).mesh->file));
  std::filesystem::remove(f);
}

namespace {
const std::string kMeshBounce = replace(replace(kMesh, "drops = 200\n", ""),
                                        "kind = \"impact\"\nV = [0.0, 0.0, -1.3]\nOmega = [0.2, 0.0, 0.0]",
                                        "kind = \"bounce\"\nspeed = 1.0\nstop_speed = 0.1\nsequences = 20\nOmega = [1.0, 2.0, 0.0]");
}  // namespace

// Mesh bodies bounce (body_bounce.hpp): experiment.kind = "bounce" on a mesh body, Omega at the first
// impact (bodies only), the one body variant "dynamic"; what cannot apply names the key.
TEST(SceneFileBodies, MeshBounceScenes) {
  const Scene s = parse_scene(kMeshBounce);
  ASSERT_TRUE(s.mesh.has_value());
  EXPECT_TRUE(s.bounce.enabled);
  EXPECT_FALSE(s.ensemble.impact.enabled);
  EXPECT_EQ(s.bounce.omega, Vec3(1.0, 2.0, 0.0));
  EXPECT_EQ(s.bounce.sequences, 20u);
  EXPECT_EQ(s.bounce.variants, std::vector<BounceVariant>{BounceVariant::dynamic});
  const Scene ex = load_scene(kScenes / "ellipsoid-bounce.toml");
  EXPECT_TRUE(ex.bounce.enabled && ex.mesh.has_value());
  EXPECT_EQ(ex.ensemble.spheres, 4u);
  expect_round_trips({s, ex});
  EXPECT_EQ(parse_scene(replace(kMeshBounce, "sequences = 20", "sequences = 20\nvariants = \"dynamic\"")), s);
  expect_error(replace(kMeshBounce, "sequences = 20", "sequences = 20\nvariants = \"paper\""), "experiment.variants", "dynamic");
  expect_error(replace(kMeshBounce, "sequences = 20", "sequences = 20\nvariants = \"dynamic,paper\""), "experiment.variants");
  expect_error(replace(kMeshBounce, "Omega = [1.0, 2.0, 0.0]", "Omega = [1.0, nan, 0.0]"), "experiment.Omega", "nan");
  expect_error(replace(kMeshBounce, "speed = 1.0", "speed = 1.0\nV = [0, 0, -1]"), "experiment.V", "impact");
  // The sphere's bounce variants start without spin.
  expect_error(replace(kGood, "kind = \"impact\"\nV = [0.0, 0.0, -1.3]", "kind = \"bounce\""), "experiment.Omega", "mesh");
  Scene bad = s;
  bad.bounce.variants = {BounceVariant::paper};
  EXPECT_THROW(validate(bad), std::invalid_argument);
  Scene sphere = preset("fig6");
  sphere.bounce.omega = Vec3(0.1, 0, 0);
  EXPECT_THROW(validate(sphere), std::invalid_argument);
}

// Sec. V groups are scene-selectable (issue 15); the defaults stay those of BounceExperiment.
// A scene text without the [ensemble] keys a sphere's bounce run refuses (it takes seed and threads).
std::string bounce_ensemble(std::string text) {
  std::string out;
  for (std::size_t pos = 0; pos < text.size();) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string line = text.substr(pos, end - pos);
    bool drop = false;
    for (const char* k : {"mode =", "drops =", "spheres =", "backend =", "kernel ="}) drop |= line.rfind(k, 0) == 0;
    if (!drop) out += line + "\n";
    pos = end + 1;
  }
  return out;
}

TEST(SceneFile, BounceGroupsAreSelectable) {
  const std::string base = bounce_ensemble(
      replace(kGood, "kind = \"impact\"\nV = [0.0, 0.0, -1.3]\nOmega = [0.2, 0.0, 0.0]", "kind = \"bounce\"\nsequences = 20"));
  // The keys it never uses are refused, never ignored (issue 43): drops counts nothing in a bounce.
  expect_error(replace(base, "seed = ", "drops = 100\nseed = "), "ensemble.drops", "experiment.sequences");
  const Scene d = parse_scene(base);
  EXPECT_EQ(d.bounce.windows, BounceExperiment{}.windows);
  EXPECT_EQ(d.bounce.impact_numbers, BounceExperiment{}.impact_numbers);
  const Scene s = parse_scene(replace(base, "sequences = 20", "sequences = 20\nspeed_windows = [[0.2, 0.25], [0.5, 0.55]]\nimpact_groups = [1, 3, 7]"));
  EXPECT_EQ(s.bounce.windows, (std::vector<std::pair<double, double>>{{0.2, 0.25}, {0.5, 0.55}}));
  EXPECT_EQ(s.bounce.impact_numbers, (std::vector<unsigned>{1, 3, 7}));
  expect_round_trips({s});
  expect_error(replace(base, "sequences = 20", "sequences = 20\nspeed_windows = [[0.5, 0.4]]"), "experiment.speed_windows", "lo < hi");
  expect_error(replace(base, "sequences = 20", "sequences = 20\nspeed_windows = [0.5, 0.6]"), "experiment.speed_windows", "pair");
  expect_error(replace(base, "sequences = 20", "sequences = 20\nimpact_groups = [0, 2]"), "experiment.impact_groups", ">= 1");
  expect_error(replace(base, "sequences = 20", "sequences = 20\nimpact_groups = [2.5]"), "experiment.impact_groups", "whole");
  expect_error(replace(kGood, "V = [0.0, 0.0, -1.3]", "V = [0.0, 0.0, -1.3]\nimpact_groups = [1]"), "experiment.impact_groups", "bounce");
}

// Issue 33 item 4: any byte a POSIX path may hold (all but '/' and NUL) either round-trips through
// to_toml and the scene reader -- what checkpoint.toml does for --resume -- or is refused by
// validate, naming the key, before any run. Non-ASCII UTF-8 (résumé, CJK, emoji) round-trips;
// bytes that are not UTF-8 are refused (TOML and JSON hold UTF-8 only). A refusal of every
// non-ASCII name would fail the first half, a round-trip that drops bytes the second.
TEST(SceneFile, EveryPathByteRoundTripsThroughTomlOrIsRefusedUpFront) {
  std::vector<std::string> names;
  for (int b = 1; b < 256; ++b)
    if (b != '/') names.push_back("out" + std::string(1, static_cast<char>(b)) + "x");
  for (const char* utf8 : {"r\xc3\xa9sum\xc3\xa9", "\xe6\x97\xa5\xe6\x9c\xac", "\xf0\x9f\x98\x80", "a\\b\"c"})
    names.push_back(utf8);
  int round_trips = 0, refused = 0;
  for (const std::string& name : names) {
    Scene s = preset("fig4");
    s.out = name;
    std::string why;
    try {
      validate(s);
    } catch (const std::invalid_argument& e) {
      why = e.what();
    }
    if (!why.empty()) {
      ++refused;
      EXPECT_NE(why.find("outputs.dir (--out)"), std::string::npos) << why;
      EXPECT_NE(why.find("not UTF-8"), std::string::npos) << why;
      continue;
    }
    ++round_trips;
    const std::string text = to_toml(s);
    for (char c : text) ASSERT_LT(static_cast<unsigned char>(c), 0x80) << "to_toml wrote a non-ASCII byte for " << name;
    EXPECT_EQ(parse_scene(text, "checkpoint.toml").out.string(), name);
  }
  EXPECT_EQ(refused, 128) << "the bytes 0x80..0xff alone are not UTF-8";
  EXPECT_EQ(round_trips, static_cast<int>(names.size()) - 128);
}
