// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a run found, as a value: per-quantity summaries, one entry per (quantity, law) test with a
// verdict, core-contact counts and timings. Rendered as a table for people, as report.json for
// tools (a versioned contract, see README), and as PNG figures.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "asperity/experiments/ensemble.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/scene.hpp"
#include "asperity/laws/family.hpp"
#include "asperity/laws/statistics.hpp"
#include "asperity/laws/verdict.hpp"

namespace asperity {

inline constexpr int kReportSchemaVersion = 1;

struct QuantityReport {
  std::string name;  ///< "r_xy", "r_x", "r_y", "r_z" [m]; "eps" [1], "omega_x_after" [rad/s]
  Summary summary;   ///< SI units (metres)
};

/// One row of tests[]: a law against the sample of a quantity ("r_xy", ...; "core_contacts"), law
/// "eq14", "exact-sphere", "eq18", ... decisive: counts towards the exit status. verdict: accept,
/// reject, undecided (the bootstrap's smallest attainable p is not below alpha), not-decisive
/// (explicit with fewer than kMinDecisiveSpheres spheres, e.g. one sphere: its own law, p assumes
/// iid), skipped (the law could not be evaluated: D, p and predicted_mean NaN, the note says why).
struct TestReport : LawTest {
  std::string scope = "all";  ///< "all" (every drop)
  /// "KS" (iid drops: exact Kolmogorov p), "KS-sphere-bootstrap" (explicit: binned KS of all drops,
  /// p from a sphere-block bootstrap, laws/block_ks.hpp) or "binomial"
  std::string statistic;
  double D = 0;           ///< KS distance (NaN for a count test)
  double p = 1;
  std::uint64_t n = 0;
  double predicted_mean = 0;  ///< mean of the quantity under the law (NaN if not applicable)
  bool iid = true;            ///< whether the p-value's iid assumption holds for these samples
};

struct GeometryReport {
  Scene scene;
  std::uint64_t samples = 0;
  std::uint64_t core_contacts = 0;
  double core_probability = 0;        ///< exact, per drop
  double core_probability_paper = 0;  ///< the paper's R* estimate
  double gap_min = 0, gap_median = 0; ///< runner-up height gap [m]
  double quenched_scale = 0;          ///< max pointwise sd of one sphere's own cdf (explicit; quenched_deviation_scale)
  /// The ensemble design and its error budget (report.json `design`, the table's design lines).
  struct Design {
    std::string kind;                 ///< "explicit" (K spheres x M rotations, spatial query) or "sampled"
    std::uint64_t spheres = 0, rotations_per_sphere = 0;
    std::string backend;              ///< the query backend ("none" when sampled)
    double statistical_scale = 0;     ///< typical KS distance of the pooled sample, 0.87/sqrt(K M)
    double quenched_scale = 0;        ///< typical KS deviation of the pooled law, c/sqrt(N K) (0 sampled)
    double model_error_scale = 0;     ///< KS distance of Eq. 14 from the exact finite-N law
  } design;
  CrossCheck cross_check;             ///< queries re-answered by other backends (explicit)
  /// Which path kept the drops (report.json "statistics"): "raw samples, ..." or "streaming histogram, 2^k bins ..."
  std::string statistics;
  std::string ensemble_note;
  std::vector<QuantityReport> quantities;
  std::vector<TestReport> tests;
  std::vector<std::pair<std::string, double>> timings_s;
  std::vector<std::string> plots;     ///< file names written in the output directory
  std::size_t index_bytes = 0;
  // Impact experiments only:
  std::uint64_t no_impacts = 0;       ///< contacts that did not approach the plate
  double eps_n_mean = 0;              ///< mean microscopic eps_n
  Estimate eps_deficit;               ///< eps_n - <eps> with its standard error
  // Filled by run_scene (run.hpp):
  std::vector<PlanStage> plan;        ///< every stage, run or skipped with its reason, and its time
  std::string scene_toml;             ///< the scene that ran, as a scene file (to_toml)

  /// The family of decisive tests (laws/family.hpp: Holm at scene.alpha over the decided ones).
  FamilyDecision family() const;
  /// The family rejects: some decisive test is rejected by Holm's procedure (exit status 1).
  bool rejected() const;
  /// Decisive tests that could not be evaluated (verdict "skipped") or not decided at the largest
  /// bootstrap size (verdict "undecided").
  std::size_t skipped() const;
};

/// Summaries and tests of a run: the contact laws only if scene.contact_stats, the restitution laws
/// only if the samples hold impacts. Sorts copies of the samples; O(n log n).
GeometryReport analyse(const Scene& scene, const ContactSamples& s);

/// The human-readable table (quantity | measured +- se | law | KS D | p | verdict).
std::string format_table(const GeometryReport& r);

/// Serialised report.json text.
std::string to_json(const GeometryReport& r);

/// report.json "family" as JSON text: procedure, alpha, tests (m), rejected, min_adjusted_p and
/// adjusted_p by test name (names[i] for test i; a repeated name gets " #2", ...). Every kind of run.
std::string family_json(const FamilyDecision& f, const std::vector<std::string>& names);

/// The fields every report.json has, whatever kind of run wrote it (docs/report-json.md).
struct ReportHeader {
  std::string tool = "validate-geometry";
  std::string scene;                    ///< scene name ("+custom" when the command line overrode it)
  std::string scene_toml;               ///< the effective scene as a scene file (to_toml); empty: omitted
  std::vector<PlanStage> plan;          ///< empty: omitted
  std::vector<std::pair<std::string, double>> timings_s;  ///< wall seconds per stage; empty: omitted
  /// Further top-level objects (name, JSON text), e.g. "cor_table" for outputs.cor_table.
  std::vector<std::pair<std::string, std::string>> sections;
};

/// `body` (a JSON object, as the to_json functions return it) with the header fields set:
/// schema_version, tool, scene, and scene_file, plan, timings_s when the header has them.
/// Fields of `body` are kept, except that the header's values win for these names.
std::string with_header(const std::string& body, const ReportHeader& h);

/// The one writer of a run's report files: `dir / report_name` (the JSON text) and, next to it,
/// the table as `<stem>.txt`, each atomically. If either cannot be written, neither is left
/// behind; throws std::runtime_error naming the file. Returns the paths written.
std::vector<std::filesystem::path> write_report_files(const std::filesystem::path& dir, const std::string& report_name,
                                                      const std::string& json, const std::string& table);

/// Writes the PNG figures of r_xy, r_x, r_y against their laws into `dir`; returns file names.
std::vector<std::string> write_plots(const std::filesystem::path& dir, const Scene& scene, const ContactSamples& s);

}  // namespace asperity
