#pragma once
// Ensembles of drops: many rough spheres meeting the plate, each contact found from explicit
// geometry. Two ensembles, named in every report:
//  - fresh: a new random sphere for every drop -- the ensemble the paper's Eqs. 13/14/18
//    describe. Costs O(1) per drop: only the asperities that can touch are generated (below).
//  - fixed: K explicit spheres x M random rotations each. Rotations of one sphere sample that
//    sphere's own (quenched) law, not the ensemble law: errors come from the spread between
//    spheres.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "asperity/core/contact.hpp"
#include "asperity/core/tangential.hpp"
#include "asperity/core/geometry.hpp"

namespace asperity {

enum class Mode { fresh, fixed };
std::string_view to_string(Mode m);
/// "fresh" or "fixed"; throws std::invalid_argument naming the value otherwise.
Mode parse_mode(std::string_view s);

/// A single impact per drop (paper Sec. IV): the body falls onto a horizontal plate (n = +z) with
/// V = (0, 0, -speed) and spin omega; the impulse is solved with the full rigid-body law.
/// Largest supported speed [m/s], for the approach speed and the spin's surface speed |Omega|(R+a):
/// a third of the speed of light, far beyond where a rigid impulse means anything, and small
/// enough that every velocity, impulse and eps stays finite.
inline constexpr double kMaxSpeed = 1e8;

struct ImpactExperiment {
  bool enabled = false;
  double speed = 1.3;            ///< u = -V.n > 0 [m/s]
  Vec3 omega{0.2, 0.0, 0.0};     ///< Omega before [rad/s]
  double density = 7850;         ///< [kg/m^3]; mass M = 4/3 pi R^3 density (eps does not depend on it)
  double beta = 0.0467;          ///< viscoelastic Pade [1/4] constant of Eq. 9 [(s/m)^(1/5)]
  double eps_t = 1.0;            ///< tangential restitution (paper: 1)
  /// The tangential law (core/tangential.hpp). kinematic (the default) uses eps_t above; coulomb and
  /// walton apply to mesh-body runs (single impacts and bounces); sphere runs refuse them for now.
  TangentialLaw tangential;

  friend bool operator==(const ImpactExperiment&, const ImpactExperiment&) = default;
};

/// Most OpenMP threads accepted: libgomp crashes when asked for ~10^5 threads (found by the
/// stress suite), and more threads than any machine's cores only cost memory.
inline constexpr int kMaxThreads = 1024;

struct EnsembleConfig {
  SphereParams sphere;
  Mode mode = Mode::fresh;
  std::uint64_t drops = 1000000;  ///< total drops (fixed: spheres x rotations)
  std::uint64_t spheres = 1;      ///< K (fixed mode); drops must be a multiple of K
  std::uint64_t seed = 1;
  Backend backend = Backend::grid;  ///< fixed mode only
  int threads = 0;                  ///< 0 = OpenMP default, at most kMaxThreads
  ImpactExperiment impact;          ///< off: contact statistics only (nothing else is computed)

  friend bool operator==(const EnsembleConfig&, const EnsembleConfig&) = default;
};

/// Throws std::invalid_argument naming the offending field.
void validate(const EnsembleConfig& c);

/// Per-drop results, index = drop number (independent of thread count and schedule).
struct ContactSamples {
  Mode mode = Mode::fresh;
  std::size_t batches = 0;          ///< fixed: K spheres; fresh: number of drops (iid)
  std::vector<double> r_x, r_y, r_z, r_xy;  ///< lowest asperity's contact vector, world frame [m]
  std::vector<double> gap;          ///< runner-up height gap [m] (+inf if N == 1)
  std::vector<std::uint8_t> core;   ///< 1 if the central sphere touches first
  std::uint64_t core_contacts = 0;
  // Impact results (empty unless the experiment is enabled). The impulse uses the physical contact:
  // the lowest asperity's r, or the central sphere's pole (0, 0, -R) in a core contact.
  std::vector<double> eps;            ///< macroscopic restitution coefficient, Eq. 1
  std::vector<double> omega_x_after;  ///< Omega'_x [rad/s]
  std::vector<double> eps_n;          ///< microscopic eps_n at the contact's normal speed
  std::vector<std::uint8_t> eps_core; ///< 1 where that impact was a core contact (aligned with eps)
  std::uint64_t no_impacts = 0;       ///< drops whose contact point does not approach the plate (v_n >= 0):
                                      ///< counted here, absent from eps/omega_x_after/eps_n
  double seconds_generate = 0, seconds_index = 0, seconds_query = 0, seconds_impact = 0;
  std::size_t index_bytes = 0;      ///< memory of one spatial index (fixed mode)
};

/// Called now and then from the calling thread with (drops done, drops total).
using Progress = std::function<void(std::uint64_t, std::uint64_t)>;

ContactSamples run_contact_ensemble(const EnsembleConfig& c, const Progress& progress = {});

/// The lowest two asperities of a fresh random sphere, exactly, in O(1): with
/// X_i = (1 - cos theta_i)/2 iid uniform on (0,1), the sorted X are generated in order by the
/// Renyi representation X_(1) = 1 - U_1^(1/N), X_(k+1) = X_(k) + (1 - X_(k)) (1 - U^(1/(N-k))),
/// with independent uniform azimuths. All other N - k centres are uniform on the rest of the
/// sphere (X > X_(k)) and cannot touch. Returns the cap's unit centres (down = -z).
std::vector<Vec3> fresh_cap(std::uint64_t n, std::uint64_t drop, std::uint64_t seed, unsigned k = 2);

}  // namespace asperity
