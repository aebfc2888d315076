// Driver for the experiments beyond the paper (body_experiments.hpp): unequal asperity radii on a
// sphere, rough mesh bodies, and PLY export. Exit status 2 with a clear message on bad input.
//
//   rough_bodies radii  [--n 100000] [--R 3e-3] [--levels 1.3e-6:0.2,6.5e-7:0.8] [--drops 100000]
//                       [--bodies 2] [--seed 1] [--out DIR] [--no-plots]
//   rough_bodies mesh   --mesh meshes/ellipsoid.off [--smooth 4e-3,3e-3,2.25e-3[,m]] [--n 100000]
//                       [--radius 6.5e-7 | --levels ...] [--bodies 10] [--drops 100000] [--speed 1.3]
//                       [--omega-x 0.2] [--seed 1] [--out DIR] [--no-plots]
//   rough_bodies export --mesh meshes/rounded_cube.off --out body.ply [--n 300] [--radius 5e-5]
//                       [--style points|spheres] [--inflate 1] [--smooth a,b,c] [--seed 1]
#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "asperity/body_bounce.hpp"
#include "asperity/body_experiments.hpp"
#include "asperity/mesh.hpp"
#include "asperity/report.hpp"
#include "asperity/random.hpp"
#include "asperity/support.hpp"

#include <algorithm>
#include <chrono>
#include <memory>

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"asperity experiments beyond the paper: unequal asperities, mesh bodies, bounces of bodies, PLY export"};
  app.require_subcommand(1);

  RadiiExperiment re;
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
  radii->add_option("--out", re.out, "output directory");
  radii->add_flag("--no-plots", no_plots, "no PNG figures");

  MeshImpactExperiment me;
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
  mesh->add_option("--out", me.out, "output directory");
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
  bounce->add_option("--out", be.out, "output directory");
  bounce->add_flag("--no-plots", b_no_plots, "no PNG figures");

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
      const RadiiReport r = run_radii_experiment(re);
      std::cout << format_table(r);
      write_driver_report(re.out, "radii", to_json(r), format_table(r));
      return 0;
    }
    if (*mesh) {
      if (!smooth.empty()) me.smooth_ellipsoid = parse_list(smooth, "--smooth");
      me.radii = mesh_levels.empty() ? RadiusDistribution::fixed(mesh_radius) : parse_levels(mesh_levels);
      me.omega = Vec3(omega_x, 0, 0);
      me.plots = !mesh_no_plots;
      const MeshImpactReport r = run_mesh_impacts(me);
      std::cout << format_table(r);
      write_driver_report(me.out, "mesh", to_json(r), format_table(r));
      return 0;
    }
    if (*bounce) {
      if (!b_smooth.empty()) be.smooth = parse_list(b_smooth, "--smooth");
      const auto w = parse_list(b_omega, "--omega");
      if (w.size() != 3) throw std::invalid_argument("--omega needs wx,wy,wz, got '" + b_omega + "'");
      be.options.bounce.omega = Vec3(w[0], w[1], w[2]);
      be.radii = RadiusDistribution::fixed(b_radius);
      be.plots = !b_no_plots;
      const MeshBounceReport r = run_mesh_bounces(
          be, [](std::uint64_t done, std::uint64_t n) { std::cerr << "\r  sequences " << done << " / " << n << std::flush; });
      std::cerr << "\n";
      std::cout << format_table(r);
      write_driver_report(be.out, "bounce", to_json(r), format_table(r));
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
        onto = superellipsoid_surface(ax[0], ax[1], ax[2], ax.size() == 4 ? ax[3] : 2.0);
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
