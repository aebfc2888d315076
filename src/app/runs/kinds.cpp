// SPDX-License-Identifier: GPL-3.0-or-later
// The table of run kinds (kinds.hpp) and what their files share.
#include "app/runs/kinds.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <array>

#include "asperity/app/scene_file.hpp"

namespace asperity {

namespace runs {

namespace {

// Recognition order: a bounce of a mesh body before a mesh body's impacts or a sphere's bounce;
// the paper's sphere (the default) last.
constexpr std::array<const Kind*, 5> kTable = {&kMeshBounce, &kBounce, &kMesh, &kRadii, &kSphere};

}  // namespace

std::span<const Kind* const> kinds() { return kTable; }

const Kind& kind(RunKind k) {
  for (const Kind* row : kTable)
    if (row->kind == k) return *row;
  return kSphere;  // unreachable: kTable has a row for each of the five RunKind values
}

PlanStage stage(std::string name, bool run, std::string reason, double seconds) {
  return {std::move(name), run, std::move(reason), run ? seconds : 0.0};
}

PlanStage plots_stage(const Scene& s, double seconds) {
  return stage("plots", s.plots, s.plots ? "outputs.plots" : "plots = false / --no-plots", seconds);
}

ReportHeader header_of(const Scene& s, std::vector<PlanStage> stages) {
  ReportHeader h;
  h.scene = s.name;
  h.scene_toml = to_toml(s);
  for (const auto& st : stages)
    if (st.run) h.timings_s.emplace_back(st.name, st.seconds);
  h.plan = std::move(stages);
  return h;
}

std::vector<std::string> skipped_of(const std::vector<LawCheck>& tests) {
  std::vector<std::string> out;
  for (const auto& t : tests)
    if (unresolved(t)) out.push_back(t.quantity + " " + t.law + ": " + t.note);
  return out;
}

std::string fmt3(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

std::string gb(double bytes) { return fmt3(bytes / 1e9) + " GB"; }

int threads_of(const Scene& s) {
  if (s.ensemble.threads > 0) return s.ensemble.threads;
#ifdef _OPENMP
  return std::max(1, omp_get_max_threads());
#else
  return 1;
#endif
}

}  // namespace runs

RunKind run_kind(const Scene& s) {
  for (const runs::Kind* row : runs::kinds())
    if (row->recognise(s)) return row->kind;
  return RunKind::sphere;
}

std::string_view to_string(RunKind k) { return runs::kind(k).name; }

}  // namespace asperity
