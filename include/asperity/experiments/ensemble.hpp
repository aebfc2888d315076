// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Ensembles of drops: rough spheres meeting the plate. Two designs, named in every report:
//  - explicit (the default): K explicit spheres of N asperities x M Haar-random rotations each;
//    every contact is found by a spatial query (grid by default; brute, kdtree, cgal, fcl) on the
//    rotated sphere. Rotations of one sphere sample that sphere's own (quenched) law, which differs
//    from the ensemble law of Eqs. 13/14/18 by O(1/sqrt(N)); K spheres average it down, and the
//    decisive tests (report.hpp) take the spread between spheres into account. K follows from an
//    error budget (auto_spheres). A deterministic subsample of the queries is answered again by
//    brute force and the kd-tree (and FCL where built and cheap): any disagreement is an error.
//  - sampled: no geometry. The two lowest asperities of each drop are drawn from the exact
//    finite-N law of the lowest asperity (order statistics of the polar angle, fresh_cap): the
//    theory cross-check and speed baseline, never called geometry.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/drop_kernel.hpp"
#include "asperity/core/tangential.hpp"
#include "asperity/core/geometry.hpp"

namespace asperity {

/// How the drops are made: explicit rough spheres (K spheres x M Haar rotations, every contact
/// found by a spatial query), or sampled iid from the exact finite-N law of the lowest asperity
/// (fresh_cap: no sphere is built).
enum class Mode { explicit_spheres, sampled };
/// "explicit" or "sampled".
std::string_view to_string(Mode m);
/// "explicit" or "sampled". Throws std::invalid_argument naming the value otherwise; for the
/// names removed in 2.0.0 ("fixed", "fresh") the message says what to write instead (removed_mode).
Mode parse_mode(std::string_view s);
/// For "fixed" and "fresh", the mode names of versions before 2.0.0: why they are refused and
/// which name to use ("explicit"; for "fresh" also "sampled"). Empty for any other text.
std::string removed_mode(std::string_view s);

/// KS-scale constant of the quenched deviation: one fixed sphere's orientation-averaged law of
/// r_xy differs from the ensemble law by E sup_t |F_sphere(t) - F(t)| ~ kQuenchedKs / sqrt(N)
/// (measured: bench/quenched_scale.cpp, bench/RESULTS.md "Explicit design: quenched constant").
inline constexpr double kQuenchedKs = 0.25;
/// Fewest spheres of an automatic design: the sphere-block bootstrap of the decisive tests needs
/// enough independent blocks to estimate the spread between spheres.
inline constexpr std::uint64_t kAutoMinSpheres = 50;
/// Fewest spheres for a decisive test at all (fewer: every test is reported, none decides).
inline constexpr std::uint64_t kMinDecisiveSpheres = 20;

/// The error budget of an explicit design for N asperities and `drops` drops: K spheres, M = drops/K
/// rotations each, with M <= N / (10 c^2) (c = kQuenchedKs), so that the quenched deviation of the
/// pooled law, c/sqrt(N K), stays below 1/sqrt(10) of the statistical resolution 1/sqrt(K M), and
/// K >= kAutoMinSpheres (or every drop its own sphere when there are fewer drops). K is the
/// smallest such divisor of drops.
std::uint64_t auto_spheres(std::uint64_t asperities, std::uint64_t drops);

/// Expected KS distances of a design (typical sizes, for reports): the statistical resolution of
/// the pooled sample 0.87/sqrt(K M), and the quenched deviation of the pooled law c/sqrt(N K)
/// (0 for the sampled design, whose drops are iid).
struct DesignScales {
  double statistical = 0;  ///< 0.87/sqrt(K M): KS distance the pooled sample resolves
  double quenched = 0;     ///< c/sqrt(N K): KS distance of the pooled law from the ensemble law
};
/// The DesignScales of `drops` drops on `spheres` spheres of `asperities` asperities.
DesignScales design_scales(Mode mode, std::uint64_t asperities, std::uint64_t spheres, std::uint64_t drops);

/// A single impact per drop (paper Sec. IV): the body falls onto a horizontal plate (n = +z) with
/// V = (0, 0, -speed) and spin omega; the impulse is solved with the full rigid-body law.
/// Largest supported speed [m/s], for the approach speed and the spin's surface speed |Omega|(R+a):
/// a third of the speed of light, far beyond where a rigid impulse means anything, and small
/// enough that every velocity, impulse and eps stays finite.
inline constexpr double kMaxSpeed = 1e8;

/// The impact experiment of a sphere run (scene [experiment] kind = "impact"): one impact per drop.
struct ImpactExperiment {
  bool enabled = false;          ///< false: contact statistics only
  double speed = 1.3;            ///< u = -V.n > 0 [m/s]
  Vec3 omega{0.2, 0.0, 0.0};     ///< Omega before [rad/s]
  double density = 7850;         ///< [kg/m^3]; mass M = 4/3 pi R^3 density (eps does not depend on it)
  double beta = 0.0467;          ///< viscoelastic Pade [1/4] constant of Eq. 9 [(s/m)^(1/5)]
  double eps_t = 1.0;            ///< tangential restitution (paper: 1)
  /// The tangential law (core/tangential.hpp). kinematic (the default) uses eps_t above; coulomb and
  /// walton solve each impact with core/tangential solve_impact (sphere and mesh-body impacts and
  /// bounces; the paper's bounce procedure refuses them, scene.cpp validate).
  TangentialLaw tangential;

  /// Field by field.
  friend bool operator==(const ImpactExperiment&, const ImpactExperiment&) = default;
};

/// Most OpenMP threads accepted: libgomp crashes when asked for ~10^5 threads (found by the
/// stress suite), and more threads than any machine's cores only cost memory.
inline constexpr int kMaxThreads = 1024;

/// How a run keeps its per-drop values (report.json "statistics"): raw samples (exact KS, every
/// figure; ~60 B per drop) or streaming histograms (experiments/streaming.hpp; memory independent of
/// the number of drops, contact statistics only). automatic: streaming above kStreamingAutoDrops
/// drops when no impact experiment runs, raw samples otherwise.
enum class Statistics { automatic, raw, streaming };
/// "auto", "raw", "streaming".
std::string_view to_string(Statistics s);
/// Throws std::invalid_argument naming the value.
Statistics parse_statistics(std::string_view s);
/// Above this many drops an automatic run streams (raw samples would take ~2 GiB).
inline constexpr std::uint64_t kStreamingAutoDrops = std::uint64_t{1} << 25;
/// Most drops of a run that keeps raw samples, and most spheres, bounce sequences or table drops a
/// scene or the command line may ask for (per-item arrays are indexed and sized in 2^31).
inline constexpr std::uint64_t kMaxRawDrops = std::uint64_t{1} << 31;
/// Most drops of a streaming run (the counters are 64-bit; 2^50 is ~10^15). Beyond 2^31 drops only
/// when statistics = streaming was asked for (validate).
inline constexpr std::uint64_t kMaxStreamingDrops = std::uint64_t{1} << 50;

/// A sphere run's drops: the sphere, the design and its size, the seed, the query backend and the
/// impact experiment (validate checks every field).
struct EnsembleConfig {
  SphereParams sphere;                ///< N asperities, R, a
  Mode mode = Mode::explicit_spheres;  ///< explicit spheres or sampled from the exact law
  std::uint64_t drops = 1000000;  ///< total drops (explicit: spheres x rotations)
  std::uint64_t spheres = 1;      ///< K (explicit design); drops must be a multiple of K
  std::uint64_t seed = 1;           ///< every drop is a pure function of (seed, drop index)
  Backend backend = Backend::grid;  ///< explicit design only
  Kernel kernel = Kernel::simd;     ///< explicit design: which drop kernel instantiation (the same bits)
  int threads = 0;                  ///< 0 = OpenMP default, at most kMaxThreads
  ImpactExperiment impact;          ///< off: contact statistics only (nothing else is computed)
  Statistics statistics = Statistics::automatic;  ///< raw samples or streaming histograms
  unsigned bins_log2 = 16;          ///< streaming: 2^bins_log2 fine bins per quantity, in [10, 24]

  /// Field by field.
  friend bool operator==(const EnsembleConfig&, const EnsembleConfig&) = default;
};

/// Whether the run streams (Statistics): streaming, or automatic above kStreamingAutoDrops without impacts.
bool uses_streaming(const EnsembleConfig& c);

/// Throws std::invalid_argument naming the offending field.
void validate(const EnsembleConfig& c);

/// A deterministic subsample of an explicit run's queries answered again by other exact backends:
/// drops j (a multiple of a stride) of spheres 0, s, 2s, ... (as few as hold the quota: one when it
/// has enough rotations; s = K / their number), about 1 % of the drops, at least
/// 100 and at most 10^4, and fewer when the brute scans would cost more than ~5 % of the run
/// (queries x N <= kCrossCheckScanBudget; never fewer than 100). Backends: brute and kdtree (each
/// skipped when it is the run's own backend), fcl when built and N <= kCrossCheckFclMax (its
/// build is ~0.08 s at 10^5). A disagreement makes run_contact_ensemble throw std::runtime_error.
struct CrossCheck {
  std::uint64_t queries = 0;           ///< queries answered again
  std::uint64_t agreed = 0;            ///< of them, answered alike by every backend
  std::vector<std::string> backends;   ///< the backends that answered them again
  double seconds = 0;                  ///< wall time of the cross-check [s]
};
/// Brute-force work of the cross-check, queries x N: ~1.3 ns each, so ~26 ms.
inline constexpr double kCrossCheckScanBudget = 2e7;
/// Largest N at which fcl joins the cross-check (its index build grows with N).
inline constexpr std::uint64_t kCrossCheckFclMax = 20000;

/// Per-drop results, index = drop number (independent of thread count and schedule).
struct ContactSamples {
  Mode mode = Mode::explicit_spheres;  ///< the design that made the drops
  std::size_t batches = 0;          ///< explicit: K spheres; sampled: number of drops (iid)
  std::vector<double> r_x;          ///< lowest asperity's contact vector, world frame: x [m]
  std::vector<double> r_y;          ///< y [m]
  std::vector<double> r_z;          ///< z [m]
  std::vector<double> r_xy;         ///< its length in the plate's plane, hypot(r_x, r_y) [m]
  std::vector<double> gap;          ///< runner-up height gap [m] (+inf if N == 1)
  std::vector<std::uint8_t> core;   ///< 1 if the central sphere touches first
  std::uint64_t core_contacts = 0;  ///< drops where the central sphere touches first
  // Impact results (empty unless the experiment is enabled). The impulse uses the physical contact:
  // the lowest asperity's r, or the central sphere's pole (0, 0, -R) in a core contact.
  std::vector<double> eps;            ///< macroscopic restitution coefficient, Eq. 1
  std::vector<double> omega_x_after;  ///< Omega'_x [rad/s]
  std::vector<double> eps_n;          ///< microscopic eps_n at the contact's normal speed
  std::vector<std::uint8_t> eps_core; ///< 1 where that impact was a core contact (aligned with eps)
  std::uint64_t no_impacts = 0;       ///< drops whose contact point does not approach the plate (v_n >= 0):
                                      ///< counted here, absent from eps/omega_x_after/eps_n
  double seconds_generate = 0;      ///< wall time building the spheres [s]
  double seconds_index = 0;         ///< wall time building their spatial indices [s]
  double seconds_query = 0;         ///< wall time of the contact queries [s]
  double seconds_impact = 0;        ///< wall time of the impulse solves [s]
  std::size_t index_bytes = 0;      ///< memory of one spatial index (explicit design)
  CrossCheck cross_check;           ///< explicit design: queries answered again by other backends
};

/// Called now and then from the calling thread with (drops done, drops total).
using Progress = std::function<void(std::uint64_t, std::uint64_t)>;

/// Runs the drops of `c` on every OpenMP thread (results independent of their number); `progress`
/// is called from the calling thread. Throws std::invalid_argument for a bad config (validate) and
/// std::runtime_error when the cross-check finds a disagreement.
ContactSamples run_contact_ensemble(const EnsembleConfig& c, const Progress& progress = {});

/// The backends that re-answer the cross-checked queries of a run with backend `main` (CrossCheck).
std::vector<Backend> cross_check_backends(Backend main, std::uint64_t asperities);

/// The lowest two asperities of a fresh random sphere, exactly, in O(1): with
/// X_i = (1 - cos theta_i)/2 iid uniform on (0,1), the sorted X are generated in order by the
/// Renyi representation X_(1) = 1 - U_1^(1/N), X_(k+1) = X_(k) + (1 - X_(k)) (1 - U^(1/(N-k))),
/// with independent uniform azimuths. All other N - k centres are uniform on the rest of the
/// sphere (X > X_(k)) and cannot touch. Returns the cap's unit centres (down = -z).
std::vector<Vec3> fresh_cap(std::uint64_t n, std::uint64_t drop, std::uint64_t seed, unsigned k = 2);

}  // namespace asperity
