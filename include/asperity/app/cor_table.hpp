// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Restitution tables for DEM codes (docs/dem-tables.md): the distribution of the
// macroscopic restitution coefficient eps of the paper's rough sphere, as quantiles on a fine
// probability grid for each impact speed of a speed grid. A DEM contact model samples it with its
// own uniform u (include/asperity/cor_table.h: asperity_cor_sample, bilinear in speed and
// probability) once when a contact begins.
//
// Files: <name>.csv (format 1, read by cor_table.h) and <name>.json next to it (the header: N, R,
// a, material, seed, tool version, grids, and per speed the fitted Eq. 2 law, counts, mean, std).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/laplace.hpp"
#include "asperity/app/scene.hpp"

namespace asperity {

/// Format 1: eps quantiles per speed (no spins, no omega bands). Format 2: a spin grid and/or
/// Omega'_x quantiles per eps band (include/asperity/cor_table.h describes both).
inline constexpr int kCorTableFormatVersion = 1;
inline constexpr int kCorTableFormatVersionSpins = 2;

struct CorTableSpec {
  SphereParams sphere;           ///< N, R, a
  ImpactExperiment impact;       ///< material and spin (impact.speed is replaced by each grid speed)
  std::vector<double> speeds;    ///< impact speeds u = -V.n [m/s], strictly ascending, > 0
  std::size_t probabilities = 201;  ///< probability grid p_j = j / (probabilities - 1), j = 0..P-1; >= 2
  std::uint64_t drops = 100000;  ///< fresh spheres dropped per speed (>= 3)
  std::uint64_t seed = 1;
  int threads = 0;
  /// Incoming spins Omega = (spin, 0, 0) [rad/s], strictly ascending (about an axis in the plate's
  /// plane; by the sphere's symmetry any tangential spin is one of these turned). Empty: the
  /// scene's Omega only. Non-empty, or omega_bands > 0: format 2.
  std::vector<double> spins;
  /// Omega'_x quantiles for each of this many equiprobable bands of the eps law (joint draws:
  /// asperity_cor_sample_omega); 0: none. At most drops / 2 (two drops per band at least).
  std::size_t omega_bands = 0;
};

/// The sphere, material, spin and seed of a scene (body.kind = "sphere"); speeds: a geometric grid
/// of `speeds` points from u/10 to 10 u around the scene's impact speed u (overwrite as needed).
CorTableSpec cor_table_spec(const Scene& s, std::size_t speeds = 9);

/// The table a scene's outputs.cor_table asks for: cor_table_spec(s) with its speeds (if given),
/// probabilities and drops.
CorTableSpec cor_table_spec(const Scene& s, const CorTableScene& c);

/// What produced the table, for reports and headers: the ensemble and method, never "geometry".
inline constexpr const char* kCorTableEnsemble =
    "sampled from the exact finite-N law of the lowest asperity (no sphere is built)";

/// Throws std::invalid_argument naming the field and value.
void validate(const CorTableSpec& spec);

struct CorTableRow {
  double spin = 0;                 ///< incoming Omega_x [rad/s] (format 1: the scene's Omega_x)
  double speed = 0;                ///< [m/s]
  std::vector<double> quantiles;   ///< eps at each probability of the grid (type-7 sample quantiles)
  std::uint64_t samples = 0;       ///< impacts behind the row (drops - no_impacts)
  std::uint64_t core_contacts = 0;
  double mean = 0, std = 0;        ///< of eps
  double eps_n = 0;                ///< microscopic eps_n(u) of the material
  /// Omega'_x after the impact [rad/s]: quantiles on the same probability grid, mean and std. Its
  /// marginal law only (it is correlated with eps; the CSV and cor_table.h sample eps alone).
  std::vector<double> omega_x_quantiles;
  double omega_x_mean = 0, omega_x_std = 0;
  /// Format 2 with omega_bands > 0: Omega'_x quantiles (probability grid) of the drops whose eps
  /// rank falls in band b = [b/B, (b+1)/B).
  std::vector<std::vector<double>> omega_x_band_quantiles;
  LaplaceFit fit;                  ///< Eq. 2 fitted to the row's eps (maximum likelihood)
  bool fitted = false;             ///< false when the fit was impossible (e.g. all eps equal)
  std::string fit_note;            ///< why not, if !fitted
};

struct CorTable {
  CorTableSpec spec;
  std::vector<double> probabilities;  ///< the probability grid
  std::vector<CorTableRow> rows;      ///< one per (spin, speed), spin-major, both ascending
  int format() const { return spec.spins.empty() && spec.omega_bands == 0 ? kCorTableFormatVersion : kCorTableFormatVersionSpins; }
};

/// Drops spec.drops fresh rough spheres (run_contact_ensemble, the same streams for every speed and
/// spin) at each (spin, speed) and records the quantiles of eps. Progress counts drops over all.
CorTable make_cor_table(const CorTableSpec& spec, const Progress& progress = {});

/// The CSV text (docs/dem-tables.md): '#' comment lines, a header row
/// "speed_m_s,p=<p0>,p=<p1>,...", then one row per speed; numbers in their shortest round-trip form.
std::string cor_table_csv(const CorTable& t);
/// The JSON header text.
std::string cor_table_json(const CorTable& t);
/// Writes `csv` and the JSON header next to it (same stem, .json), each atomically; returns both paths.
std::vector<std::filesystem::path> write_cor_table(const std::filesystem::path& csv, const CorTable& t);

}  // namespace asperity
