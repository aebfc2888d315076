// SPDX-License-Identifier: GPL-3.0-or-later
// Driver for the experiments beyond the paper (body_experiments.hpp): unequal asperity radii on a
// sphere, rough mesh bodies, and PLY export. Exit status 2 with a clear message on bad input.
//
//   rough_bodies radii  [--n 100000] [--R 3e-3] [--levels 1.3e-6:0.2,6.5e-7:0.8] [--drops 100000]
//                       [--bodies 2] [--seed 1] [--out DIR] [--no-plots]
//   rough_bodies mesh   --mesh meshes/ellipsoid.off [--smooth 4e-3,3e-3,2.25e-3[,m]] [--n 100000]
//                       [--radius 6.5e-7 | --levels ...] [--bodies 10] [--drops 100000] [--speed 1.3]
//                       [--omega-x 0.2] [--seed 1] [--out DIR] [--no-plots]
//   rough_bodies screen --mesh meshes/ellipsoid.off --smooth 4e-3,3e-3,2.25e-3 [--n 100000]
//                       [--levels 1.3e-6:0.2,6.5e-7:0.8] [--repeats 3] [--directions 400000] [--calibrate]
//   rough_bodies export --mesh meshes/rounded_cube.off --out body.ply [--n 300] [--radius 5e-5]
//                       [--style points|spheres] [--inflate 1] [--smooth a,b,c] [--seed 1]
#include <CLI/CLI.hpp>

#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "asperity/experiments/body_bounce.hpp"
#include "asperity/experiments/body_experiments.hpp"
#include "asperity/core/mesh.hpp"
#include "asperity/app/experiment_reports.hpp"
#include "app/io/mesh_io.hpp"
#include "asperity/app/plot.hpp"
#include "asperity/app/report.hpp"
#include "asperity/core/random.hpp"
#include "asperity/core/screening.hpp"
#include "asperity/core/support.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include "timing.hpp"

using namespace asperity;

namespace {

// "r1:f1,r2:f2,..." -> levels.
RadiusDistribution parse_levels(const std::string& s) {
  std::vector<double> r, f;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto colon = item.find(':');
    if (colon == std::string::npos) throw std::invalid_argument("--levels: expected radius:fraction, got '" + item + "'");
    std::size_t used = 0;
    try {
      r.push_back(std::stod(item.substr(0, colon), &used));
      f.push_back(std::stod(item.substr(colon + 1), &used));
    } catch (const std::logic_error&) {
      throw std::invalid_argument("--levels: not a number in '" + item + "'");
    }
  }
  auto d = RadiusDistribution::discrete(r, f);
  validate(d);
  return d;
}

std::vector<double> parse_list(const std::string& s, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      v.push_back(std::stod(item));
    } catch (const std::logic_error&) {
      throw std::invalid_argument(what + ": not a number: '" + item + "'");
    }
  }
  return v;
}

// Single-threaded ns per query of the support tree and of brute_support on a two-level rough
// sphere; every tree answer is checked against brute force on the brute-force subset.
void support_bench(const std::vector<std::uint64_t>& ns, std::uint64_t queries, int repeats) {
  std::cout << "| N | tree ns/query | brute ns/query | speed-up | tree build ms | tree MB |\n|---|---|---|---|---|---|\n";
  for (std::uint64_t n : ns) {
    SphereParams p;
    p.asperities = n;
    const RoughBody b = make_rough_sphere_body(p, RadiusDistribution::discrete({1.3e-6, 6.5e-7}, {0.2, 0.8}), 1, 0);
    std::vector<Vec3> d(queries);
    for (std::uint64_t k = 0; k < queries; ++k) {
      Stream s(2, Purpose::analysis, k);
      d[k] = uniform_on_sphere(s.uniform0(), s.uniform0());
    }
    using clock = std::chrono::steady_clock;
    std::vector<double> build, tree, brute;
    std::unique_ptr<SupportQuery> q;
    std::uint64_t sink = 0;
    const std::uint64_t brute_q = std::max<std::uint64_t>(1, std::min<std::uint64_t>(queries, 2e8 / static_cast<double>(n)));
    for (int r = 0; r < repeats; ++r) {
      auto t0 = clock::now();
      q = make_support_tree(b.centres, b.radii);
      build.push_back(std::chrono::duration<double>(clock::now() - t0).count() * 1e3);
      t0 = clock::now();
      for (const Vec3& x : d) sink += q->support(x).index;
      tree.push_back(std::chrono::duration<double>(clock::now() - t0).count() * 1e9 / static_cast<double>(queries));
      t0 = clock::now();
      for (std::uint64_t k = 0; k < brute_q; ++k) {
        const Support want = brute_support(b.centres, b.radii, d[k]);
        sink += want.index;
        if (r == 0 && !(q->support(d[k]) == want)) throw std::runtime_error("support tree differs from brute force");
      }
      brute.push_back(std::chrono::duration<double>(clock::now() - t0).count() * 1e9 / static_cast<double>(brute_q));
    }
    auto med = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    std::cout << "| " << n << " | " << med(tree) << " | " << med(brute) << " | " << med(brute) / med(tree) << " | "
              << med(build) << " | " << static_cast<double>(q->memory_bytes()) / 1e6 << " |\n";
    if (sink == 42) std::cout << "";
  }
}

// report.json (with the common header, tool "rough_bodies") and report.txt into `dir`, through
// the same writer as validate-geometry.
void write_driver_report(const std::filesystem::path& dir, const std::string& what, const std::string& body,
                         const std::string& table) {
  std::filesystem::create_directories(dir);
  ReportHeader h;
  h.tool = "rough_bodies";
  h.scene = what;
  write_report_files(dir, "report.json", with_header(body, h), table);
  std::cout << "wrote " << (dir / "report.json").string() << ", report.txt\n";
}

using asperity::bench::median;

// Gaussian curvature of |x/a|^m + |y/b|^m + |z/c|^m = 1 at p (mesh coordinates):
// K = g^T adj(H) g / |g|^4 for the implicit F, H diagonal.
double superellipsoid_curvature(const Vec3& p, const std::vector<double>& ax) {
  const double m = ax.size() == 4 ? ax[3] : 2.0;
  double g[3], h[3];
  for (int i = 0; i < 3; ++i) {
    const double a = ax[static_cast<std::size_t>(i)], x = std::abs(p[i]) / a;
    g[i] = m * std::pow(x, m - 1) / a * (p[i] < 0 ? -1 : 1);
    h[i] = m * (m - 1) * std::pow(x, m - 2) / (a * a);
  }
  const double gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
  return (g[0] * g[0] * h[1] * h[2] + g[1] * g[1] * h[0] * h[2] + g[2] * g[2] * h[0] * h[1]) / (gg * gg);
}

// Screening of one smooth mesh body: kept per level, lambda_eff, counts, timing (median of
// `repeats`), cross-check, and the kept fraction of the smallest level against the local
// screening variable x = lambda_top * (rho_top - rho_small) / sqrt(K). On a sphere x = lambda_top
// drho R; the kept fraction of a paraboloid patch depends on x alone (scale the tangent
// coordinates by sqrt(kappa_1), sqrt(kappa_2)), so spheres of the same lambda and several R
// predict it (--calibrate).
void screen_run(const std::filesystem::path& file, const std::vector<double>& ax, std::uint64_t n, const RadiusDistribution& rd,
                int repeats, std::uint64_t directions, bool calibrate, std::uint64_t seed) {
  const TriangleMesh m = read_mesh(file);
  const Vec3 g = mass_properties(m, 1000).centroid;
  const RoughBody b = make_rough_mesh_body(m, n, rd, 1000, seed, 0, smooth_surface(ax),
                                           file.stem().string());
  const auto q = make_support_tree(b.centres, b.radii);
  std::vector<double> secs;
  ScreeningResult r;
  for (int k = 0; k < repeats; ++k) {
    r = screen_body(b, *q);
    secs.push_back(r.seconds);
  }
  const ScreeningCheck c = check_screening(b, *q, r, directions, seed);
  const auto& lv = rd.levels;
  std::vector<double> kept(lv.size(), 0), tot(lv.size(), 0), unproven(lv.size(), 0);
  for (std::size_t i = 0; i < b.size(); ++i) {
    const auto l = static_cast<std::size_t>(std::find(lv.begin(), lv.end(), b.radii[i]) - lv.begin());
    if (l < lv.size()) tot[l] += 1, kept[l] += r.status[i] != Screen::screened, unproven[l] += r.status[i] == Screen::helly;
  }
  std::cout << file.string() << ": N = " << n << ", area " << r.area << " m^2, lambda " << r.lambda << ", lambda_eff " << r.lambda_eff
            << " (" << r.lambda_eff / r.lambda << " lambda)\n  kept by level:";
  for (std::size_t l = 0; l < lv.size(); ++l)
    std::cout << " " << lv[l] << ": " << kept[l] / tot[l] << " (" << unproven[l] << " without proof)";
  std::cout << "\n  witnessed " << r.witnessed << ", kept without proof " << r.helly << ", screened " << r.screened
            << ", mean competitors " << r.mean_competitors << "\n  seconds (median of " << repeats << "): " << median(secs)
            << "\n  cross-check: " << c.directions << " directions, winners screened " << c.winners_screened << ", distinct winners "
            << c.distinct_winners << ", kept never hit " << c.kept_never_hit << "\n";
  if (lv.size() != 2) return;
  const std::size_t top = lv[0] > lv[1] ? 0 : 1, small = 1 - top;
  const double drho = lv[top] - lv[small], lam_top = rd.fractions[top] * r.lambda;
  // Sphere calibration f(x): same lambda, R varied.
  std::vector<std::pair<double, double>> cal;
  if (calibrate) {
    for (double R : {1.0e-3, 1.5e-3, 2.0e-3, 3.0e-3, 4.5e-3, 6.0e-3, 9.0e-3}) {
      SphereParams p;
      p.radius = R;
      p.asperities = static_cast<std::uint64_t>(std::llround(r.lambda * 4 * std::numbers::pi * R * R));
      const RoughBody s = make_rough_sphere_body(p, rd, seed, 0);
      const auto qs = make_support_tree(s.centres, s.radii);
      const ScreeningResult rs = screen_sphere(s, *qs);
      double k = 0, t = 0;
      for (std::size_t i = 0; i < s.size(); ++i)
        if (s.radii[i] == lv[small]) t += 1, k += rs.status[i] != Screen::screened;
      cal.emplace_back(lam_top * drho * R, k / t);
      std::cout << "  sphere R = " << R << " m, N = " << p.asperities << ": x = " << cal.back().first << ", small kept " << cal.back().second
                << ", screen_sphere " << rs.seconds << " s\n";
    }
  }
  auto f = [&](double x) {
    if (cal.empty()) return std::numeric_limits<double>::quiet_NaN();
    if (x <= cal.front().first) return cal.front().second;
    for (std::size_t i = 1; i < cal.size(); ++i)
      if (x <= cal[i].first) {
        const double t = std::log(x / cal[i - 1].first) / std::log(cal[i].first / cal[i - 1].first);
        return cal[i - 1].second + t * (cal[i].second - cal[i - 1].second);
      }
    return std::numeric_limits<double>::quiet_NaN();  // beyond the calibration
  };
  // Bins of x (log, factor 1.5).
  std::vector<double> edges{0};
  for (double e = 0.05; e < 50; e *= 1.5) edges.push_back(e);
  edges.push_back(std::numeric_limits<double>::infinity());
  std::vector<double> bk(edges.size(), 0), bt(edges.size(), 0), bx(edges.size(), 0);
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.radii[i] != lv[small]) continue;
    const double K = superellipsoid_curvature(b.centres[i] + g, ax);
    const double x = K > 0 ? lam_top * drho / std::sqrt(K) : std::numeric_limits<double>::infinity();
    const auto j = static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), x) - edges.begin()) - 1;
    bt[j] += 1, bk[j] += r.status[i] != Screen::screened, bx[j] += std::isfinite(x) ? std::log(x) : 0;
  }
  std::cout << "  | x = lambda_top drho / sqrt(K) | small asperities | kept (body) | kept (sphere of same x) |\n  |---|---|---|---|\n";
  for (std::size_t j = 0; j + 1 < edges.size(); ++j) {
    if (bt[j] == 0) continue;
    const double xm = std::exp(bx[j] / bt[j]);
    const double se = std::sqrt(bk[j] / bt[j] * (1 - bk[j] / bt[j]) / bt[j]);
    std::cout << "  | " << edges[j] << " - " << edges[j + 1] << " | " << bt[j] << " | " << bk[j] / bt[j] << " +- " << se << " | "
              << f(xm) << " |\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"asperity experiments beyond the paper: unequal asperities, mesh bodies, bounces of bodies, PLY export"};
  app.require_subcommand(1);

  RadiiExperiment re;
  std::filesystem::path re_out = "asperity-radii";
  std::string levels = "1.3e-6:0.2,6.5e-7:0.8";
  bool no_plots = false;
  auto* radii = app.add_subcommand("radii", "screening, lambda_eff and the law of r_x with level radii");
  radii->add_option("--n", re.asperities, "asperities N");
  radii->add_option("--R", re.radius, "sphere radius [m]");
  radii->add_option("--levels", levels, "radius:fraction,... [m]");
  std::string lognormal;
  radii->add_option("--lognormal", lognormal, "median,sigma: lognormal radii (explicit bodies; instead of --levels)");
  radii->add_option("--drops", re.drops, "fresh drops");
  radii->add_option("--bodies", re.screen_bodies, "explicit spheres screened for lambda_eff");
  radii->add_option("--directions", re.screen_directions, "random directions of the screening cross-check per body");
  radii->add_option("--seed", re.seed, "seed");
  radii->add_option("--out", re_out, "output directory");
  radii->add_flag("--no-plots", no_plots, "no PNG figures");

  MeshImpactExperiment me;
  std::filesystem::path me_out = "asperity-mesh";
  std::string mesh_levels, smooth;
  double mesh_radius = 6.5e-7, omega_x = 0.2;
  bool mesh_no_plots = false;
  auto* mesh = app.add_subcommand("mesh", "single impacts of a rough mesh body with its full inertia tensor");
  mesh->add_option("--mesh", me.mesh, "mesh file (OFF/PLY/STL/OBJ, metres)")->required();
  mesh->add_option("--smooth", smooth, "a,b,c[,m]: map centres onto |x/a|^m+|y/b|^m+|z/c|^m = 1 [m] (m = 2)");
  mesh->add_option("--n", me.asperities, "asperities per body");
  mesh->add_option("--radius", mesh_radius, "asperity radius [m]");
  mesh->add_option("--levels", mesh_levels, "radius:fraction,... [m] (instead of --radius)");
  mesh->add_option("--bodies", me.bodies, "explicit bodies");
  mesh->add_option("--drops", me.drops, "drops (multiple of bodies)");
  mesh->add_option("--speed", me.speed, "impact speed [m/s]");
  mesh->add_option("--omega-x", omega_x, "spin before [rad/s]");
  mesh->add_option("--seed", me.seed, "seed");
  mesh->add_option("--screen-bodies", me.screen_bodies, "unequal radii: bodies screened (screen_body)");
  mesh->add_option("--out", me_out, "output directory");
  mesh->add_flag("--no-plots", mesh_no_plots, "no PNG figures");

  std::filesystem::path ex_mesh, ex_out;
  std::string ex_style = "spheres", ex_smooth;
  std::uint64_t ex_n = 300, ex_seed = 1;
  double ex_radius = 5e-5, ex_inflate = 1.0;
  auto* exp = app.add_subcommand("export", "write a rough mesh body as PLY (MeshLab, ParaView)");
  exp->add_option("--mesh", ex_mesh, "mesh file")->required();
  exp->add_option("--out", ex_out, "PLY file")->required();
  exp->add_option("--n", ex_n, "asperities");
  exp->add_option("--radius", ex_radius, "asperity radius [m]");
  exp->add_option("--style", ex_style, "points | spheres");
  exp->add_option("--inflate", ex_inflate, "draw asperities this many times larger (visibility)");
  exp->add_option("--smooth", ex_smooth, "a,b,c: map centres onto this ellipsoid [m]");
  exp->add_option("--seed", ex_seed, "seed");

  MeshBounceExperiment be;
  std::filesystem::path be_out = "asperity-bounce";
  std::string b_smooth, b_omega = "0,0,0";
  double b_radius = 5e-7;
  bool b_no_plots = false;
  be.options.bounce.variants = {BounceVariant::dynamic};
  be.options.bounce.sequences = 1000;
  be.options.bounce.speed = 1.0;
  be.options.bounce.stop_speed = 0.1;
  be.mesh.clear();
  auto* bounce = app.add_subcommand("bounce", "bounce sequences of a rough body (mesh, or sphere without --mesh)");
  bounce->add_option("--mesh", be.mesh, "mesh file (OFF/PLY/STL/OBJ, metres); absent: a rough sphere of radius --R");
  bounce->add_option("--smooth", b_smooth, "a,b,c[,m]: map centres onto |x/a|^m+|y/b|^m+|z/c|^m = 1 [m] (m = 2)");
  bounce->add_option("--R", be.sphere_radius, "sphere radius [m] (without --mesh)");
  bounce->add_option("--n", be.asperities, "asperities per body");
  bounce->add_option("--radius", b_radius, "asperity radius [m]");
  bounce->add_option("--bodies", be.bodies, "explicit bodies");
  bounce->add_option("--sequences", be.options.bounce.sequences, "sequences");
  bounce->add_option("--speed", be.options.bounce.speed, "first impact speed [m/s]");
  bounce->add_option("--stop-speed", be.options.bounce.stop_speed, "stop below this approach speed [m/s]");
  bounce->add_option("--omega", b_omega, "wx,wy,wz: spin at the first impact [rad/s]");
  bounce->add_option("--eps-t", be.options.bounce.eps_t, "tangential restitution");
  bounce->add_option("--bootstrap", be.options.bounce.bootstrap, "bootstrap replicates of the Eq. 2 fits");
  bounce->add_option("--threads", be.threads, "threads (0: OpenMP default)");
  bounce->add_option("--seed", be.seed, "seed");
  bounce->add_option("--out", be_out, "output directory");
  bounce->add_flag("--no-plots", b_no_plots, "no PNG figures");

  std::filesystem::path sc_mesh;
  std::string sc_smooth, sc_levels = "1.3e-6:0.2,6.5e-7:0.8";
  std::uint64_t sc_n = 100000, sc_dirs = 400000, sc_seed = 1;
  int sc_repeats = 3;
  bool sc_cal = false;
  auto* scr = app.add_subcommand("screen", "screening of a smooth mesh body (screen_body): kept per level, timing, curvature");
  scr->add_option("--mesh", sc_mesh, "mesh file")->required();
  scr->add_option("--smooth", sc_smooth, "a,b,c[,m] [m]")->required();
  scr->add_option("--n", sc_n, "asperities");
  scr->add_option("--levels", sc_levels, "radius:fraction,... [m]");
  scr->add_option("--repeats", sc_repeats, "timing repeats (median)");
  scr->add_option("--directions", sc_dirs, "random directions of the cross-check");
  scr->add_option("--seed", sc_seed, "seed");
  scr->add_flag("--calibrate", sc_cal, "screen spheres of the same lambda (several R) to predict the curvature dependence");

  std::vector<std::uint64_t> sb_n{10000, 100000, 1000000};
  std::uint64_t sb_queries = 20000;
  int sb_repeats = 5;
  auto* sbench = app.add_subcommand("support-bench", "time the exact support query (tree vs brute), medians");
  sbench->add_option("--n", sb_n, "asperity counts");
  sbench->add_option("--queries", sb_queries, "queries per repeat");
  sbench->add_option("--repeats", sb_repeats, "repeats (median reported)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (*radii) {
      if (lognormal.empty()) {
        re.radii = parse_levels(levels);
      } else {
        const auto v = parse_list(lognormal, "--lognormal");
        if (v.size() != 2) throw std::invalid_argument("--lognormal needs median,sigma, got '" + lognormal + "'");
        re.radii = RadiusDistribution::lognormal(v[0], v[1]);
      }
      re.plots = !no_plots;
      RadiiReport r = run_radii_experiment(re);
      std::filesystem::create_directories(re_out);
      if (re.plots) r.plots = write_figures(re_out, r.figures);
      std::cout << format_table(r);
      write_driver_report(re_out, "radii", to_json(r), format_table(r));
      return 0;
    }
    if (*mesh) {
      if (!smooth.empty()) me.smooth_ellipsoid = parse_list(smooth, "--smooth");
      me.radii = mesh_levels.empty() ? RadiusDistribution::fixed(mesh_radius) : parse_levels(mesh_levels);
      me.omega = Vec3(omega_x, 0, 0);
      me.plots = !mesh_no_plots;
      MeshImpactReport r = run_mesh_impacts(me, read_mesh(me.mesh, me.scale));
      std::filesystem::create_directories(me_out);
      if (me.plots) r.plots = write_figures(me_out, r.figures);
      std::cout << format_table(r);
      write_driver_report(me_out, "mesh", to_json(r), format_table(r));
      return 0;
    }
    if (*bounce) {
      if (!b_smooth.empty()) be.smooth = parse_list(b_smooth, "--smooth");
      const auto w = parse_list(b_omega, "--omega");
      if (w.size() != 3) throw std::invalid_argument("--omega needs wx,wy,wz, got '" + b_omega + "'");
      be.options.bounce.omega = Vec3(w[0], w[1], w[2]);
      be.radii = RadiusDistribution::fixed(b_radius);
      be.plots = !b_no_plots;
      const std::optional<TriangleMesh> base =
          be.mesh.empty() ? std::nullopt : std::optional<TriangleMesh>(read_mesh(be.mesh, be.scale));
      MeshBounceReport r = run_mesh_bounces(
          be, base ? &*base : nullptr, [](std::uint64_t done, std::uint64_t n) { std::cerr << "\r  sequences " << done << " / " << n << std::flush; });
      std::cerr << "\n";
      std::filesystem::create_directories(be_out);
      if (be.plots) r.plots = write_mesh_bounce_plots(be_out, r);
      std::cout << format_table(r);
      write_driver_report(be_out, "bounce", to_json(r), format_table(r));
      return 0;
    }
    if (*scr) {
      const auto ax = parse_list(sc_smooth, "--smooth");
      if (ax.size() != 3 && ax.size() != 4) throw std::invalid_argument("--smooth needs a,b,c[,m]");
      screen_run(sc_mesh, ax, sc_n, parse_levels(sc_levels), std::max(1, sc_repeats), sc_dirs, sc_cal, sc_seed);
      return 0;
    }
    if (*sbench) {
      support_bench(sb_n, sb_queries, sb_repeats);
      return 0;
    }
    if (*exp) {
      if (ex_style != "points" && ex_style != "spheres")
        throw std::invalid_argument("--style must be points or spheres, got '" + ex_style + "'");
      const TriangleMesh m = read_mesh(ex_mesh);
      SurfaceMap onto;
      if (!ex_smooth.empty()) {
        const auto ax = parse_list(ex_smooth, "--smooth");
        if (ax.size() != 3 && ax.size() != 4)
          throw std::invalid_argument("--smooth needs a,b,c[,m], got " + std::to_string(ax.size()) + " numbers");
        onto = smooth_surface(ax);
      }
      const RoughBody b = make_rough_mesh_body(m, ex_n, RadiusDistribution::fixed(ex_radius), 1000, ex_seed, 0, onto,
                                               ex_mesh.stem().string());
      write_ply(ex_out, b, ex_style == "points" ? PlyStyle::points : PlyStyle::spheres, ex_inflate, &m,
                -mass_properties(m, 1000).centroid);
      std::cout << "wrote " << ex_out.string() << ": " << b.size() << " asperities of " << ex_mesh.string() << "\n";
      return 0;
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
