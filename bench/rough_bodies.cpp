// Driver for the experiments beyond the paper (body_experiments.hpp): unequal asperity radii on a
// sphere, rough mesh bodies, and PLY export. Exit status 2 with a clear message on bad input.
//
//   rough_bodies radii  [--n 100000] [--R 3e-3] [--levels 1.3e-6:0.2,6.5e-7:0.8] [--drops 100000]
//                       [--bodies 2] [--seed 1] [--out DIR] [--no-plots]
#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "asperity/body_experiments.hpp"

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"asperity experiments beyond the paper: unequal asperities, mesh bodies, PLY export"};
  app.require_subcommand(1);

  RadiiExperiment re;
  std::string levels = "1.3e-6:0.2,6.5e-7:0.8";
  bool no_plots = false;
  auto* radii = app.add_subcommand("radii", "screening, lambda_eff and the law of r_x with level radii");
  radii->add_option("--n", re.asperities, "asperities N");
  radii->add_option("--R", re.radius, "sphere radius [m]");
  radii->add_option("--levels", levels, "radius:fraction,... [m]");
  radii->add_option("--drops", re.drops, "fresh drops");
  radii->add_option("--bodies", re.screen_bodies, "explicit spheres screened for lambda_eff");
  radii->add_option("--directions", re.screen_directions, "random directions of the screening cross-check per body");
  radii->add_option("--seed", re.seed, "seed");
  radii->add_option("--out", re.out, "output directory");
  radii->add_flag("--no-plots", no_plots, "no PNG figures");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (*radii) {
      re.radii = parse_levels(levels);
      re.plots = !no_plots;
      const RadiiReport r = run_radii_experiment(re);
      std::cout << format_table(r);
      return 0;
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
