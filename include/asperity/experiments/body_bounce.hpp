// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Bounce sequences of general rough bodies (body.hpp: mesh bodies, spheres with fixed or unequal
// radii): the body is dropped on the plate and left to bounce. Between impacts the centre of mass
// flies ballistically under gravity and the orientation follows the torque-free rotation of the
// asymmetric top (free_rotation.hpp); every impact is the general 3x3 impulse (body_impact.hpp)
// at the asperity the exact support query (support.hpp) puts lowest.
//
// The landing. With z(t) the centre height and D(q) = support(body_down(q)).h the depth of the
// lowest point below the centre, the next impact is the FIRST t > 0 with gap f(t) = z(t) - D(q(t))
// = 0. For a non-sphere D changes by millimetres within one flight, so the landing is found by
// conservative advancement: at time t the support query gives the lowest asperity i (gap f) and
// the runner-up (gap f2 >= f). Every other asperity j has gap g_j(t + s) >= f2 + (v_z - w) s - g s^2/2
// (w = Omega_max max_j |c_j| bounds how fast any asperity centre can move down relative to the
// centre of mass; Omega_max = sqrt(2 T / J_min) bounds |Omega| over the whole flight because T is
// constant), and asperity i has g_i(t + s) >= f + g_i'(t) s - (g + a_i) s^2/2 (g_i' its exact normal
// contact velocity, a_i = |c_i| Omega_max^2 (1 + J_max/J_min) bounds the acceleration of its centre
// relative to the centre of mass, from Euler's equations). The step is the smaller first positive
// root of the two bounds, so no contact can be stepped over; because the bound of the lowest
// asperity is second order with the exact slope, the steps converge like Newton's near the landing.
// At lift-off (t = 0, f = 0) the same rule applies: the contact asperity separates (g_i' > 0) and
// the step is the time it surely stays clear; a second asperity that is about to touch (rocking,
// chatter) is found as soon as it does. The result is a lower bound t on the landing time with
// t* - t <= time_tolerance (to first order).
//
// Stop rule (checked before every impact, each reason counted): (1) total time > max_time; (2) the
// lowest asperity does not approach the plate (no impact: a grazing landing); (3) its normal
// approach speed -v_n = -(V + Omega x r)_z < stop_speed: the fig6 rule (bounce.hpp stops at
// u = -V_z < stop_speed) measured where the contact law acts. For the sphere the two agree to
// |Omega| r_xy ~ 1e-4 m/s, so impacts per sequence compare; for a non-sphere the centre speed is
// no measure of the impact: a rocking contact can have the centre RISING (u <= 0) while the
// contact point strikes hard, and a u rule would end most rounded-cube sequences there (measured:
// 13 of 20). (4) max_impacts reached; (5) a landing search needing more than max_steps support
// queries (a safety net). Chatter (many short flights) cannot run forever: (1) and (4) bound it;
// the fraction of flights < 1 ms is reported.
// Frames and units: world z up, plate normal +z, q body -> world, SI (m, s, kg, rad/s, J).
// Randomness: sequence s uses body s mod K and the initial Haar orientation from
// Stream(seed, Purpose::bounce, s, kBodyBounceSub); nothing else is random, so results are
// bit-identical for any thread count.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "asperity/core/body.hpp"
#include "asperity/experiments/bounce.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/core/free_rotation.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/core/support.hpp"
#include "asperity/laws/figure.hpp"

namespace asperity {

/// Sub-stream of Stream(seed, Purpose::bounce, s, .) for a body sequence's initial orientation
/// (src/bounce.cpp uses 0, 1..max_impacts and 2^40).
inline constexpr std::uint64_t kBodyBounceSub = std::uint64_t{1} << 41;

/// Options of the landing search.
struct LandingOptions {
  double time_tolerance = 1e-12;    ///< [s]
  unsigned max_steps = 1000000;     ///< support queries per flight before giving up
  /// 1: the rigorous bound. Tests only: 0 omits the rotation terms (w, a_i), a deliberately
  /// too-optimistic bound that steps over contacts.
  double rotation_bound_scale = 1.0;
};

/// The flight state right after an impact (t = 0) or a drop.
struct FlightStart {
  double z = 0;       ///< centre height above the plate [m]
  double vz = 0;      ///< vertical centre velocity [m/s]
  double gravity = 9.81;  ///< [m/s^2]
};

/// The result of next_landing: when and how the flying body first touches the plate.
struct Landing {
  bool found = false;     ///< false: max_steps reached
  double time = 0;        ///< [s], lower bound within time_tolerance
  RotationState rotation; ///< q and Omega at `time`
  double z = 0;           ///< centre height at `time` [m]
  double vz = 0;          ///< vertical centre velocity at `time` [m/s]
  Support support;        ///< at body_down(rotation.q)
  double gap = 0;         ///< z - support.h [m] (>= 0 up to rounding)
  std::uint32_t queries = 0;  ///< support queries spent
};

/// Precomputed bounds of one body: max |c_i| and the extreme principal moments.
struct BodyBounds {
  double c_max = 0;          ///< max_i |c_i| [m]
  double j_min = 0;          ///< smallest principal moment [kg m^2]
  double j_max = 0;          ///< largest principal moment [kg m^2]
  /// The bounds of body b.
  static BodyBounds of(const RoughBody& b);
};

/// The first landing t > 0 of body b (index over it) flying from `start` while rotating freely as `rot`.
Landing next_landing(const RoughBody& b, const BodyBounds& bb, const SupportQuery& index, const FreeRotation& rot,
                     const FlightStart& start, const LandingOptions& o = {});

/// Total mechanical energy M |V|^2/2 + Omega . J_world Omega/2 + M g z [J].
double body_energy(const RoughBody& b, const Rotation& q, const Vec3& V, const Vec3& Omega, double z, double g);

/// A bounce run of rough bodies (run_body_bounces): the experiment, the tangential law, the time
/// limit per sequence and the landing search.
struct BodyBounceOptions {
  /// sequences, speed, omega (spin at the first impact), stop_speed, gravity, beta, eps_t,
  /// max_impacts, windows, impact_numbers, bootstrap. density is unused (the bodies carry their
  /// mass); variants must be {dynamic} (the orientation carried by the free rotation: the only
  /// meaning bounce variants have for a body).
  BounceExperiment bounce;
  /// The tangential law of every impact (core/tangential.hpp); kinematic uses bounce.eps_t.
  TangentialLaw tangential;
  double max_time = 60;    ///< total time per sequence [s]
  LandingOptions landing;  ///< the landing search of every flight
};
/// Throws std::invalid_argument naming the field and value.
void validate(const BodyBounceOptions& o);

/// Why sequences ended.
struct BodyBounceStops {
  std::uint64_t slow = 0;         ///< normal approach speed of the contact point < stop_speed
  std::uint64_t no_approach = 0;  ///< the lowest asperity does not approach the plate
  std::uint64_t max_impacts = 0;  ///< BounceExperiment::max_impacts reached
  std::uint64_t max_time = 0;     ///< BodyBounceOptions::max_time reached
  std::uint64_t max_steps = 0;    ///< a landing search gave up (LandingOptions::max_steps)
};

/// Every impact of every sequence, in sequence then impact order.
struct BodyBounceSamples {
  BounceSamples base;                 ///< sequence, k, u, eps (Eq. 1), eps_time, |Omega| before, Omega'_x
  std::vector<Vec3> r;                ///< contact vector, world frame [m]
  std::vector<Vec3> omega_after;      ///< Omega', world frame [rad/s]
  std::vector<double> energy_before;  ///< total energy before the impact (potential from the plate) [J]
  std::vector<double> energy_after;   ///< total energy after the impact [J]
  std::vector<double> rot_energy_after;    ///< rotational energy after [J]
  std::vector<double> trans_energy_after;  ///< translational energy after [J]
  std::vector<double> contact_speed;  ///< -v_n: normal approach speed of the contact point [m/s]
  std::vector<double> work;           ///< P . (v + v')/2 of the contact point velocities [J]
  std::vector<double> flight;         ///< flight time after the impact (NaN after the last) [s]
  std::vector<std::uint32_t> queries; ///< support queries of that flight
  std::vector<double> first_energy;   ///< per sequence: total energy at the first impact [J]
  BodyBounceStops stops;     ///< why the sequences ended
  std::uint64_t flights = 0;          ///< flights searched for a landing
  std::uint64_t support_queries = 0;  ///< support queries over all flights
  double seconds = 0;        ///< the sequences (wall)
  double seconds_index = 0;  ///< building the K support trees (wall)
};

/// Runs o.bounce.sequences sequences over `bodies` (sequence s uses bodies[s % K]); each body's
/// support tree is built once and shared by all threads. threads = 0: OpenMP default.
/// `progress` (optional) is called between chunks with (sequences done, total).
BodyBounceSamples run_body_bounces(std::span<const RoughBody> bodies, const BodyBounceOptions& o, std::uint64_t seed,
                                   int threads = 0,
                                   const Progress& progress = {});

/// eps and spin in one impact-speed bin.
struct SpeedBin {
  double lo = 0;                    ///< lower end of the u range [m/s]
  double hi = 0;                    ///< upper end of the u range [m/s]
  std::size_t n = 0;                ///< impacts in the bin
  Estimate eps;                     ///< mean eps with iid se
  double eps_q10 = 0;               ///< 10% quantile of eps
  double eps_q90 = 0;               ///< 90% quantile of eps
  double spin_mean = 0;             ///< mean |Omega| before [rad/s]
};

/// analyse_bounces (bounce.hpp: speed windows, impact numbers, Eq. 2 fits) plus what only bodies have.
struct BodyBounceReport {
  std::vector<SpeedBin> by_speed;   ///< 18 equal bins over [stop_speed, speed]
  BounceVariantReport base;         ///< analyse_bounces of the body impacts
  BodyBounceStops stops;            ///< why the sequences ended
  double impacts_per_sequence_sd = 0;  ///< standard deviation of the impacts per sequence
  std::uint32_t impacts_max = 0;       ///< most impacts of a sequence
  double queries_per_flight = 0;      ///< mean support queries per flight
  double eps_below_0 = 0;             ///< fraction of impacts with eps < 0
  double eps_above_1 = 0;             ///< fraction of impacts with eps > 1
  double rising_fraction = 0;         ///< fraction of impacts with the centre rising (u <= 0)
  double rot_fraction_last = 0;       ///< mean rotational / kinetic energy after the last impact
  double work_identity_max = 0;       ///< max |dE - P.(v+v')/2| / E before, over impacts
  double flight_energy_max = 0;       ///< max |E before k+1 - E after k| / E, over flights
  double short_flights = 0;           ///< fraction of flights shorter than 1 ms (chatter)
  /// Fraction of impacts whose kinetic energy INCREASES, and the largest gain / E before: eps_t = 1
  /// keeps v_t, which takes a tangential impulse whose work has either sign off-centre.
  double energy_gain_fraction = 0;
  double energy_gain_max = 0;         ///< the largest gain / E before (above)
};
/// The analysis of `s` (analyse_bounces with b's groups and bootstrap, seeded by `seed`) and the
/// body-only measures of BodyBounceReport.
BodyBounceReport analyse_body_bounces(const BodyBounceSamples& s, const BounceExperiment& b, std::uint64_t seed);

}  // namespace asperity

namespace asperity {

/// A bounce run as the CLI makes it: K rough bodies from a mesh (mesh.hpp, like run_mesh_impacts)
/// or, with `mesh` empty, rough spheres of radius `sphere_radius` (make_rough_sphere_body: the
/// same engine on the paper's body, for comparison), then run_body_bounces and the analysis.
/// Builds the per-speed-window figures when asked (figures as data; app/ writes them).
struct MeshBounceExperiment {
  std::filesystem::path mesh = "meshes/ellipsoid.off";  ///< the mesh file (OFF or PLY); empty: spheres
  double scale = 1.0;                    ///< mesh coordinates -> metres
  std::vector<double> smooth;            ///< {a, b, c[, m]} [m]: centres mapped onto that (super)ellipsoid
  double sphere_radius = 3e-3;           ///< mesh empty: R [m]
  std::uint64_t asperities = 100000;     ///< N per body
  RadiusDistribution radii = RadiusDistribution::fixed(6.5e-7);  ///< the asperities' radii [m]
  double density = 7850;                 ///< [kg/m^3]
  std::uint64_t bodies = 4;              ///< K explicit bodies
  std::uint64_t seed = 1;                ///< every body and sequence is a pure function of (seed, index)
  int threads = 0;                       ///< 0 = OpenMP default
  BodyBounceOptions options;             ///< options.bounce.density is ignored (density above)
  bool plots = true;  ///< build the figures (MeshBounceReport::figures)
};
/// Throws std::invalid_argument naming the field and value.
void validate(const MeshBounceExperiment& e);

/// What run_mesh_bounces measured: the body, the analysis and the figures.
struct MeshBounceReport {
  MeshBounceExperiment experiment;       ///< the experiment run
  std::string body_name;                 ///< the mesh file's stem, or "sphere"
  double mass = 0;                       ///< [kg]
  Vec3 principal_moments{0, 0, 0};       ///< [kg m^2], ascending
  double c_max = 0;                      ///< max |c_i| over the bodies [m]
  BodyBounceReport report;               ///< analyse_body_bounces of the sequences
  std::vector<NamedFigure> figures;  ///< eps per speed window; built when experiment.plots
  std::vector<std::string> plots;    ///< file names written (filled by app/)
  /// bodies, support trees, sequences, analysis, figures (wall)
  double seconds_build = 0;
  double seconds_index = 0;     ///< building the support trees (wall) [s]
  double seconds_run = 0;       ///< the sequences (wall) [s]
  double seconds_analysis = 0;  ///< the analysis (wall) [s]
  double seconds_plots = 0;     ///< the figures (wall) [s]
};

/// `base`: the mesh of e.mesh (read by the caller, app/mesh_io.hpp); null when e.mesh is empty
/// (spheres). progress: (sequences done, total), between chunks of sequences.
MeshBounceReport run_mesh_bounces(const MeshBounceExperiment& e, const TriangleMesh* base, const Progress& progress = {});
/// "<body>, N = ..., ... sequences": the subtitle of a mesh-bounce run's figures (figure markup, the
/// body name escaped: laws/figure.hpp).
std::string mesh_bounce_subtitle(const MeshBounceReport& r);

}  // namespace asperity
