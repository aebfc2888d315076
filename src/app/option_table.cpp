// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/option_table.hpp"

#include <array>
#include <cctype>
#include <stdexcept>
#include <string>

#include "asperity/core/geometry.hpp"
#include "asperity/experiments/ensemble.hpp"

namespace asperity {

namespace {

constexpr std::uint64_t kMaxSeed = ~std::uint64_t{0};
constexpr std::uint64_t kMaxThreadCount = static_cast<std::uint64_t>(kMaxThreads);

// clang-format off
constexpr std::array kRows = {
  OptionRow{"--preset", "the scene", "NAME", "fig3 (default), fig3-fixed, fig4, fig5, fig6", "scene preset", true},
  OptionRow{"--scene", "the scene", "FILE", "", "scene file (TOML, see docs/scenes.md); the options below override it", true},
  OptionRow{"--asperities,-N", "asperities.count", "COUNT", "", "number of asperities N", true, 1, kMaxAsperities},
  OptionRow{"--radius", "body.radius", "METRES", "> 0", "central sphere radius R", true},
  OptionRow{"--asperity-radius", "asperities.radius", "METRES", "0 < a < R",
            "asperity radius a (every asperity: the radii become \"fixed\")", true},
  OptionRow{"--drops", "ensemble.drops", "COUNT", "",
            "number of drops (explicit: spheres x rotations; raw statistics up to 2^31)", true, 2, kMaxStreamingDrops},
  OptionRow{"--mode", "ensemble.mode", "NAME", "explicit, sampled",
            "explicit (default: K explicit spheres x M rotations, contacts by spatial query) or sampled (drawn from the "
            "exact finite-N law of the lowest asperity; no geometry); fixed and fresh are read as explicit", true},
  OptionRow{"--spheres,-K", "ensemble.spheres", "COUNT", "",
            "number of explicit spheres K (explicit design; default: from the error budget)", true, 1, kMaxRawDrops},
  OptionRow{"--seed", "ensemble.seed", "COUNT", "", "random seed (results are identical for any thread count)", true, 0,
            kMaxSeed},
  OptionRow{"--backend", "ensemble.backend", "NAME", "brute, kdtree, cgal, fcl, grid", "contact query (explicit design)",
            true},
  OptionRow{"--threads", "ensemble.threads", "COUNT", "", "OpenMP threads (0 = all)", false, 0, kMaxThreadCount},
  OptionRow{"--kernel", "ensemble.kernel", "NAME", "simd, scalar",
            "drop kernel of the explicit drops: simd (default) or scalar (the reference; the same bits)", false},
  OptionRow{"--statistics", "ensemble.statistics", "NAME", "auto, raw, streaming",
            "auto (default: streaming above 2^25 drops without impacts), raw (every drop kept: exact KS, figures of "
            "every quantity) or streaming (integer histograms, memory independent of the drops; contact only)", true},
  OptionRow{"--bins-log2", "ensemble.bins_log2", "COUNT", "", "streaming: 2^k fine bins per quantity (default 16)",
            true, 10, 24},
  OptionRow{"--checkpoint-every", "run control", "SECONDS", ">= 0",
            "streaming: seconds between checkpoints in --out (default 300; 0: only on SIGINT/SIGTERM)", false},
  OptionRow{"--resume", "run control", "DIR", "",
            "continue the interrupted streaming run whose checkpoint is in DIR (its scene)", false},
  OptionRow{"--alpha", "outputs.alpha", "REAL", "(0, 1)",
            "significance level of each test and of the run's family of decisive tests (Holm)", true},
  OptionRow{"--out", "outputs.dir", "DIR", "", "output directory for report.json and figures", true},
  OptionRow{"--speed", "experiment.kind, experiment.V (bounce: experiment.speed)", "M/S", "> 0",
            "impact: approach speed -V.n (enables the impact stage)", true},
  OptionRow{"--omega-x", "experiment.Omega", "RAD/S", "finite", "impact: spin Omega_x before", true},
  OptionRow{"--omega-y", "experiment.Omega", "RAD/S", "finite", "impact: spin Omega_y before", true},
  OptionRow{"--variant", "experiment.variants", "LIST",
            "comma list of paper, paper-printed33, paper-corrected28, random-orientation, dynamic",
            "bounce runs (fig6): the variants compared", true},
  OptionRow{"--sequences", "experiment.sequences", "COUNT", "", "bounce runs (fig6): bounce sequences per variant", true,
            1, kMaxRawDrops},
  OptionRow{"--tangential", "material.tangential", "LAW",
            "kinematic[:eps_t=E], coulomb:mu=M,restitution=newton|poisson|energetic, stronge:mu=M, walton:mu=M,beta0=B",
            "tangential law of the impacts (sphere impacts, the explicit bounce variants, mesh bodies)", true},
  OptionRow{"--no-plots", "outputs.plots", "", "", "do not write figures (nor their data, CSV)", false},
  OptionRow{"--plot-format", "outputs.plot_format", "FORMAT", "png, svg, pdf, png+svg, png+pdf; @S for S times the size",
            "figures as png (default), svg or pdf, e.g. png@2; CSV always", false},
  OptionRow{"--quiet,-q", "run control", "", "", "print no progress", false},
};
// clang-format on

// The power of two a limit is, for the range text ("2^50", "2^32 - 1").
std::string bound_text(std::uint64_t v) {
  if (v == ~std::uint64_t{0}) return "2^64 - 1";
  for (int k = 16; k < 64; ++k) {
    const std::uint64_t p = std::uint64_t{1} << k;
    if (v == p) return "2^" + std::to_string(k);
    if (v == p - 1) return "2^" + std::to_string(k) + " - 1";
  }
  return std::to_string(v);
}

}  // namespace

std::span<const OptionRow> option_rows() { return kRows; }

std::string_view long_flag(const OptionRow& row) { return row.flag.substr(0, row.flag.find(',')); }

const OptionRow& option_row(std::string_view flag) {
  for (const OptionRow& r : kRows)
    if (long_flag(r) == flag) return r;
  throw std::out_of_range("no option " + std::string(flag));
}

std::string type_text(const OptionRow& row) {
  std::string range(row.range);
  if (row.type == "COUNT") range = "[" + std::to_string(row.lo) + ", " + bound_text(row.hi) + "]";
  if (range.empty()) return std::string(row.type);
  const char* joint = range[0] == '[' || range[0] == '(' ? " in " : std::isalpha(static_cast<unsigned char>(range[0])) ? ": " : " ";
  return std::string(row.type) + joint + range;
}

}  // namespace asperity
