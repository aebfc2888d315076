// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The bouncing ball of the paper's Sec. V: a rough sphere dropped onto a plate bounces until its
// impact speed falls below a threshold; the restitution coefficients of all its impacts are
// collected, grouped, and fitted with the asymmetric Laplace law of Eq. 2 (laplace.hpp).
//
// Variants (selectable, reported side by side):
//  - paper: the paper's Sec. V procedure. eps from Eq. 28 along the paper's own route, i.e. with its
//    approximations (Eq. 26: r_x + r_y ~ r_xy Rayleigh, times the tracked, signed Omega_x; r_z = R + a)
//    and the algebra repaired so that it is a density (eq28-paper-route, theory_impact.hpp): s ~
//    Rayleigh(sigma), eps = eq28_paper_route_eps(s). Then Omega'_x = Omega_x + (1 + eps) u r_y/(I + r_z^2),
//    r_y ~ Normal(0, sigma^2) drawn independently of s (Eq. 32 with the sign and J corrected; P_z =
//    M u (1 + eps) with the eps just drawn; equivalently the corrected Eq. 33), as the paper's Fig. 5
//    drew r_y and eps independently. Only Omega_x is tracked and it keeps its sign between impacts.
//    The next impact speed is eps times this one (flight conserves |V_z|).
//  - paper-printed33: the same with Omega'_x ~ Normal(Omega_x, sigma_printed^2), Eq. 33 as printed
//    (6x wider). Eq. 28 as printed is not a density (docs/sec4-derivations.md) and cannot be iterated.
//  - paper-corrected28: the paper's iteration with eps from the corrected Eq. 28 (noncentral chi^2 in
//    |Omega_x|, no Eq. 26) and Omega'_x from the corrected Eq. 33 drawn independently; only Omega_x
//    tracked. It isolates what Eq. 26 does inside the paper's procedure (paper vs paper-corrected28)
//    and what a one-component spin does (paper-corrected28 vs random-orientation).
//  - random-orientation: explicit geometry and the full impulse (impact.hpp) at every impact, on
//    one lazy exact sphere per sequence (lazy_sphere.hpp) given a fresh Haar orientation before
//    every impact: consecutive contacts are independent, as the paper assumes.
//  - dynamic: the same sphere and impulse, but the orientation is carried by the real rotation
//    between impacts: q(t) = exp(Omega t) q exactly (isotropic inertia: free rotation is uniform
//    about the constant Omega), so consecutive contacts are correlated.
// Flight (explicit variants): the centre lifts off at height h = -r_z (the contact point on the
// plate), flies ballistically under gravity g, and lands when its lowest point touches: the
// landing time solves h + V_z t - g t^2/2 = D(q(t)), D the depth of the lowest point below the
// centre (R (1 - key/2) + a, or R for a core contact), by fixed-point iteration on t (D changes by
// ~R Omega theta t ~ 1e-11 m over the nanoseconds it shifts t, so it converges in 2-3 steps).
// The flight times T_k are exact including the height differences of successive contacts; they
// give eps as the experiment measures it, T_k / T_{k-1}.
// Frame and units: z up, plate normal +z, SI (m, s, rad/s). Sequence i uses only streams keyed
// by (seed, i): results are bit-identical for any thread count.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "asperity/core/geometry.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/laplace.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/verdict.hpp"

namespace asperity {

/// How a bounce sequence draws each impact (the variants at the top of this header).
enum class BounceVariant { paper, paper_printed33, random_orientation, dynamic, paper_corrected28 };
/// "paper", "paper-printed33", "random-orientation", "dynamic" or "paper-corrected28".
std::string_view to_string(BounceVariant v);
/// "paper", "paper-printed33", "random-orientation", "dynamic", "paper-corrected28"; throws std::invalid_argument naming the value.
BounceVariant parse_bounce_variant(std::string_view s);

/// Stated ranges of a bounce sequence (validate): where its model and its numbers hold.
/// Speed: the viscoelastic collision law of Eq. 9 is quasi-static, valid far below the speed of
/// sound in the bodies (~10^3 m/s to ~6*10^3 m/s for metals and glass); at 1e7 m/s the statistics of
/// a sequence reached NaN (exit 2 with an internal message) and at 1e155 the squared speed
/// overflowed (NaN reported with exit 0, issue 33 item 6). The same bound holds for the spin's
/// surface speed |Omega|(R + a) (checked with the body's size, scene.cpp).
inline constexpr double kMaxBounceSpeed = 1e3;
/// Gravity: from 1e-3 m/s^2 (1e-4 g) to 1e4 m/s^2 (1e3 g). Each flight lasts 2 u / g and the
/// body turns freely meanwhile: at the ends of these ranges a flight lasts at most 2e6 s; below
/// them (5e-324 m/s^2) the flight time overflowed, above them (1e19) it vanished below the
/// resolution of the impact times.
inline constexpr double kMinGravity = 1e-3;
/// Largest gravity of a bounce sequence [m/s^2] (kMinGravity).
inline constexpr double kMaxGravity = 1e4;

/// The bouncing-ball experiment of a scene ([experiment] kind = "bounce"): its variants, size,
/// first impact, stop condition, material and analysis.
struct BounceExperiment {
  bool enabled = false;          ///< false: no bounce run
  /// The variants run, each on the same seeds, reported side by side.
  std::vector<BounceVariant> variants{BounceVariant::paper, BounceVariant::random_orientation, BounceVariant::dynamic};
  std::uint64_t sequences = 100000;  ///< bounce sequences per variant
  double speed = 1.0;        ///< first impact speed -V_z [m/s]
  /// Spin at the first impact, world frame [rad/s]: bodies only (body_bounce.hpp); the sphere
  /// variants start without spin (Sec. V), run_bounces refuses anything else.
  Vec3 omega{0, 0, 0};
  double stop_speed = 0.1;   ///< the sequence ends before the first impact slower than this [m/s]
  double gravity = 9.81;     ///< [m/s^2]
  double density = 7850;     ///< [kg/m^3] (eps does not depend on it)
  double beta = 0.0467;      ///< viscoelastic Pade [1/4] constant of Eq. 9 [(s/m)^(1/5)]
  double eps_t = 1.0;        ///< tangential restitution (paper: 1)
  /// The tangential law of the explicit variants (core/tangential.hpp): kinematic (the default)
  /// uses eps_t above; coulomb, stronge and walton solve each impact with solve_impact. The paper
  /// variants are the paper's kinematic law and refuse anything else (run_bounces). Mesh-body
  /// bounces take their law from MeshBounceOptions::tangential instead.
  TangentialLaw tangential;
  unsigned max_impacts = 100000;  ///< safety bound per sequence
  std::size_t bootstrap = 99;     ///< replicates of the goodness-of-fit bootstrap (per group at most
                                  ///< max(19, bootstrap_draws/n): the work is B n; the count used is reported)
  /// The work budget B n of one group's bootstrap (draws); big low-speed windows get fewer replicates.
  std::uint64_t bootstrap_draws = 20000000;
  /// Sequential stop of that bootstrap (laplace.hpp SequentialStop): after this many replicates at
  /// or beyond the data's D, once the verdict can only be "accept", p is estimated as K / L from
  /// the L replicates drawn; the verdicts are those of all B. 0: always all B (exact p).
  std::size_t bootstrap_stop = 10;
  /// Level of the goodness-of-fit verdicts: a group whose bootstrap found no replicate as far from
  /// its fit as the data (p at its floor 1/(1+B)) while 1/(1+B) >= alpha is undecided.
  double alpha = 0.01;
  /// Impact-speed windows [lo, hi] [m/s]: p(eps | u) with the history marginalised as the experiment
  /// does; membership depends on the past (u_k = u_1 prod eps_j), see bounce_grouping_note().
  std::vector<std::pair<double, double>> windows{{0.9, 1.0}, {0.7, 0.8}, {0.5, 0.6}, {0.3, 0.4}, {0.1, 0.2}};
  /// Impact numbers k (1 = first impact) grouped for comparison.
  std::vector<unsigned> impact_numbers{1, 2, 5, 10, 20, 40};

  /// Field by field.
  friend bool operator==(const BounceExperiment&, const BounceExperiment&) = default;
};

/// Throws std::invalid_argument naming the offending field and value.
void validate(const BounceExperiment& b);

/// Every impact of every sequence, sequence by sequence, in impact order.
struct BounceSamples {
  BounceVariant variant = BounceVariant::dynamic;  ///< the variant that made them
  std::optional<SphereParams> sphere;   ///< set by run_bounces (enables the semi-analytic residual law)
  double first_speed = 0;               ///< u_1 [m/s]
  std::uint64_t sequences = 0;          ///< sequences run
  std::vector<std::uint32_t> sequence;  ///< sequence index
  std::vector<std::uint32_t> number;    ///< impact number k = 1, 2, ...
  std::vector<double> speed;            ///< impact speed u_k = -V_z before [m/s]
  std::vector<double> eps;              ///< V'_z / u_k (Eq. 1)
  std::vector<double> eps_time;         ///< T_k / T_{k-1} from flight times (NaN for k = 1)
  std::vector<float> spin;              ///< |Omega| before the impact [rad/s]
  std::vector<float> omega_x_after;     ///< Omega'_x [rad/s]
  std::vector<std::uint8_t> core;       ///< the central sphere touched (explicit variants)
  std::uint64_t no_impacts = 0;         ///< sequences cut short: contact point not approaching
  std::uint64_t cells = 0;              ///< lazy-sphere cells generated, summed over the sequences
  std::uint64_t centres = 0;            ///< lazy-sphere centres generated, summed
  double seconds = 0;                   ///< wall time of the run [s]
};

/// Free rotation of an isotropic body: q(t) = exp(Omega t) q, Omega the constant world-frame
/// angular velocity [rad/s], t [s] (q maps body to world, orientation.hpp).
Eigen::Quaterniond advance_rotation(const Eigen::Quaterniond& q, const Vec3& omega, double t);

/// Ballistic flight of the centre from lift-off height h0 [m] with vertical velocity vz > 0 [m/s]
/// until it is at height D [m]: the later root of h0 + vz t - g t^2/2 = D, and the vertical
/// velocity then (-sqrt(vz^2 + 2 g (h0 - D)), energy conservation written without cancellation).
struct Flight {
  double time = 0;          ///< [s]
  double landing_vz = 0;    ///< [m/s], <= 0
};
/// The Flight from h0 with vz until height D under gravity g [m/s^2].
Flight ballistic_flight(double h0, double vz, double D, double g);

/// Runs `sequences` sequences of one variant for a sphere (N, R, a). threads = 0: OpenMP default.
/// progress(done, total) is called from the calling thread between blocks of sequences (at most
/// kBounceBlock each, well under a second); an exception it throws (the Python module's
/// KeyboardInterrupt) ends the run and comes out of this call. Results do not depend on the blocks.
inline constexpr std::uint64_t kBounceBlock = 1024;
/// The sequences of variant `v` of `b` for `sphere` (the comment above); throws
/// std::invalid_argument for an experiment the variant refuses (validate, spin, tangential law).
BounceSamples run_bounces(const SphereParams& sphere, const BounceExperiment& b, BounceVariant v, std::uint64_t seed,
                          int threads = 0, const Progress& progress = {});

/// One group of impacts (a speed window or an impact number) and its fit.
struct BounceGroup {
  std::string by;              ///< "speed" or "impact"
  /// What is histogrammed and fitted: "eps" (impact groups: one speed) or "eps-eps_n(u)" (speed
  /// windows: eps_n changes by ~5e-4 across a 0.1 m/s window, 100x the roughness scatter, so the
  /// window's law of eps itself would be eps_n's speed dependence, not the fluctuation).
  std::string quantity;
  double lo = 0;               ///< window [m/s], or k (lo = hi)
  double hi = 0;               ///< window's upper end [m/s], or k
  std::size_t n = 0;           ///< impacts in the group
  double mean_speed = 0;       ///< [m/s]
  Estimate eps_mean;           ///< mean of `quantity` with iid se
  double eps_std = 0;          ///< standard deviation of `quantity`
  double spin_mean = 0;        ///< mean |Omega| before impact [rad/s]
  Estimate eps_time_minus_eps; ///< mean of eps(times) - eps(velocities) (impacts k >= 2)
  bool fitted = false;         ///< n >= 20
  LaplaceFit fit;              ///< Eq. 2 fit of `quantity` (when fitted)
  LaplaceGof gof;              ///< its bootstrap goodness of fit
  /// accept, reject (p < alpha) or undecided ("cannot decide at this B": no replicate reached D and
  /// the floor 1/(1+B) is not below alpha); skipped without a bootstrap.
  Verdict gof_verdict = Verdict::skipped;
  /// The residual eps - eps_n(u_k) of every group (for speed windows the same as `quantity`):
  /// mean, sd, Eq. 2 fit (no bootstrap) and its correlation with the impact speed u_k (se 1/sqrt(n)).
  Estimate residual_mean;
  double residual_std = 0;               ///< sd of the residual
  bool residual_fitted = false;          ///< n >= 20
  LaplaceFit residual_fit;               ///< Eq. 2 fit of the residual
  Estimate speed_residual_correlation;   ///< correlation of the residual with u_k
  /// Semi-analytic law of the residual (theory_impact.hpp bounce_residual_laws; for a speed window the
  /// mixture over the impact numbers it holds, weighted by their counts): KS of the residual against
  /// it, and for impact groups its rates. Spheres only (has_theory).
  bool has_theory = false;
  KsResult theory_ks;              ///< KS of the residual against that law
  double theory_rate_below = 0;    ///< its rate below the mode (impact groups)
  double theory_rate_above = 0;    ///< its rate above the mode (impact groups)
  std::vector<double> sorted;  ///< the group's `quantity`, sorted (for figures; not serialised)
};

/// One variant's analysis (analyse_bounces): its groups and fits, and the checks across them.
struct BounceVariantReport {
  BounceVariant variant = BounceVariant::dynamic;  ///< the variant analysed
  std::uint64_t sequences = 0;        ///< sequences run
  std::uint64_t impacts = 0;          ///< impacts over all sequences
  std::uint64_t no_impacts = 0;       ///< sequences cut short: contact point not approaching
  double impacts_per_sequence = 0;    ///< mean impacts per sequence
  double seconds = 0;                 ///< wall time of the run [s]
  double cells_per_sequence = 0;      ///< lazy-sphere cells generated per sequence
  double centres_per_sequence = 0;    ///< lazy-sphere centres generated per sequence
  std::vector<BounceGroup> groups;    ///< speed windows, then impact numbers
  /// eps from flight times against eps from velocities, all impacts k >= 2.
  std::size_t time_n = 0;
  double time_diff_mean = 0;     ///< mean of eps(times) - eps(velocities)
  double time_diff_sd = 0;       ///< its standard deviation
  double time_diff_max_abs = 0;  ///< its largest magnitude
  double spin_final_mean = 0;   ///< mean |Omega| before the last impact [rad/s]
  /// Lag-1 correlation of eps - eps_n(u) between consecutive impacts of a sequence (k >= 2), and
  /// its iid standard error 1/sqrt(pairs): how much the orientation carried between impacts
  /// correlates consecutive contacts.
  Estimate lag1_correlation;
  std::size_t lag1_pairs = 0;    ///< consecutive pairs behind lag1_correlation
};

/// Two-sample KS between two variants' groups (same grouping): does the variant change the law?
struct BounceComparison {
  BounceVariant a;    ///< the first variant
  BounceVariant b;    ///< the second variant
  std::string by;     ///< the grouping, "speed" or "impact" (BounceGroup::by)
  double lo = 0;      ///< the group (BounceGroup::lo)
  double hi = 0;      ///< the group (BounceGroup::hi)
  KsResult ks;        ///< two-sample KS between the groups' `quantity`
};
/// For every pair of variants in `r` and every group present in both (n >= 20 each).
std::vector<BounceComparison> compare_bounce_variants(const std::vector<BounceVariantReport>& r);

/// Groups, fits (profile MLE, Fisher se) and bootstrap goodness of fit (Purpose::analysis streams
/// keyed by seed). Groups with fewer than 20 impacts are listed without a fit.
BounceVariantReport analyse_bounces(const BounceSamples& s, const BounceExperiment& b, std::uint64_t seed);

/// Runs and analyses every variant of `b` in turn (samples are freed after each analysis); writes a
/// line per variant to `log` if given; progress counts sequences over all variants.
std::vector<BounceVariantReport> run_bounce_experiment(const SphereParams& sphere, const BounceExperiment& b,
                                                       std::uint64_t seed, int threads = 0, std::ostream* log = nullptr,
                                                       const Progress& progress = {});

/// Which grouping answers which question, and when window selection by the past biases it.
std::string bounce_grouping_note();



}  // namespace asperity
