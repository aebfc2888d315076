// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/app/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "app/io/output_staging.hpp"
#include "asperity/app/scene_file.hpp"
#include "core/format.hpp"
#include "app/io/text_escape.hpp"
#include "asperity_embedded_scenes.hpp"  // generated from scenes/*.toml (CMakeLists.txt)

namespace asperity {

std::vector<std::string> preset_names() {
  std::vector<std::string> names;
  for (const auto& s : embedded::kScenes) names.emplace_back(s.name);
  return names;
}

std::string_view preset_text(std::string_view name) {
  for (const auto& s : embedded::kScenes)
    if (s.name == name) return s.text;
  std::string known;
  for (const auto& p : preset_names()) known += (known.empty() ? "" : ", ") + p;
  throw std::invalid_argument("unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

Scene preset(std::string_view name) { return preset(name, {}); }

Scene preset(std::string_view name, const std::vector<SceneEdit>& edits) {
  return parse_scene(preset_text(name), "preset " + std::string(name) + " (scenes/" + std::string(name) + ".toml)", edits);
}

namespace {

// Figures are written as *.png, *.svg or *.pdf with their data as *.csv (app/plot.hpp).
bool ends_with_png(const std::string& name) {
  if (name.size() < 4) return false;
  std::string ext = name.substr(name.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png" || ext == ".svg" || ext == ".pdf" || ext == ".csv";
}

// A name for a message: control characters (a NUL, a newline) shown as \xNN.
std::string printable(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::string report_table_name(const std::string& report) {
  std::filesystem::path txt = report;
  txt.replace_extension(".txt");
  if (txt == std::filesystem::path(report)) txt += ".txt";  // a report named "x.txt" keeps its table apart
  return txt.string();
}

std::string file_output_key(const Scene& s) {
  if (s.cor_table) return "outputs.cor_table";
  if (s.mesh && !s.mesh->export_ply.empty()) return "outputs.export_ply";
  return {};
}

std::string cor_table_header_name(const std::string& csv) {
  return std::filesystem::path(csv).replace_extension(".json").string();
}

namespace {

// The table's own limits are checked where it is built (validate(CorTableSpec)); here: what the
// scene decides -- which runs may write one, and names that collide with no other output.
void validate_cor_table(const Scene& s) {
  const CorTableScene& c = *s.cor_table;
  const std::string key = "outputs.cor_table";
  if (s.mesh || s.radii || s.bounce.enabled || !s.ensemble.impact.enabled)
    throw std::invalid_argument(key + ": only for a sphere impact scene (body.kind = \"sphere\", experiment.kind = "
                                "\"impact\", one asperity radius)");
  if (const std::string why = output_name_problem(c.file); !why.empty())
    throw std::invalid_argument(key + ".file: \"" + printable(c.file) + "\" " + why);
  if (std::filesystem::path(c.file).extension() != ".csv")
    throw std::invalid_argument(key + ".file: \"" + c.file + "\" must end in .csv (its header is written as .json)");
  const std::string header = cor_table_header_name(c.file);
  for (const std::string& taken : {s.report, report_table_name(s.report)})
    if (c.file == taken || header == taken)
      throw std::invalid_argument(key + ".file: \"" + c.file + "\" and its header \"" + header +
                                  "\" must differ from the report and its table (\"" + taken + "\")");
}

// Output names: plain file names, none the same as another output of the run (the figures are
// *.png; the table is the report's name with .txt).
void validate_outputs(const Scene& s) {
  if (const std::string why = output_name_problem(s.report); !why.empty())
    throw std::invalid_argument("outputs.report: \"" + printable(s.report) + "\" " + why);
  const std::string table = report_table_name(s.report);
  if (ends_with_png(s.report))
    throw std::invalid_argument("outputs.report: \"" + s.report + "\" would collide with the figures (*.png, *.svg, *.pdf, *.csv)");
  if (s.mesh && !s.mesh->export_ply.empty()) {
    const std::string& ply = s.mesh->export_ply;
    if (const std::string why = output_name_problem(ply); !why.empty())
      throw std::invalid_argument("outputs.export_ply: \"" + printable(ply) + "\" " + why);
    if (ply == s.report || ply == table)
      throw std::invalid_argument("outputs.export_ply: \"" + ply + "\" is also the name of the report" +
                                  (ply == table ? "'s table (" + s.report + " -> " + table + ")" : std::string()));
    if (ends_with_png(ply))
      throw std::invalid_argument("outputs.export_ply: \"" + ply + "\" would collide with the figures (*.png, *.svg, *.pdf, *.csv)");
  }
  if (s.cor_table) validate_cor_table(s);
}

// Every name that report.json (JSON) and checkpoint.toml (TOML) hold as text: both hold UTF-8
// only, so a name with another byte (a POSIX path may hold any) is refused here, before the run;
// it was a JSON library's message after the whole run (issue 33 item 7), and a checkpoint that
// could not be resumed. UTF-8 names round-trip (to_toml writes them as \u escapes).
void validate_text_names(const Scene& s) {
  const auto check = [](const std::string& key, const std::string& v) {
    if (const std::string why = detail::utf8_problem(v); !why.empty())
      throw std::invalid_argument(key + ": \"" + detail::escaped(v) + "\": " + why +
                                  " (report.json and checkpoint.toml hold it as UTF-8 text); choose a UTF-8 name");
  };
  check("outputs.dir (--out)", s.out.string());
  check("outputs.report", s.report);
  check("name", s.name);
  if (s.mesh) check("body.mesh", s.mesh->file.string()), check("outputs.export_ply", s.mesh->export_ply);
  if (s.cor_table) check("outputs.cor_table.file", s.cor_table->file);
}

void validate_bounce(const Scene& s) {
  if (s.bounce.enabled) {
    validate(s.bounce);
    for (std::size_t i = 0; i < s.bounce.variants.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (s.bounce.variants[i] == s.bounce.variants[j])
          throw std::invalid_argument("experiment.variants: \"" + std::string(to_string(s.bounce.variants[i])) +
                                      "\" is given twice (a variant compared with itself decides nothing)");
  }
  // A tangential law other than the kinematic one acts in solved impacts: mesh bodies, sphere
  // impacts and the sphere's explicit bounce variants; the paper's procedure is its kinematic law.
  if (const auto& law = s.ensemble.impact.tangential; law.model != TangentialLaw::Model::kinematic) {
    if (!s.mesh && !s.ensemble.impact.enabled && !s.bounce.enabled)
      throw std::invalid_argument("material.tangential.model: " + law.describe() +
                                  " needs impacts (an impact or bounce experiment); this run only finds contacts");
    if (s.bounce.enabled && !s.mesh)
      for (auto v : s.bounce.variants)
        if (v != BounceVariant::random_orientation && v != BounceVariant::dynamic)
          throw std::invalid_argument("material.tangential.model: " + law.describe() +
                                      " applies to the explicit variants (random-orientation, dynamic); experiment.variants has \"" +
                                      std::string(to_string(v)) + "\", the paper's procedure with its kinematic law");
  }
  if (s.bounce.enabled && !s.mesh && s.bounce.omega != Vec3::Zero())
    throw std::invalid_argument("bounce: Omega is for mesh bodies; the sphere's variants start without spin (Sec. V)");
}

// A mesh body: explicit bodies x rotations, single impacts or bounce sequences.
void validate_mesh_run(const Scene& s) {
  if (s.mesh->file.empty()) throw std::invalid_argument("mesh file must not be empty");
  if (s.ensemble.mode != Mode::explicit_spheres)
    throw std::invalid_argument("ensemble.mode: a mesh body needs mode = \"explicit\" (ensemble.spheres explicit bodies x "
                                "rotations), got \"" + std::string(to_string(s.ensemble.mode)) + "\"");
  if (s.ensemble.impact.enabled == s.bounce.enabled)
    throw std::invalid_argument("experiment.kind: a mesh body needs kind = \"impact\" (with V and Omega) or \"bounce\"");
  if (s.bounce.enabled && s.bounce.variants != std::vector<BounceVariant>{BounceVariant::dynamic})
    throw std::invalid_argument("experiment.variants: a mesh body bounces with its orientation carried by the free "
                                "rotation: only \"dynamic\"");
  // Standard errors between bodies (batch means) need two rotations of each: refused before
  // the run, not found after it.
  const auto K = s.ensemble.spheres, n = s.ensemble.drops;
  if (s.ensemble.impact.enabled && K >= 2 && n / K < 2)
    throw std::invalid_argument("ensemble.drops (--drops): " + std::to_string(n) + " drops over ensemble.spheres = " +
                                std::to_string(K) + " bodies is " + std::to_string(n / K) +
                                " rotation per body; the standard errors between bodies need at least 2 (drops >= " +
                                std::to_string(2 * K) + ", or fewer --spheres)");
}

// Unequal radii on a sphere: their exact sampler, contacts only.
void validate_radii_run(const Scene& s) {
  // As the scene file checks it, also after --radius: every level (the lognormal median) below R.
  const auto& d = s.radii->radii;
  const double R = s.ensemble.sphere.radius;
  const double top = d.kind == RadiusDistribution::Kind::levels
                         ? *std::max_element(d.levels.begin(), d.levels.end())
                         : d.kind == RadiusDistribution::Kind::lognormal ? d.median : d.radius;
  if (!(top < R))
    throw std::invalid_argument("asperity radii " + d.describe() + " must be smaller than radius = " + detail::num(R) + " m");
  if (s.ensemble.mode != Mode::sampled)
    throw std::invalid_argument("ensemble.mode: unequal asperity radii on a sphere draw from their exact sampler (mode = "
                                "\"sampled\") and screen [screening] bodies explicit ones, got \"" +
                                std::string(to_string(s.ensemble.mode)) + "\"");
  if (s.ensemble.impact.enabled || s.bounce.enabled)
    throw std::invalid_argument("experiment.kind: unequal asperity radii on a sphere are analysed as contacts only; use "
                                "kind = \"contact\"");
  const auto B = s.radii->screen_bodies, n = s.ensemble.drops;
  if (d.kind == RadiusDistribution::Kind::lognormal && B >= 2 && n / B < 2)
    throw std::invalid_argument("ensemble.drops (--drops): " + std::to_string(n) + " drops over screening.bodies = " +
                                std::to_string(B) + " (lognormal radii: r_x from rotations of the screened bodies) is " +
                                std::to_string(n / B) + " rotation per body; the standard errors between bodies need "
                                "at least 2 (drops >= " + std::to_string(2 * B) + ")");
}

}  // namespace

void validate(const Scene& s) {
  if (s.mesh) {
    // A mesh body's size is its mesh x scale (plan(), plan.hpp, checks the asperity
    // radius against it): the sphere radius is unused and must not refuse the asperity radius.
    EnsembleConfig e = s.ensemble;
    e.sphere.radius = std::max(e.sphere.radius, 2.0 * e.sphere.asperity_radius);
    validate(e);
  } else {
    validate(s.ensemble);
  }
  if (!(s.alpha > 0 && s.alpha < 1))
    throw std::invalid_argument("alpha must be in (0, 1), got " + std::to_string(s.alpha));
  if (s.out.empty()) throw std::invalid_argument("out must not be empty");
  validate_text_names(s);
  validate_outputs(s);
  if (s.name.empty()) throw std::invalid_argument("name must not be empty");
  validate_bounce(s);
  // Mesh bodies and unequal radii are the runs of body_experiments.hpp (also after command-line
  // overrides of a scene file): only the ensembles and experiments those runs have.
  if (s.radii) validate(s.radii->radii);
  if (s.mesh) validate_mesh_run(s);
  else if (s.radii) validate_radii_run(s);
}

}  // namespace asperity
