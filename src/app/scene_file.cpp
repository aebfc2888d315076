// SPDX-License-Identifier: GPL-3.0-or-later
// Scene files (format 1). toml++ is used header-only, in this translation unit only.
#include "asperity/app/scene_file.hpp"

#include "app/io/bounded_read.hpp"
#include "app/io/output_staging.hpp"
#include "asperity/app/plan.hpp"  // run_kind: the kinds table's recognition (app/runs/kinds.hpp)
#include "asperity/app/plot.hpp"
#include "app/io/text_escape.hpp"

#define TOML_ENABLE_FORMATTERS 0  // we write TOML ourselves (to_toml)
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <variant>

namespace asperity {

namespace {

// Shortest text that reads back as the same double, and is a TOML float (not an integer).
std::string num(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, res.ptr);
  if (std::isfinite(v) && s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string quote(std::string_view s) {
  std::string out = "\"";
  std::size_t skip = 0;  // continuation bytes of a UTF-8 sequence already written
  for (const char& c : s) {
    if (skip > 0) {
      --skip;
      continue;
    }
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out += buf;
    } else if (u >= 0x80) {
      // Scene files are ASCII (bad_brackets): a non-ASCII name is written as \u or \U escapes,
      // which toml++ reads back as the same UTF-8 bytes (a checkpoint of --out résumé resumes).
      // A byte that is not UTF-8 cannot be held by TOML at all: such a path is refused before
      // any run (validate, detail::utf8_problem); here (a message) it shows as U+FFFD.
      std::uint32_t cp = 0;
      const std::size_t n = detail::utf8_at(s, static_cast<std::size_t>(&c - s.data()), cp);
      const unsigned v = n == 0 ? 0xfffdu : static_cast<unsigned>(cp);
      char buf[16];
      if (v > 0xffff) std::snprintf(buf, sizeof buf, "\\U%08x", v);
      else std::snprintf(buf, sizeof buf, "\\u%04x", v);
      out += buf;
      skip = n == 0 ? 0 : n - 1;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A value as the user wrote it, for messages.
std::string show(const toml::node& n) {
  if (auto f = n.as_floating_point()) return num(f->get());
  if (auto i = n.as_integer()) return std::to_string(i->get());
  if (auto s = n.as_string()) return quote(s->get());
  if (auto b = n.as_boolean()) return b->get() ? "true" : "false";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date/time";
}

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "string";
    case toml::node_type::integer: return "integer";
    case toml::node_type::floating_point: return "float";
    case toml::node_type::boolean: return "boolean";
    case toml::node_type::array: return "array";
    case toml::node_type::table: return "table";
    default: return "date/time";
  }
}

// One TOML table being read: remembers which keys were read, so that every other key is an
// error naming its full dotted path.
class Reader {
 public:
  Reader(const toml::table& t, std::string path, std::string_view origin) : t_(t), path_(std::move(path)), origin_(origin) {}

  std::string key(std::string_view k) const { return path_.empty() ? std::string(k) : path_ + "." + std::string(k); }

  // "<origin>:<line>: <message>", thrown as SceneError carrying the key.
  [[noreturn]] void fail(const toml::node* at, const std::string& key, const std::string& message) const {
    std::string where(origin_);
    const auto line = at ? at->source().begin.line : t_.source().begin.line;
    if (line > 0) where += ":" + std::to_string(line);
    throw SceneError(where + ": " + message, key);
  }
  [[noreturn]] void bad(std::string_view k, const std::string& problem) const {
    fail(t_.get(k), key(k), key(k) + ": " + problem);
  }
  [[noreturn]] void unsupported(std::string_view k, const std::string& why) const {
    const toml::node* n = t_.get(k);
    fail(n, key(k), "not supported yet: " + key(k) + " = " + (n ? show(*n) : "?") + " (" + why + ")");
  }

  const toml::node* find(std::string_view k) {
    used_.insert(std::string(k));
    return t_.get(k);
  }
  bool has(std::string_view k) const { return t_.contains(k); }

  void finish() const {
    for (auto&& [k, v] : t_)
      if (!used_.count(std::string(k.str()))) fail(&v, key(k.str()), "unknown key '" + key(k.str()) + "'");
  }

  std::optional<double> real(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    double v = 0;
    if (auto f = n->as_floating_point()) {
      v = f->get();
    } else if (auto i = n->as_integer()) {
      v = static_cast<double>(i->get());
    } else {
      bad(k, "expected a number, got " + show(*n) + " (" + type_name(*n) + ")");
    }
    if (!std::isfinite(v)) bad(k, "must be finite, got " + show(*n));
    return v;
  }
  std::optional<double> positive(std::string_view k, const char* unit) {
    const auto v = real(k);
    if (v && !(*v > 0)) bad(k, "must be > 0 " + std::string(unit) + ", got " + show(*t_.get(k)));
    return v;
  }
  // Whole numbers, written as integers or exactly as floats ("1e6").
  std::optional<std::uint64_t> count(std::string_view k, std::uint64_t lo, std::uint64_t hi) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    long double v = 0;
    if (auto i = n->as_integer()) {
      v = static_cast<long double>(i->get());
    } else if (auto f = n->as_floating_point()) {
      v = f->get();
      if (!std::isfinite(f->get())) bad(k, "must be finite, got " + show(*n));
      if (v != std::floor(v)) bad(k, "must be a whole number, got " + show(*n));
    } else {
      bad(k, "expected a whole number, got " + show(*n) + " (" + type_name(*n) + ")");
    }
    if (v < static_cast<long double>(lo)) bad(k, "must be >= " + std::to_string(lo) + ", got " + show(*n));
    if (v > static_cast<long double>(hi)) bad(k, "must be <= " + std::to_string(hi) + ", got " + show(*n));
    return static_cast<std::uint64_t>(v);
  }
  std::optional<bool> boolean(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    if (auto b = n->as_boolean()) return b->get();
    bad(k, "expected true or false, got " + show(*n) + " (" + type_name(*n) + ")");
  }
  std::optional<std::string> text(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    auto s = n->as_string();
    if (!s) bad(k, "expected a string, got " + show(*n) + " (" + type_name(*n) + ")");
    if (s->get().empty()) bad(k, "must not be empty");
    return s->get();
  }
  // One of `choices`, named in the message.
  std::optional<std::string> choice(std::string_view k, std::initializer_list<std::string_view> choices) {
    auto v = text(k);
    if (!v) return v;
    std::string list;
    for (auto c : choices) {
      if (*v == c) return v;
      list += (list.empty() ? "" : ", ") + quote(c);
    }
    bad(k, "expected one of " + list + ", got " + quote(*v));
  }
  std::optional<Vec3> vec3(std::string_view k, const char* unit) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    auto a = n->as_array();
    if (!a || a->size() != 3) bad(k, std::string("expected an array of 3 numbers [") + unit + "], got " + show(*n));
    Vec3 v;
    for (std::size_t i = 0; i < 3; ++i) {
      const toml::node& e = *a->get(i);
      if (auto f = e.as_floating_point()) {
        v[static_cast<Eigen::Index>(i)] = f->get();
      } else if (auto j = e.as_integer()) {
        v[static_cast<Eigen::Index>(i)] = static_cast<double>(j->get());
      } else {
        bad(k, "element " + std::to_string(i) + " must be a number, got " + show(e));
      }
      if (!std::isfinite(v[static_cast<Eigen::Index>(i)])) bad(k, "element " + std::to_string(i) + " must be finite, got " + show(e));
    }
    return v;
  }
  std::optional<std::vector<double>> reals(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    auto a = n->as_array();
    if (!a || a->empty()) bad(k, "expected a non-empty array of numbers, got " + show(*n));
    std::vector<double> out;
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& e = *a->get(i);
      double v = 0;
      if (auto f = e.as_floating_point()) v = f->get();
      else if (auto j = e.as_integer()) v = static_cast<double>(j->get());
      else bad(k, "element " + std::to_string(i) + " must be a number, got " + show(e));
      if (!std::isfinite(v)) bad(k, "element " + std::to_string(i) + " must be finite, got " + show(e));
      out.push_back(v);
    }
    return out;
  }
  // [[lo, hi], ...]: non-empty array of number pairs (the bounce speed windows).
  std::optional<std::vector<std::pair<double, double>>> pairs(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    auto a = n->as_array();
    if (!a || a->empty()) bad(k, "expected a non-empty array of [lo, hi] pairs, got " + show(*n));
    std::vector<std::pair<double, double>> out;
    for (std::size_t i = 0; i < a->size(); ++i) {
      auto p = a->get(i)->as_array();
      if (!p || p->size() != 2) bad(k, "element " + std::to_string(i) + " must be a pair [lo, hi], got " + show(*a->get(i)));
      double v[2] = {0, 0};
      for (std::size_t j = 0; j < 2; ++j) {
        const toml::node& e = *p->get(j);
        if (auto f = e.as_floating_point()) v[j] = f->get();
        else if (auto m = e.as_integer()) v[j] = static_cast<double>(m->get());
        else bad(k, "element " + std::to_string(i) + " must hold numbers, got " + show(e));
      }
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !(v[0] >= 0) || !(v[0] < v[1]))
        bad(k, "element " + std::to_string(i) + " must satisfy 0 <= lo < hi (finite), got " + show(*a->get(i)));
      out.push_back({v[0], v[1]});
    }
    return out;
  }
  // A sub-table (a [section] or an inline { ... } table).
  std::optional<Reader> table(std::string_view k) {
    const toml::node* n = find(k);
    if (!n) return std::nullopt;
    auto t = n->as_table();
    if (!t) bad(k, "expected a table, got " + show(*n) + " (" + type_name(*n) + ")");
    return Reader(*t, key(k), origin_);
  }
  [[noreturn]] void missing(std::string_view k, const std::string& hint) const {
    fail(nullptr, key(k), key(k) + ": missing (" + hint + ")");
  }

 private:
  const toml::table& t_;
  std::string path_;
  std::string_view origin_;
  std::set<std::string> used_;
};


// [outputs.cor_table]: file (required), speeds, probabilities, drops, spins, omega_bands. The names are checked against
// the run's other outputs by validate(Scene); the table's own ranges here, each key named.
CorTableScene read_cor_table(Reader& t) {
  CorTableScene c;
  const auto file = t.text("file");
  if (!file) t.missing("file", "the table's CSV file name inside outputs.dir, e.g. \"cor.csv\"");
  c.file = *file;
  if (auto v = t.reals("speeds")) {
    for (std::size_t i = 0; i < v->size(); ++i) {
      const double u = (*v)[i];
      if (!(u > 0) || u > 1e8) t.bad("speeds", "each speed must be > 0 and <= 1e8 m/s, got " + num(u));
      if (i > 0 && !(u > (*v)[i - 1])) t.bad("speeds", "must ascend strictly, got " + num((*v)[i - 1]) + " then " + num(u));
    }
    if (v->size() > 1000) t.bad("speeds", "at most 1000 speeds, got " + std::to_string(v->size()));
    c.speeds = *v;
  }
  if (auto p = t.count("probabilities", 2, 100001)) c.probabilities = *p;
  if (auto d = t.count("drops", 3, kMaxRawDrops)) c.drops = *d;
  if (auto w = t.reals("spins")) {
    for (std::size_t i = 0; i < w->size(); ++i) {
      if (std::abs((*w)[i]) > 1e6) t.bad("spins", "each |spin| must be <= 1e6 rad/s, got " + num((*w)[i]));
      if (i > 0 && !((*w)[i] > (*w)[i - 1])) t.bad("spins", "must ascend strictly, got " + num((*w)[i - 1]) + " then " + num((*w)[i]));
    }
    if (w->size() > 1000) t.bad("spins", "at most 1000 spins, got " + std::to_string(w->size()));
    c.spins = *w;
  }
  if (auto b = t.count("omega_bands", 0, 1000)) {
    if (2 * *b > c.drops) t.bad("omega_bands", "at most drops / 2 = " + std::to_string(c.drops / 2) + ", got " + std::to_string(*b));
    c.omega_bands = *b;
  }
  t.finish();
  return c;
}

// THE mapping from a scene file to a Scene: every section and key of format 1 is read here, and
// nowhere else. New engine features (mesh bodies, radius distributions, bounce experiments, ...)
// are wired in by replacing the matching `unsupported(...)` with a field of Scene.
// material.tangential = { model = "kinematic" (eps_t) | "coulomb" (mu, restitution = "newton" |
// "poisson" | "energetic") | "stronge" (mu) | "walton" (mu, beta0) } (core/tangential.hpp).
TangentialLaw read_tangential(Reader& t) {
  const auto model = t.choice("model", {"kinematic", "coulomb", "stronge", "walton"});
  if (!model)
    t.missing("model", "\"kinematic\" (eps_t), \"coulomb\" (mu, restitution), \"stronge\" (mu) or \"walton\" (mu, beta0)");
  auto mu = [&] {
    const auto m = t.real("mu");
    if (!m) t.missing("mu", "the friction coefficient, e.g. 0.1");
    if (!(*m >= 0 && *m <= TangentialLaw::kMaxMu)) t.bad("mu", "must be in [0, 1e12] (1e12 already sticks every impact), got " + num(*m));
    return *m;
  };
  TangentialLaw law;
  if (*model == "kinematic") {
    const auto e = t.real("eps_t");
    if (e && (*e < -1 || *e > 1)) t.bad("eps_t", "must be in [-1, 1], got " + num(*e));
    law = TangentialLaw::kinematic(e.value_or(1.0));
  } else if (*model == "coulomb") {
    const double m = mu();
    const auto rule = t.choice("restitution", {"newton", "poisson", "energetic"});
    if (!rule) t.missing("restitution", "\"newton\", \"poisson\" or \"energetic\" (Stronge)");
    law = TangentialLaw::coulomb(m, parse_normal_rule(*rule));
  } else if (*model == "stronge") {
    law = TangentialLaw::stronge(mu());
  } else {
    const double m = mu();
    const auto b = t.real("beta0");
    if (!b) t.missing("beta0", "tangential restitution when sticking, in [-1, 1]");
    if (*b < -1 || *b > 1) t.bad("beta0", "must be in [-1, 1], got " + num(*b));
    law = TangentialLaw::walton(m, *b);
  }
  t.finish();
  return law;
}

// Reads `format` (which must be the library's) and `name`.
void read_header(Reader& top, Scene& s) {
  const auto format = top.count("format", 1, std::numeric_limits<std::int64_t>::max());
  if (!format) top.missing("format", "write format = " + std::to_string(kSceneFormatVersion) + " as the first line");
  if (*format != kSceneFormatVersion)
    top.bad("format", "this library reads format " + std::to_string(kSceneFormatVersion) + ", got " +
                          std::to_string(*format));
  s.name = top.text("name").value_or("custom");
}

// body.smooth = [a, b, c] or [a, b, c, m]: the (super)ellipsoid the asperity centres are mapped onto.
std::vector<double> read_smooth(Reader& body, std::vector<double> sm) {
  if (sm.size() != 3 && sm.size() != 4)
    body.bad("smooth", "expected [a, b, c] or [a, b, c, m] [m], got " + std::to_string(sm.size()) + " numbers");
  for (std::size_t i = 0; i < sm.size(); ++i)
    if (!(sm[i] > 0)) body.bad("smooth", "element " + std::to_string(i) + " must be > 0, got " + num(sm[i]));
  // The supported lengths (geometry.hpp); plan() (plan.hpp) also matches them to the mesh.
  for (std::size_t i = 0; i < 3; ++i)
    if (!(sm[i] >= kMinLength && sm[i] <= kMaxLength))
      body.bad("smooth", "semi-axis " + std::to_string(i) + " must be in [" + num(kMinLength) + ", " +
                             num(kMaxLength) + "] m (supported range), got " + num(sm[i]));
  if (sm.size() == 4 && !(sm[3] >= 2 && sm[3] <= kMaxSuperellipsoidExponent))
    body.bad("smooth", "exponent m must be in [2, " + std::to_string(static_cast<int>(kMaxSuperellipsoidExponent)) +
                           "], got " + num(sm[3]));
  return sm;
}

MeshBodyScene read_mesh_body(Reader& body) {
  MeshBodyScene m;
  const auto file = body.text("mesh");
  if (!file) body.missing("mesh", "a mesh file (OFF/PLY/STL/OBJ), e.g. mesh = \"../meshes/ellipsoid.off\"");
  m.file = *file;
  if (auto sc = body.positive("scale", "(mesh units -> m)")) m.scale = *sc;
  if (auto sm = body.reals("smooth")) m.smooth = read_smooth(body, std::move(*sm));
  if (body.has("radius")) body.bad("radius", "only for kind = \"sphere\" (a mesh body's size is the mesh x scale)");
  return m;
}

// [body]: the paper's sphere (radius) or a mesh body.
void read_body(Reader& top, Scene& s) {
  auto body = top.table("body");
  if (!body) return;
  const auto kind = body->choice("kind", {"sphere", "mesh"}).value_or("sphere");
  if (kind == "mesh") {
    s.mesh = read_mesh_body(*body);
  } else {
    for (const char* k : {"mesh", "scale", "smooth"})
      if (body->has(k)) body->bad(k, "only for kind = \"mesh\"");
  }
  if (auto r = body->positive("radius", "m")) s.ensemble.sphere.radius = *r;
  body->finish();
}

// material.restitution: the viscoelastic model of Eq. 9 (a constant one is refused, not ignored).
void read_restitution(Reader& rest, ImpactExperiment& impact) {
  const auto model = rest.choice("model", {"viscoelastic", "constant"});
  if (!model) rest.missing("model", "\"viscoelastic\" (with beta) or \"constant\" (with value)");
  if (*model == "viscoelastic") {
    const auto beta = rest.positive("beta", "(s/m)^(1/5)");
    if (!beta) rest.missing("beta", "Pade [1/4] constant of Eq. 9, e.g. 0.0467 for steel");
    impact.beta = *beta;
  } else {
    if (auto v = rest.real("value"); v && (*v < 0 || *v > 1))
      rest.bad("value", "must be in [0, 1], got " + num(*v));
    rest.unsupported("model", "impacts use the viscoelastic model only");
  }
  rest.finish();
}

// [material]: density, the tangential law (eps_t or material.tangential, once) and restitution.
void read_material(Reader& top, Scene& s) {
  auto mat = top.table("material");
  if (!mat) return;
  auto& impact = s.ensemble.impact;
  if (auto d = mat->positive("density", "kg/m^3")) impact.density = *d;
  const bool eps_t_given = mat->has("eps_t");
  if (auto e = mat->real("eps_t")) {
    if (*e < -1 || *e > 1) mat->bad("eps_t", "must be in [-1, 1], got " + num(*e));
    impact.eps_t = *e;
  }
  if (auto tan = mat->table("tangential")) {
    impact.tangential = read_tangential(*tan);
    if (impact.tangential.model != TangentialLaw::Model::kinematic) {
      if (eps_t_given) mat->bad("eps_t", "belongs to the kinematic law; material.tangential chose " + impact.tangential.describe());
    } else if (eps_t_given) {
      mat->bad("eps_t", "give it once: tangential = { model = \"kinematic\", eps_t = ... } or eps_t, not both");
    } else {
      impact.eps_t = impact.tangential.eps_t;
    }
  }
  if (auto rest = mat->table("restitution")) read_restitution(*rest, impact);
  mat->finish();
}

// asperities.count or asperities.areal_density (on the sphere of radius R), one of them.
void read_asperity_count(Reader& asp, Scene& s, double R) {
  const auto n = asp.count("count", 1, kMaxAsperities);
  const auto eta = asp.positive("areal_density", "per m^2");
  if (n && eta) asp.bad("areal_density", "give either count or areal_density, not both");
  if (eta && s.mesh) asp.bad("areal_density", "a mesh body needs count (N per body), got areal_density = " + num(*eta));
  if (n) s.ensemble.sphere.asperities = *n;
  if (eta) {
    const double count = std::round(*eta * 4.0 * std::numbers::pi * R * R);
    if (!(count >= 1) || count > double(kMaxAsperities))
      asp.bad("areal_density", num(*eta) + " per m^2 on a sphere of radius " + num(R) + " m gives " + num(count) +
                                   " asperities; need 1 .. 2^32-1");
    s.ensemble.sphere.asperities = static_cast<std::uint64_t>(count);
  }
}

// Message for a length outside the supported range (geometry.hpp), "" when it is inside.
std::string length_range_problem(double a) {
  if (a >= kMinLength && a <= kMaxLength) return "";
  return "must be in [" + num(kMinLength) + ", " + num(kMaxLength) + "] m (supported range), got " + num(a);
}

// distribution = "fixed": every asperity has radius `value` (the paper).
void read_fixed_radius(Reader& rad, Scene& s, double R) {
  const auto a = rad.positive("value", "m");
  if (!a) rad.missing("value", "the asperity radius a [m]");
  if (const std::string why = length_range_problem(*a); !why.empty()) rad.bad("value", why);
  if (!s.mesh && *a >= R) rad.bad("value", num(*a) + " m must be smaller than body.radius = " + num(R) + " m");
  s.ensemble.sphere.asperity_radius = *a;
}

RadiusDistribution read_lognormal_radius(Reader& rad, const Scene& s, double R) {
  const auto median = rad.positive("median", "m");
  if (!median) rad.missing("median", "the median asperity radius exp(mu) [m]");
  if (const std::string why = length_range_problem(*median); !why.empty()) rad.bad("median", why);
  const auto sigma = rad.real("sigma");
  if (!sigma) rad.missing("sigma", "the standard deviation of ln(radius), e.g. 0.3");
  if (*sigma < 0) rad.bad("sigma", "must be >= 0, got " + num(*sigma));
  if (!s.mesh && *median >= R) rad.bad("median", num(*median) + " m must be smaller than body.radius = " + num(R) + " m");
  return RadiusDistribution::lognormal(*median, *sigma);
}

// distribution = "levels": radii with their fractions (the exact level law, theory_radii.hpp).
RadiusDistribution read_radius_levels(Reader& rad, const Scene& s, double R) {
  const auto radii = rad.reals("radii");
  const auto fractions = rad.reals("fractions");
  if (radii) {
    for (double r : *radii)
      if (!(r >= kMinLength && r <= kMaxLength))
        rad.bad("radii", "every radius must be in [" + num(kMinLength) + ", " + num(kMaxLength) +
                             "] m (supported range), got " + num(r));
    if (radii->size() > kMaxRadiusLevels)
      rad.bad("radii", "at most " + std::to_string(kMaxRadiusLevels) + " levels, got " +
                           std::to_string(radii->size()) + " (the exact level law costs ~levels^3 per point)");
  }
  if (fractions) {
    double sum = 0;
    for (double f : *fractions) {
      if (!(f > 0)) rad.bad("fractions", "every fraction must be > 0, got " + num(f));
      sum += f;
    }
    if (std::abs(sum - 1.0) > 1e-9) rad.bad("fractions", "must sum to 1, got " + num(sum));
  }
  if (!radii) rad.missing("radii", "the level radii [m], e.g. [1.3e-6, 6.5e-7]");
  if (!fractions) rad.missing("fractions", "one probability per radius, summing to 1, e.g. [0.2, 0.8]");
  if (radii->size() != fractions->size())
    rad.bad("fractions", "needs one fraction per radius (" + std::to_string(radii->size()) + "), got " +
                             std::to_string(fractions->size()));
  if (!s.mesh)
    for (double r : *radii)
      if (r >= R) rad.bad("radii", num(r) + " m must be smaller than body.radius = " + num(R) + " m");
  return RadiusDistribution::discrete(*radii, *fractions);
}

// asperities.radius: "fixed" sets the one radius; "lognormal" and "levels" make a radii run.
void read_asperity_radius(Reader& rad, Scene& s, double R) {
  const auto dist = rad.choice("distribution", {"fixed", "lognormal", "levels"});
  if (!dist) rad.missing("distribution", "\"fixed\" (with value), \"lognormal\" or \"levels\"");
  if (*dist == "fixed") read_fixed_radius(rad, s, R);
  else if (*dist == "lognormal") s.radii = RadiiScene{read_lognormal_radius(rad, s, R)};
  else s.radii = RadiiScene{read_radius_levels(rad, s, R)};
  rad.finish();
}

// [asperities]; then the sphere must be larger than its asperities.
void read_asperities(Reader& top, Scene& s) {
  const double R = s.ensemble.sphere.radius;
  if (auto asp = top.table("asperities")) {
    read_asperity_count(*asp, s, R);
    if (auto rad = asp->table("radius")) read_asperity_radius(*rad, s, R);
    asp->finish();
  }
  if (!s.mesh && s.ensemble.sphere.asperity_radius >= R)
    top.fail(nullptr, "body.radius",
             "body.radius: " + num(R) + " m must exceed the asperity radius " + num(s.ensemble.sphere.asperity_radius) + " m");
}

// ensemble.mode; the names removed in 2.0.0 ("fixed", "fresh") are refused saying what to write.
void read_mode(Reader& ens, Scene& s) {
  auto& e = s.ensemble;
  if (const auto* m = ens.has("mode") ? ens.find("mode") : nullptr; m && m->as_string())
    if (const std::string why = removed_mode(m->as_string()->get()); !why.empty()) ens.bad("mode", why);
  if (auto m = ens.choice("mode", {"explicit", "sampled"})) {
    e.mode = parse_mode(*m);
  } else if (s.radii && !s.mesh) {
    e.mode = Mode::sampled;  // unequal radii on a sphere: the exact sampler is their only design
  }
}

// ensemble.spheres: a count, or "auto" (the planner takes K from the error budget).
void read_spheres(Reader& ens, Scene& s) {
  auto& e = s.ensemble;
  const toml::node* k_node = ens.has("spheres") ? ens.find("spheres") : nullptr;
  if (k_node && k_node->as_string() && k_node->as_string()->get() == "auto") {
    s.spheres_auto = true;
  } else if (auto k = ens.count("spheres", 1, kMaxRawDrops)) {
    if (e.mode == Mode::sampled && *k != 1)
      ens.bad("spheres", "only mode = \"explicit\" uses explicit spheres (sampled draws from the exact law, no sphere), "
                         "got " + std::to_string(*k));
    e.spheres = *k;
    s.spheres_auto = e.mode != Mode::explicit_spheres;
  }
}

// ensemble.seed: integers up to 2^63 - 1; larger 64-bit seeds as a string of digits.
void read_seed(Reader& ens, std::uint64_t& seed_out) {
  const toml::node* seed = ens.find("seed");
  if (!seed) return;
  if (auto i = seed->as_integer()) {
    if (i->get() < 0) ens.bad("seed", "must be >= 0, got " + show(*seed));
    seed_out = static_cast<std::uint64_t>(i->get());
  } else if (auto str = seed->as_string()) {
    const std::string& t = str->get();
    const auto res = std::from_chars(t.data(), t.data() + t.size(), seed_out);
    if (t.empty() || res.ec != std::errc() || res.ptr != t.data() + t.size())
      ens.bad("seed", "expected a non-negative 64-bit integer, got " + show(*seed));
  } else {
    ens.bad("seed", "expected a non-negative integer, got " + show(*seed) + " (" + type_name(*seed) + ")");
  }
}

void read_backend(Reader& ens, Scene& s) {
  auto& e = s.ensemble;
  if (auto b = ens.choice("backend", {"auto", "brute", "kdtree", "cgal", "fcl", "grid"})) {
    s.backend_auto = *b == "auto";
    if (!s.backend_auto) e.backend = parse_backend(*b);
    if (e.mode == Mode::sampled && !s.backend_auto)  // a key that cannot apply is refused, never ignored
      ens.bad("backend", "only mode = \"explicit\" queries a contact index (sampled draws the lowest asperities "
                         "from the exact law): \"auto\" or absent, got \"" + *b + "\"");
  }
}

// [ensemble]
void read_ensemble(Reader& top, Scene& s) {
  auto ens = top.table("ensemble");
  if (!ens) return;
  auto& e = s.ensemble;
  read_mode(*ens, s);
  if (auto d = ens->count("drops", 2, kMaxStreamingDrops)) e.drops = *d;  // > 2^31: streaming only (validate)
  read_spheres(*ens, s);
  if (e.mode == Mode::explicit_spheres && !s.spheres_auto && e.drops % e.spheres != 0)
    ens->bad("drops", std::to_string(e.drops) + " must be a multiple of ensemble.spheres = " + std::to_string(e.spheres));
  read_seed(*ens, e.seed);
  read_backend(*ens, s);
  // Which drop kernel instantiation runs the explicit drops (the same bits; validate() refuses one
  // this build lacks).
  if (auto k = ens->choice("kernel", {"scalar", "simd", "gpu"})) {
    e.kernel = parse_kernel(*k);
    if (e.mode == Mode::sampled)  // a key that cannot apply is refused, never ignored
      ens->bad("kernel", "only mode = \"explicit\" runs the drop kernel (sampled draws the lowest asperities from "
                         "the exact law), got \"" + *k + "\"");
  }
  if (auto t = ens->count("threads", 0, std::uint64_t(kMaxThreads))) e.threads = static_cast<int>(*t);
  if (auto st = ens->choice("statistics", {"auto", "raw", "streaming"})) e.statistics = parse_statistics(*st);
  if (auto b = ens->count("bins_log2", 10, 24)) e.bins_log2 = static_cast<unsigned>(*b);
  ens->finish();
}

// Mesh bodies and unequal radii are runs of body_experiments.hpp: explicit bodies with the exact
// support tree, so the ensemble keys that choose a contact backend do not apply (their modes:
// validate(Scene), scene.cpp). Bodies, radii and bounce runs choose their own number of bodies: K
// is never automatic there.
void check_body_ensemble(Reader& top, Scene& s) {
  const auto& e = s.ensemble;
  if (s.mesh || s.radii || s.bounce.enabled) s.spheres_auto = false;
  if ((s.mesh || s.radii) && !s.backend_auto)
    top.fail(nullptr, "ensemble.backend",
             "ensemble.backend: mesh bodies and unequal asperity radii use the exact support tree; only \"auto\", got \"" +
                 std::string(to_string(e.backend)) + "\"");
}

// [screening]: unequal radii (sphere: lambda_eff of run_radii_experiment; mesh: screen_body).
void read_screening(Reader& top, Scene& s) {
  if (auto scr = top.table("screening")) {
    if (!s.radii)
      scr->fail(nullptr, "screening", "screening: only for unequal asperity radii (asperities.radius distribution "
                                      "\"levels\" or \"lognormal\")");
    if (auto b = scr->count("bodies", 1, 1u << 20)) s.radii->screen_bodies = *b;
    if (auto d = scr->count("directions", 1, kMaxRawDrops)) s.radii->screen_directions = *d;
    scr->finish();
  }
  if (s.radii && !s.mesh && s.radii->radii.kind == RadiusDistribution::Kind::lognormal &&
      s.ensemble.drops % s.radii->screen_bodies != 0)
    top.fail(nullptr, "ensemble.drops",
             "ensemble.drops: " + std::to_string(s.ensemble.drops) + " must be a multiple of screening.bodies = " +
                 std::to_string(s.radii->screen_bodies) + " (lognormal radii: r_x comes from rotations of the screened bodies)");
}

// experiment.variants = "paper,dynamic,...": each variant once.
std::vector<BounceVariant> read_bounce_variants(Reader& ex, const std::string& v) {
  std::vector<BounceVariant> variants;
  std::size_t pos = 0;
  do {
    const std::size_t comma = v.find(',', pos);
    BounceVariant b{};
    try {
      b = parse_bounce_variant(v.substr(pos, comma - pos));
    } catch (const std::invalid_argument& err) {
      ex.bad("variants", err.what());
    }
    if (std::find(variants.begin(), variants.end(), b) != variants.end())
      ex.bad("variants", "\"" + std::string(to_string(b)) + "\" is given twice in " + quote(v) +
                             " (a variant compared with itself decides nothing)");
    variants.push_back(b);
    pos = comma == std::string::npos ? comma : comma + 1;
  } while (pos != std::string::npos);
  return variants;
}

// The groups of the bounce analysis (defaults: bounce.hpp), e.g. to match an experiment's impact speeds.
void read_bounce_groups(Reader& ex, BounceExperiment& b) {
  if (auto w = ex.pairs("speed_windows")) b.windows = *w;
  if (auto g = ex.reals("impact_groups")) {
    b.impact_numbers.clear();
    for (double k : *g) {
      if (!(k >= 1) || k != std::floor(k) || k > 1e9) ex.bad("impact_groups", "impact numbers are whole numbers >= 1, got " + num(k));
      b.impact_numbers.push_back(static_cast<unsigned>(k));
    }
  }
}

// kind = "bounce" (Sec. V): sequences of impacts from `speed` down to `stop_speed`, Omega = 0 at the start.
void read_bounce(Reader& ex, Scene& s) {
  auto& b = s.bounce;
  b.enabled = true;
  if (auto u = ex.positive("speed", "m/s")) b.speed = *u;
  if (auto u = ex.positive("stop_speed", "m/s")) b.stop_speed = *u;
  if (auto g = ex.positive("gravity", "m/s^2")) b.gravity = *g;
  if (auto n = ex.count("sequences", 1, std::uint64_t{1} << 31)) b.sequences = *n;
  if (auto v = ex.text("variants")) b.variants = read_bounce_variants(ex, *v);
  read_bounce_groups(ex, b);
  if (!(b.stop_speed < b.speed))
    ex.bad("stop_speed", "must be below speed = " + num(b.speed) + " m/s, got " + num(b.stop_speed));
  // A body bounces one way, its orientation carried by the free rotation (body_bounce.hpp): its
  // default; any other variant is refused by validate(Scene).
  if (s.mesh) {
    if (!ex.has("variants")) b.variants = {BounceVariant::dynamic};
    if (const auto W = ex.vec3("Omega", "rad/s")) b.omega = *W;
  } else if (ex.has("Omega")) {
    ex.bad("Omega", "only for body.kind = \"mesh\": the sphere's bounce variants start without spin (Sec. V)");
  }
}

// kind = "impact": one vertical impact at V with spin Omega.
void read_impact(Reader& ex, ImpactExperiment& impact) {
  const auto V = ex.vec3("V", "m/s");
  const auto Omega = ex.vec3("Omega", "rad/s");
  if (!V) ex.missing("V", "velocity before the impact [m/s], e.g. [0, 0, -1.3]");
  if (!Omega) ex.missing("Omega", "spin before the impact [rad/s], e.g. [0.2, 0, 0]");
  if (!((*V)[2] < 0)) ex.bad("V", "the body must approach the plate below it (V.z < 0), got V.z = " + num((*V)[2]));
  if ((*V)[0] != 0 || (*V)[1] != 0)
    ex.unsupported("V", "only vertical impacts V = [0, 0, -u] are in the engine yet");
  impact.speed = -(*V)[2];
  impact.omega = *Omega;
}

// [experiment]: contact (default), impact or bounce; returns whether it has single impacts.
bool read_experiment(Reader& top, Scene& s) {
  auto ex = top.table("experiment");
  if (!ex) return false;
  const auto kind = ex->choice("kind", {"contact", "impact", "bounce"}).value_or("contact");
  const bool impacts = kind == "impact";
  if (kind == "bounce") {
    read_bounce(*ex, s);
  } else {
    for (const char* k : {"speed", "stop_speed", "gravity", "sequences", "variants", "speed_windows", "impact_groups"})
      if (ex->has(k)) ex->bad(k, "only for kind = \"bounce\"");
  }
  if (impacts) {
    read_impact(*ex, s.ensemble.impact);
  } else {
    for (const char* k : {"V", "Omega"})
      if (ex->has(k) && !(s.bounce.enabled && s.mesh && std::string(k) == "Omega"))
        ex->bad(k, s.bounce.enabled ? "only for kind = \"impact\" (a bounce starts at V = [0, 0, -speed])"
                                    : "only for kind = \"impact\"");
  }
  ex->finish();
  return impacts;
}

// Which bodies can run which experiment; the bounce takes the material of every impact.
void check_experiment(Reader& top, Scene& s, bool impacts) {
  auto& impact = s.ensemble.impact;
  impact.enabled = impacts;
  if (s.bounce.enabled || s.mesh) s.spheres_auto = false;  // their own designs
  if (s.mesh && impacts && s.ensemble.drops % s.ensemble.spheres != 0)
    top.fail(nullptr, "ensemble.drops", "ensemble.drops: must be a multiple of ensemble.spheres");
  if (s.bounce.enabled) {  // the material applies to every impact of a sequence
    s.bounce.density = impact.density, s.bounce.beta = impact.beta, s.bounce.eps_t = impact.eps_t;
  }
}

// outputs.report and outputs.export_ply/export_style: plain names inside outputs.dir.
void read_output_files(Reader& out, Scene& s) {
  if (auto r = out.text("report")) {
    if (const std::string why = output_name_problem(*r); !why.empty())
      out.bad("report", "must be a plain file name inside outputs.dir, got " + quote(*r) + ": it " + why);
    s.report = *r;
  }
  if (auto p = out.text("export_ply")) {
    if (!s.mesh) out.bad("export_ply", "only for body.kind = \"mesh\"");
    if (const std::string why = output_name_problem(*p); !why.empty())
      out.bad("export_ply", "must be a plain file name inside outputs.dir, got " + quote(*p) + ": it " + why);
    if (*p == s.report || *p == report_table_name(s.report))
      out.bad("export_ply", quote(*p) + " is also the name of the report or its table (" + quote(s.report) + ", " +
                                quote(report_table_name(s.report)) + ")");
    s.mesh->export_ply = *p;
  }
  if (auto st = out.choice("export_style", {"spheres", "points"})) {
    if (!s.mesh || s.mesh->export_ply.empty()) out.bad("export_style", "only with outputs.export_ply");
    s.mesh->export_points = *st == "points";
  }
}

// [outputs]: what to analyse and where to write it.
void read_outputs(Reader& top, Scene& s, bool impacts) {
  auto out = top.table("outputs");
  if (!out) return;
  if (auto c = out->boolean("contact")) s.contact_stats = *c;
  if (auto r = out->boolean("restitution")) {
    if (*r && !impacts && !s.bounce.enabled)
      out->bad("restitution", "true needs experiment.kind = \"impact\" or \"bounce\"");
    s.restitution_stats = *r;
  }
  if (!s.bounce.enabled && !s.contact_stats && !(impacts && s.restitution_stats))
    out->bad("contact", "nothing to compute: request contact = true, or restitution = true with an impact experiment");
  if (auto p = out->boolean("plots")) s.plots = *p;
  if (auto f = out->text("plot_format")) {
    try {
      parse_plot_formats(*f);
    } catch (const std::invalid_argument& ex) {
      out->bad("plot_format", ex.what());
    }
    s.plot_format = *f;
  }
  if (auto a = out->real("alpha")) {
    if (!(*a > 0 && *a < 1)) out->bad("alpha", "must be in (0, 1), got " + num(*a));
    s.alpha = *a;
  }
  if (auto d = out->text("dir")) s.out = *d;
  read_output_files(*out, s);
  if (s.mesh && !(s.contact_stats && s.restitution_stats))
    out->bad(s.contact_stats ? "restitution" : "contact", "a mesh body's run always analyses contacts and restitution");
  if (auto ct = out->table("cor_table")) s.cor_table = read_cor_table(*ct);  // which runs: validate(Scene)
  out->finish();
}

// The [ensemble] keys a kind of run never uses are refused, never ignored (an option that edits
// one is named before it): a bounce counts experiment.sequences, not drops, and the sphere's
// bounce variants build a lazy sphere per sequence (no mode, spheres, backend); only explicit
// sphere drops run the drop kernel; only sphere contact runs stream; unequal radii on a sphere
// screen screening.bodies, not spheres. The one statement of these rules (the CLI has none).
void check_unused_ensemble_keys(const Reader& top, const toml::table& root, const Scene& s) {
  const RunKind kind = run_kind(s);
  if (kind == RunKind::sphere) return;
  std::vector<std::string_view> unused{"kernel", "statistics", "bins_log2"};
  if (kind == RunKind::bounce || kind == RunKind::mesh_bounce) unused.push_back("drops");
  if (kind == RunKind::bounce) unused.insert(unused.end(), {"mode", "spheres", "backend"});
  if (kind == RunKind::radii) unused.push_back("spheres");
  const std::string what = kind == RunKind::bounce        ? "a bounce run (experiment.kind = \"bounce\")"
                           : kind == RunKind::mesh_bounce ? "a mesh body's bounce run"
                           : kind == RunKind::mesh        ? "a mesh body (body.kind = \"mesh\")"
                                                          : "a run with unequal asperity radii on a sphere";
  for (const std::string_view k : unused) {
    const std::string key = "ensemble." + std::string(k);
    const toml::node* at = root.at_path(key).node();
    if (!at) continue;
    std::string why = "not used by " + what;
    if (k == "drops") why += ", which counts bounce sequences: use experiment.sequences";
    else if (k == "spheres" && kind == RunKind::radii) why += " (its explicit spheres are screening.bodies)";
    else if (k == "kernel") why += " (explicit sphere drops only)";
    else if (k == "statistics" || k == "bins_log2") why += " (sphere contact runs only)";
    else if (kind == RunKind::bounce) why += ": every sequence bounces its own lazy sphere";
    top.fail(at, key, key + ": " + why);
  }
}

// The engine's own checks, as a net: the keys read above should already have caught everything.
// A message that starts with a dotted key ("ensemble.drops (--drops): ...") points at its line.
void validate_at_lines(const Reader& top, const toml::table& root, const Scene& s) {
  try {
    validate(s);
  } catch (const std::invalid_argument& ex) {
    const std::string what = ex.what();
    const std::string key = what.substr(0, what.find_first_of(" :"));
    const toml::node* at = key.find('.') != std::string::npos ? root.at_path(key).node() : nullptr;
    top.fail(at, at ? key : "", what);
  }
}

// The tables in this order: a later table's rules may depend on an earlier one (body -> radii ->
// mode -> experiment -> outputs), and the first error found is the one reported.
Scene scene_from_toml(const toml::table& root, std::string_view origin) {
  Reader top(root, "", origin);
  Scene s;
  read_header(top, s);
  read_body(top, s);
  read_material(top, s);
  read_asperities(top, s);
  read_ensemble(top, s);
  check_body_ensemble(top, s);
  read_screening(top, s);
  const bool impacts = read_experiment(top, s);
  check_experiment(top, s, impacts);
  read_outputs(top, s, impacts);
  top.finish();
  check_unused_ensemble_keys(top, root, s);
  validate_at_lines(top, root, s);
  return s;
}

// toml++ 3.3 (Debian 12) violates its own precondition on a table header whose name does not
// start with a key character ("[\n", "[[=", "[[[1]]"): an assertion failure in debug builds,
// undefined behaviour (__builtin_assume) in clang release builds (upstream marzer/tomlplusplus
// PR #301). Such headers are never valid TOML, so they are refused here, before toml++ sees them.
// Returns the 1-based line of the first one, 0 if there is none. Tracks strings, comments and
// multi-line arrays so that a '[' inside a value is not taken for a header.
struct SyntaxProblem {
  std::size_t line = 0;  // 0: none found
  const char* what = "";
};

// Bounds checked before toml++ sees the text: toml++ recurses per dotted-key part and per nested
// array or inline table (a header of 40,000 parts overflowed its stack). No scene key of asperity
// has more than 3 parts, nor any value more than 2 levels of nesting; the limits leave room.
constexpr std::size_t kMaxSceneBytes = std::size_t{1} << 20;  ///< 1 MiB: a scene is a few hundred bytes
constexpr std::size_t kMaxKeyDots = 15;                       ///< a dotted key of at most 16 parts
constexpr std::size_t kMaxNesting = 16;                       ///< arrays / inline tables inside each other

// Counts the dots of the dotted key being read (between separators), outside strings and comments.
// A number has at most one dot and a date or time one, so only a key reaches the limit.
struct KeyDots {
  std::size_t dots = 0;
  bool see(char c) {  // true when the key has too many parts
    if (c == '.') return ++dots > kMaxKeyDots;
    if (c == '=' || c == ',' || c == '[' || c == '{' || c == ']' || c == '}' || c == '\n') dots = 0;
    return false;
  }
};

SyntaxProblem bad_brackets(std::string_view t) {
  std::size_t line = 1;
  bool line_start = true, in_header = false;
  std::string open;  // the [ and { open inside a value, innermost last
  KeyDots key;
  const std::size_t n = t.size();
  // Scene files are ASCII: toml++ 3.3 reaches TOML_UNREACHABLE (undefined behaviour) classifying
  // some non-ASCII characters, in bare keys and inside strings alike (found by fuzzing).
  for (std::size_t i = 0, l = 1; i < n; ++i) {
    if (t[i] == '\n') ++l;
    if (static_cast<unsigned char>(t[i]) >= 0x80) return {l, "a non-ASCII byte (scene files are ASCII)"};
  }
  for (std::size_t i = 0; i < n; ++i) {
    const char c = t[i];
    if (key.see(c)) return {line, "a dotted key of more than 16 parts (no scene key has more than 3)"};
    if (c == '\n') {
      ++line;
      in_header = false;
      if (open.empty()) line_start = true;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r') continue;
    if (c == '#') {
      while (i + 1 < n && t[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '"' || c == '\'') {
      line_start = false;
      if (i + 2 < n && t[i + 1] == c && t[i + 2] == c) {  // multi-line string
        const std::string_view close = c == '"' ? std::string_view("\"\"\"") : std::string_view("'''");
        i += 3;
        while (i < n && t.substr(i, 3) != close) {
          if (c == '"' && t[i] == '\\' && i + 1 < n) ++i;  // an escape (maybe a line-ending backslash)
          if (t[i] == '\n') ++line;
          ++i;
        }
        i += 2;  // at the last quote of the closing triple (the loop's ++i steps past it)
      } else {
        ++i;
        while (i < n && t[i] != c && t[i] != '\n') {
          if (c == '"' && t[i] == '\\') ++i;
          ++i;
        }
        if (i < n && t[i] == '\n') --i;  // unterminated: let the newline be counted
      }
      continue;
    }
    if (line_start && open.empty() && c == '[') {
      std::size_t j = i + 1;
      if (j < n && t[j] == '[') ++j;
      while (j < n && (t[j] == ' ' || t[j] == '\t')) ++j;
      if (j < n) {
        const char k = t[j];
        const bool key_start = (k >= 'A' && k <= 'Z') || (k >= 'a' && k <= 'z') || (k >= '0' && k <= '9') ||
                               k == '_' || k == '-' || k == '"' || k == '\'';
        if (!key_start) return {line, "a table header must start with a key, e.g. [body]"};
      }
      in_header = true;
      line_start = false;
      i = j - 1;
      continue;
    }
    line_start = false;
    if (in_header) continue;
    if (c == '[' || c == '{') {
      open.push_back(c);
      if (open.size() > kMaxNesting) return {line, "arrays or inline tables nested more than 16 deep"};
    } else if ((c == ']' || c == '}') && !open.empty()) {
      // toml++ 3.3 asserts (debug) or misbehaves on a closer that does not match, e.g. [0, 1,}2].
      if ((c == ']') != (open.back() == '[')) return {line, c == ']' ? "']' closes an inline table" : "'}' closes an array"};
      open.pop_back();
    }
  }
  return {};
}

// body.mesh relative to the scene file's directory, then to the meshes/ of the source tree and of
// the installation (by the path as written, then by its file name).
std::filesystem::path resolve_mesh(const std::filesystem::path& mesh, const std::filesystem::path& scene_file,
                                   const std::filesystem::path& scene_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> tried;
  if (mesh.is_absolute()) {
    tried.push_back(mesh);
  } else {
    tried.push_back(scene_dir.empty() ? mesh : scene_dir / mesh);
    for (const char* dir_name : {ASPERITY_SOURCE_MESHES_DIR, ASPERITY_INSTALL_MESHES_DIR}) {
      const fs::path dir(dir_name);
      tried.push_back(dir / mesh);
      tried.push_back(dir / mesh.filename());
    }
  }
  for (const auto& p : tried)
    if (fs::is_regular_file(p, ec)) return p.lexically_normal();
  // The first path that exists but is no file is named as what it is (it was "not found").
  for (const auto& p : tried)
    if (const auto st = fs::status(p, ec); fs::exists(st)) {
      const char* what = fs::is_directory(st) ? "a directory" : fs::is_fifo(st) ? "a FIFO" : fs::is_socket(st) ? "a socket"
                         : fs::is_block_file(st) || fs::is_character_file(st) ? "a device" : "not a regular file";
      throw SceneError(scene_file.string() + ": body.mesh: " + quote(p.string()) + " is " + what + ", not a mesh file",
                       "body.mesh");
    }
  std::string where;
  for (const auto& p : tried) where += (where.empty() ? "" : ", ") + p.string();
  throw SceneError(scene_file.string() + ": body.mesh: mesh file " + quote(mesh.string()) + " not found (looked for " +
                       where + ")",
                   "body.mesh");
}

}  // namespace

namespace {

// The command line's edits, before the one reading: each key set, its tables made when absent.
void apply_edits(toml::table& root, const std::vector<SceneEdit>& edits) {
  for (const SceneEdit& e : edits) {
    toml::table* t = &root;
    std::string_view key = e.key;
    for (std::size_t dot; (dot = key.find('.')) != std::string_view::npos; key.remove_prefix(dot + 1)) {
      const std::string part(key.substr(0, dot));
      if (!t->contains(part)) t->insert(part, toml::table{});
      t = (*t)[part].as_table();
      if (!t) throw SceneError(e.option + ": " + e.key + ": the scene's " + part + " is not a table", e.key);
    }
    std::visit([&](const auto& v) { t->insert_or_assign(std::string(key), v); }, e.value);
    for (const std::string& k : e.replaces) {
      if (k.starts_with('[')) root.erase(k.substr(1, k.size() - 2));
      for (auto it = t->begin(); k == "*" && it != t->end();) it = it->first == key ? std::next(it) : t->erase(it);
      t->erase(k);
    }
  }
}

// The one reading; a problem with an edited key is named by its option (the edited value has no
// line: the message starts with the origin alone).
Scene read_edited(const toml::table& root, std::string_view origin, const std::vector<SceneEdit>& edits) {
  try {
    return scene_from_toml(root, origin);
  } catch (const SceneError& e) {
    for (const SceneEdit& ed : edits) {
      const std::string m = e.what();
      if (e.key() != ed.key || m.rfind(origin, 0) != 0) continue;
      std::size_t at = origin.size();  // past "<origin>" and ":<line>" (a rule of the table names no line of the key)
      if (at + 1 < m.size() && m[at] == ':' && std::isdigit(static_cast<unsigned char>(m[at + 1])))
        at = m.find_first_not_of("0123456789", at + 1);
      if (m.compare(at, 2, ": ") == 0) throw SceneError(ed.option + ": " + m.substr(at + 2), e.key());
    }
    throw;
  }
}

}  // namespace

Scene parse_scene(std::string_view toml_text, std::string_view origin) { return parse_scene(toml_text, origin, {}); }

Scene parse_scene(std::string_view toml_text, std::string_view origin, const std::vector<SceneEdit>& edits) {
  if (toml_text.size() > kMaxSceneBytes)
    throw SceneError(std::string(origin) + ": a scene is at most 1 MiB of TOML, this one has " +
                         std::to_string(toml_text.size()) + " bytes",
                     "");
  if (const SyntaxProblem bad = bad_brackets(toml_text); bad.line != 0)
    throw SceneError(std::string(origin) + ":" + std::to_string(bad.line) + ": TOML syntax error: " + bad.what, "");
  toml::table root;
  try {
    root = toml::parse(toml_text, std::string(origin));
  } catch (const toml::parse_error& e) {
    throw SceneError(std::string(origin) + ":" + std::to_string(e.source().begin.line) + ": TOML syntax error: " +
                         std::string(e.description()),
                     "");
  }
  apply_edits(root, edits);
  return read_edited(root, origin, edits);
}

TangentialLaw read_tangential_items(const std::vector<OptionItem>& items, std::string_view origin) {
  toml::table t;
  for (const OptionItem& i : items) {
    const bool fresh = i.number ? t.insert(i.key, *i.number).second : t.insert(i.key, i.text).second;
    if (!fresh)
      throw SceneError(std::string(origin) + ": material.tangential." + i.key + ": given twice", "material.tangential." + i.key);
  }
  Reader reader(t, "material.tangential", origin);
  return read_tangential(reader);
}

Scene load_scene(const std::filesystem::path& file) { return load_scene(file, {}); }

Scene load_scene(const std::filesystem::path& file, const std::vector<SceneEdit>& edits) {
  std::string text;
  try {
    text = read_bounded_file(file, kMaxSceneBytes, "scene file");
  } catch (const InputFileError& e) {
    throw SceneError(e.what(), "");
  }
  Scene s = parse_scene(text, file.string(), edits);
  if (s.mesh) s.mesh->file = resolve_mesh(s.mesh->file, file, file.parent_path());
  return s;
}

namespace {

// One writer per table of to_toml, in the order of the file.
void write_body(std::ostream& os, const Scene& s) {
  if (s.mesh) {
    os << "[body]\nkind = \"mesh\"\nmesh = " << quote(s.mesh->file.string()) << "\nscale = " << num(s.mesh->scale) << "\n";
    if (!s.mesh->smooth.empty()) {
      os << "smooth = [";
      for (std::size_t i = 0; i < s.mesh->smooth.size(); ++i) os << (i ? ", " : "") << num(s.mesh->smooth[i]);
      os << "]\n";
    }
    os << "\n";
  } else {
    os << "[body]\nkind = \"sphere\"\nradius = " << num(s.ensemble.sphere.radius) << "\n\n";
  }
}

void write_material(std::ostream& os, const ImpactExperiment& x) {
  os << "[material]\ndensity = " << num(x.density);
  if (const auto& t = x.tangential; t.model == TangentialLaw::Model::coulomb)
    os << "\ntangential = { model = \"coulomb\", mu = " << num(t.mu) << ", restitution = \"" << to_string(t.normal) << "\" }";
  else if (t.model == TangentialLaw::Model::walton)
    os << "\ntangential = { model = \"walton\", mu = " << num(t.mu) << ", beta0 = " << num(t.beta0) << " }";
  else
    os << "\neps_t = " << num(x.eps_t);
  os << "\nrestitution = { model = \"viscoelastic\", beta = " << num(x.beta) << " }\n\n";
}

std::string toml_list(const std::vector<double>& v) {
  std::string t = "[";
  for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + num(v[i]);
  return t + "]";
}

// [asperities] and, for unequal radii, [screening].
void write_asperities(std::ostream& os, const Scene& s) {
  const auto& e = s.ensemble;
  os << "[asperities]\ncount = " << e.sphere.asperities << "\n";
  if (!s.radii) {
    os << "radius = { distribution = \"fixed\", value = " << num(e.sphere.asperity_radius) << " }\n\n";
  } else if (const auto& d = s.radii->radii; d.kind == RadiusDistribution::Kind::lognormal) {
    os << "radius = { distribution = \"lognormal\", median = " << num(d.median) << ", sigma = " << num(d.sigma) << " }\n\n";
  } else {
    os << "radius = { distribution = \"levels\", radii = " << toml_list(d.levels) << ", fractions = "
       << toml_list(d.fractions) << " }\n\n";
  }
  if (s.radii)
    os << "[screening]\nbodies = " << s.radii->screen_bodies << "\ndirections = " << s.radii->screen_directions << "\n\n";
}

// Only the keys the kind uses (check_unused_ensemble_keys): a sphere's bounce run has its seed and
// threads; a mesh body's bounce no drops.
void write_ensemble(std::ostream& os, const Scene& s) {
  const auto& e = s.ensemble;
  const RunKind kind = run_kind(s);
  os << "[ensemble]\n";
  if (kind != RunKind::bounce) os << "mode = \"" << to_string(e.mode) << "\"\n";
  if (kind != RunKind::bounce && kind != RunKind::mesh_bounce) os << "drops = " << e.drops << "\n";
  if (e.mode == Mode::explicit_spheres && kind != RunKind::bounce) {  // sampled drops have no explicit spheres
    if (s.spheres_auto)
      os << "spheres = \"auto\"\n";
    else
      os << "spheres = " << e.spheres << "\n";
  }
  os << "seed = ";
  if (e.seed > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    os << quote(std::to_string(e.seed));
  else
    os << e.seed;
  os << "\n";
  if (kind != RunKind::bounce)
    os << "backend = \"" << (s.backend_auto || e.mode == Mode::sampled ? std::string_view("auto") : to_string(e.backend)) << "\"\n";
  os << "threads = " << e.threads << "\n";
  if (e.statistics != Statistics::automatic) os << "statistics = \"" << to_string(e.statistics) << "\"\n";
  if (e.bins_log2 != EnsembleConfig{}.bins_log2) os << "bins_log2 = " << e.bins_log2 << "\n";
  if (e.mode == Mode::explicit_spheres && e.kernel != EnsembleConfig{}.kernel)
    os << "kernel = \"" << to_string(e.kernel) << "\"\n";
  os << "\n";
}

void write_bounce(std::ostream& os, const BounceExperiment& b, bool mesh) {
  os << "[experiment]\nkind = \"bounce\"\nspeed = " << num(b.speed) << "\nstop_speed = " << num(b.stop_speed)
     << "\ngravity = " << num(b.gravity) << "\nsequences = " << b.sequences << "\nvariants = \"";
  for (std::size_t i = 0; i < b.variants.size(); ++i) os << (i ? "," : "") << to_string(b.variants[i]);
  os << "\"\n";
  if (mesh) os << "Omega = [" << num(b.omega.x()) << ", " << num(b.omega.y()) << ", " << num(b.omega.z()) << "]\n";
  if (b.windows != BounceExperiment{}.windows) {
    os << "speed_windows = [";
    for (std::size_t i = 0; i < b.windows.size(); ++i) os << (i ? ", " : "") << "[" << num(b.windows[i].first) << ", " << num(b.windows[i].second) << "]";
    os << "]\n";
  }
  if (b.impact_numbers != BounceExperiment{}.impact_numbers) {
    os << "impact_groups = [";
    for (std::size_t i = 0; i < b.impact_numbers.size(); ++i) os << (i ? ", " : "") << b.impact_numbers[i];
    os << "]\n";
  }
  os << "\n";
}

void write_experiment(std::ostream& os, const Scene& s) {
  const auto& x = s.ensemble.impact;
  if (s.bounce.enabled) {
    write_bounce(os, s.bounce, s.mesh.has_value());
  } else if (x.enabled) {
    os << "[experiment]\nkind = \"impact\"\nV = [0.0, 0.0, " << num(-x.speed) << "]\nOmega = [" << num(x.omega.x())
       << ", " << num(x.omega.y()) << ", " << num(x.omega.z()) << "]\n\n";
  } else {
    os << "[experiment]\nkind = \"contact\"\n\n";
  }
}

// [outputs.cor_table]: written back only when the scene asks for a table.
void write_cor_table_section(std::ostream& os, const CorTableScene& c) {
  os << "\n[outputs.cor_table]\nfile = " << quote(c.file) << "\n";
  if (!c.speeds.empty()) {
    os << "speeds = [";
    for (std::size_t i = 0; i < c.speeds.size(); ++i) os << (i ? ", " : "") << num(c.speeds[i]);
    os << "]\n";
  }
  os << "probabilities = " << c.probabilities << "\ndrops = " << c.drops << "\n";
  if (!c.spins.empty()) {
    os << "spins = [";
    for (std::size_t i = 0; i < c.spins.size(); ++i) os << (i ? ", " : "") << num(c.spins[i]);
    os << "]\n";
  }
  if (c.omega_bands > 0) os << "omega_bands = " << c.omega_bands << "\n";
}

void write_outputs(std::ostream& os, const Scene& s) {
  os << "[outputs]\ncontact = " << (s.contact_stats ? "true" : "false") << "\n";
  if (s.ensemble.impact.enabled || !s.restitution_stats)
    os << "restitution = " << (s.restitution_stats ? "true" : "false") << "\n";
  os << "plots = " << (s.plots ? "true" : "false") << "\n";
  if (s.plot_format != "png") os << "plot_format = " << quote(s.plot_format) << "\n";
  os << "alpha = " << num(s.alpha) << "\ndir = " << quote(s.out.string())
     << "\nreport = " << quote(s.report) << "\n";
  if (s.mesh && !s.mesh->export_ply.empty())
    os << "export_ply = " << quote(s.mesh->export_ply) << "\nexport_style = \""
       << (s.mesh->export_points ? "points" : "spheres") << "\"\n";
  if (s.cor_table) write_cor_table_section(os, *s.cor_table);
}

}  // namespace

std::string to_toml(const Scene& s) {
  std::ostringstream os;
  os << "# asperity scene (README \"Scenes\")\n";
  os << "format = " << kSceneFormatVersion << "\n";
  os << "name = " << quote(s.name) << "\n\n";
  write_body(os, s);
  write_material(os, s.ensemble.impact);
  write_asperities(os, s);
  write_ensemble(os, s);
  write_experiment(os, s);
  write_outputs(os, s);
  return os.str();
}

}  // namespace asperity
