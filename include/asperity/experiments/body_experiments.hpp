// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Experiments beyond the paper, as values in and values out (the lead wires them to the scene
// format): (1) unequal asperity radii on a sphere: screening, effective density and the law of
// r_x; (2) single impacts of rough mesh bodies (mesh.hpp) with the full inertia tensor.
// Each run returns its report as a value, figures included as data (laws/figure.hpp); app/ writes
// them (app/experiment_reports.hpp: tables, report.json bodies, PNGs).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "asperity/core/body.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/laws/family.hpp"
#include "asperity/laws/figure.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/verdict.hpp"

namespace asperity {

/// One KS test of a sample against a law, with its verdict at the run's alpha (accept / reject /
/// skipped: the law could not be evaluated). quantity: "r_x", "r_xy", "eps"; law: e.g.
/// "exact-levels", "gauss-lambda", "gauss-lambda-eff", "gauss-lambda-top". decisive: an exact
/// finite-N law, whose rejection fails the run (exit status 1); the paper's laws applied to other
/// radii or bodies are measurements, not pass/fail.
struct LawCheck : LawTest {
  double lambda = 0;        ///< areal density behind a Gaussian law [1/m^2] (NaN otherwise)
  KsResult ks;              ///< the KS test (D, p, n)
  bool power_check = false; ///< a deliberately wrong law: must be rejected
};

/// Spheres with asperities of unequal radii (scene [asperities] radius a distribution): the law of
/// r_x against the exact level law and Gaussians of several densities, with a screening cross-check.
struct RadiiExperiment {
  std::uint64_t asperities = 100000;  ///< N
  double radius = 3e-3;               ///< R [m]
  /// The asperities' radii (core/body.hpp: fixed, discrete levels or lognormal) [m].
  RadiusDistribution radii = RadiusDistribution::discrete({1.3e-6, 6.5e-7}, {0.2, 0.8});
  std::uint64_t drops = 100000;       ///< fresh drops for the r_x law (iid)
  std::uint64_t screen_bodies = 2;    ///< explicit spheres screened for lambda_eff
  std::uint64_t screen_directions = 200000;  ///< random directions of the screening cross-check, per body
  std::uint64_t seed = 1;             ///< every body and drop is a pure function of (seed, index)
  double alpha = 0.01;                ///< level of each test and of the decisive family (Holm)
  bool plots = true;  ///< build the figures (RadiiReport::figures)
};
/// Throws std::invalid_argument naming the field.
void validate(const RadiiExperiment& e);

/// What run_radii_experiment measured: densities, screening counts, the fresh drops' r_x and the tests.
struct RadiiReport {
  RadiiExperiment experiment;       ///< the experiment run
  double lambda = 0;                ///< N / (4 pi R^2)
  double lambda_top = 0;            ///< density of the largest level
  Estimate lambda_eff;              ///< kept asperities per area, mean over screened bodies (se over bodies)
  std::vector<double> kept_fraction_by_level;  ///< levels only: kept/total per level (pooled over bodies)
  double theta_cover = 0;           ///< largest empty cap, first body [rad]
  double mean_competitors = 0;      ///< mean competitors per asperity after the half-space filter
  std::uint64_t witnessed = 0;      ///< kept with a witness direction, pooled over bodies
  std::uint64_t helly = 0;          ///< kept by Helly's theorem, without a checked direction, pooled
  std::uint64_t screened = 0;       ///< proved never lowest (a triple of competitors), pooled
  std::uint64_t winners_screened = 0;  ///< cross-check: screened asperities that won a direction (must be 0)
  std::uint64_t kept_never_hit = 0;    ///< cross-check: kept asperities no direction hit
  std::uint64_t directions = 0;        ///< cross-check: random directions queried
  double lambda_fit = 0;            ///< 1/(2 pi var(r_x)) of the fresh drops
  Estimate rx_std;                  ///< [m]
  std::uint64_t core_contacts = 0;  ///< fresh drops where the bare sphere reaches lower
  std::vector<double> winner_level_fraction;  ///< fresh drops: which level touched
  std::vector<LawCheck> tests;      ///< the KS tests of r_x
  std::vector<NamedFigure> figures;  ///< built when experiment.plots; written by app/
  std::vector<std::string> plots;    ///< file names written (filled by app/)
  /// Wall seconds: screening (incl. the rotations of lognormal runs), fresh drops, tests, figures.
  double seconds_screen = 0;
  double seconds_fresh = 0;     ///< wall seconds of the fresh drops
  double seconds_analysis = 0;  ///< wall seconds of the tests
  double seconds_plots = 0;     ///< wall seconds of the figures

  /// The family of decisive tests rejects a law (Holm at experiment.alpha).
  bool rejected() const;
};

/// The family of decisive checks at alpha (laws/family.hpp: Holm over the decided ones).
FamilyDecision check_family(const std::vector<LawCheck>& tests, double alpha);
/// The family rejects a law (Holm at alpha): the run exits 1.
bool decisive_rejection(const std::vector<LawCheck>& tests, double alpha);
/// Decisive tests that could not be evaluated (verdict "skipped": D and p NaN, the note says why).
std::size_t decisive_skipped(const std::vector<LawCheck>& tests);

/// Screens `screen_bodies` explicit spheres (Stream(seed, sphere, k)), draws `drops` fresh
/// contacts, tests r_x against the exact level law, Gaussians with lambda, lambda_eff and the top
/// level's lambda, and the exact law stretched by 5% (power check). Builds the r_x figure when
/// e.plots. `progress(done, drops)`
/// is called from the calling thread between chunks of drops (lognormal: rotations).
RadiiReport run_radii_experiment(const RadiiExperiment& e, const Progress& progress = {});

/// Single impacts of rough mesh bodies (K explicit bodies x M random rotations each, like the
/// "fixed" ensemble), compared with the paper's sphere laws for the sphere of equal volume (or the
/// given smooth sphere) carrying the same areal density of asperities.
struct MeshImpactExperiment {
  std::filesystem::path mesh = "meshes/ellipsoid.off";  ///< the mesh file (OFF or PLY)
  double scale = 1.0;                  ///< mesh coordinates -> metres
  std::vector<double> smooth_ellipsoid;  ///< empty: centres on the facets; {a, b, c[, m]}: mapped onto that
                                         ///< (super)ellipsoid [m] (m = 2 if absent)
  std::uint64_t asperities = 100000;   ///< N per body
  RadiusDistribution radii = RadiusDistribution::fixed(6.5e-7);  ///< the asperities' radii [m]
  double density = 7850;               ///< [kg/m^3]
  std::uint64_t bodies = 10;           ///< K explicit bodies (drops must be a multiple)
  std::uint64_t drops = 100000;        ///< impacts in all (bodies x rotations)
  double speed = 1.3;                  ///< [m/s], V = (0, 0, -speed)
  Vec3 omega{0.2, 0.0, 0.0};           ///< [rad/s]
  double beta = 0.0467;                ///< Pade [1/4] constant of eps_n(v)
  double eps_t = 1.0;                  ///< kinematic law's coefficient (tangential.model == kinematic)
  TangentialLaw tangential;            ///< the tangential law; kinematic uses eps_t above
  std::uint64_t seed = 1;              ///< every body and drop is a pure function of (seed, index)
  double alpha = 0.01;                 ///< level of each test and of the decisive family (Holm)
  bool plots = true;  ///< build the figures (MeshImpactReport::figures)
  std::uint64_t screen_bodies = 2;         ///< unequal radii: the first bodies screened (screen_body); 0: none
  std::uint64_t screen_directions = 200000;  ///< random directions of the screening cross-check, per body
};
/// Throws std::invalid_argument naming the field.
void validate(const MeshImpactExperiment& e);
/// The law the impacts use: e.tangential, with e.eps_t when it is the kinematic law.
TangentialLaw tangential_law(const MeshImpactExperiment& e);

/// A quantity's summary, by name.
struct NamedSummary {
  std::string name;  ///< "r_x", "r_y", "r_z", "r_xy" [m], "eps" [1], "omega_x_after" [rad/s]
  Summary summary;   ///< se from batch means over the K bodies
};

/// Screening of the first bodies of a mesh run (screening.hpp, screen_body); pooled over them.
struct MeshScreening {
  std::uint64_t bodies = 0;         ///< 0: not run (equal radii, or screen_bodies = 0)
  double lambda = 0;                ///< N / mesh surface area [1/m^2]
  Estimate lambda_eff;              ///< kept per mesh surface area, mean over bodies (se over bodies) [1/m^2]
  std::vector<double> levels;       ///< level radii [m] (levels only)
  std::vector<double> kept_fraction_by_level;  ///< kept/total per level, pooled
  double kept_fraction = 0;         ///< kept/total, pooled
  std::uint64_t witnessed = 0;      ///< kept with a witness direction
  std::uint64_t helly = 0;          ///< kept without a proof
  std::uint64_t screened = 0;       ///< proven never lowest
  double mean_competitors = 0;      ///< mean competitors per asperity
  std::uint64_t directions = 0;     ///< cross-check: random directions queried
  std::uint64_t winners_screened = 0;  ///< cross-check: screened asperities that won a direction (must be 0)
  std::uint64_t kept_never_hit = 0;    ///< cross-check: kept asperities no direction hit
  double seconds = 0;               ///< wall time of the screening [s]
};

/// What run_mesh_impacts measured: the body, the summaries, the tests against the sphere laws.
struct MeshImpactReport {
  MeshImpactExperiment experiment;  ///< the experiment run
  MassProperties mass;              ///< mass, centre of mass and inertia of the body
  Vec3 principal_moments{0, 0, 0};  ///< eigenvalues of J [kg m^2], ascending
  double law_radius = 0;            ///< radius of the comparison sphere [m]
  std::uint64_t law_asperities = 0; ///< N of the comparison sphere (same areal density)
  std::uint64_t samples = 0;        ///< impacts solved
  std::uint64_t no_impacts = 0;     ///< drops whose contact point does not approach the plate
  std::uint64_t core_contacts = 0;  ///< drops where the bare base surface reaches lower than every asperity
  /// Impacts whose kinetic energy increases (> 1e-9 relative), and the largest relative change
  /// (negative: every impact lost energy; NaN without impacts): the kinematic law with eps_t = 1
  /// gains off-centre, Stronge's law never does.
  double energy_gain_fraction = 0;
  double energy_gain_max = 0;       ///< the largest relative change of kinetic energy (above)
  std::vector<NamedSummary> quantities;  ///< r_x, r_y, r_z, r_xy, eps, omega_x_after
  std::vector<LawCheck> tests;      ///< pooled over K x M drops: p assumes iid (see note)
  std::vector<NamedFigure> figures;  ///< built when experiment.plots; written by app/
  std::vector<std::string> plots;    ///< file names written (filled by app/)
  double seconds = 0;               ///< the whole run [s]
  /// Wall seconds: mesh and mass properties, K bodies x M impacts, summaries and tests, figures.
  double seconds_mesh = 0;
  double seconds_drops = 0;     ///< wall seconds of the K bodies x M impacts
  double seconds_analysis = 0;  ///< wall seconds of the summaries and tests
  double seconds_plots = 0;     ///< wall seconds of the figures

  MeshScreening screening;          ///< unequal radii only

  /// The family of decisive tests rejects a law (Holm at experiment.alpha).
  bool rejected() const;
};

/// Impacts of bodies built on `mesh` (the file e.mesh, read by the caller: app/mesh_io.hpp). Builds
/// the eps / r_x figures when e.plots. `progress(done, drops)` is called from the calling thread
/// between chunks.
MeshImpactReport run_mesh_impacts(const MeshImpactExperiment& e, const TriangleMesh& mesh, const Progress& progress = {});

}  // namespace asperity
