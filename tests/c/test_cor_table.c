/* SPDX-License-Identifier: GPL-3.0-or-later */
/* A DEM code's view of a restitution table: this file is built against include/asperity/cor_table.h
 * alone (C99, no asperity library linked). Without arguments it checks the sampler on a small table
 * written here; with a path it also loads that table (one asperity wrote) and checks its shape. */
#include "asperity/cor_table.h"

#include <math.h>
#include <stdio.h>

static int failures = 0;
#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                     \
    }                                                                 \
  } while (0)
#define NEAR(a, b) CHECK(fabs((a) - (b)) < 1e-12)

static const char *kTable =
    "# asperity-cor-table format=1\n"
    "# a hand-made table: eps = 0.9 - 0.1 speed + 0.2 (p - 0.5) at speeds 1 and 2\n"
    "speed_m_s,p=0,p=0.5,p=1\n"
    "1,0.7,0.8,0.9\n"
    "2,0.6,0.7,0.8\n";

/* Format 2: spins -1 and 1, speeds 1 and 2, two eps bands with their Omega'_x quantiles.
 * eps = 0.8 + 0.05 spin - 0.1 (speed - 1) + 0.2 (p - 0.5); omega rows: band b at p -> 10 b + p. */
static const char *kTable2 =
    "# asperity-cor-table format=2\n"
    "spin_rad_s,speed_m_s,row,p=0,p=0.5,p=1\n"
    "-1,1,eps,0.65,0.75,0.85\n"
    "-1,1,omega_x:0,0,0.5,1\n"
    "-1,1,omega_x:1,10,10.5,11\n"
    "-1,2,eps,0.55,0.65,0.75\n"
    "-1,2,omega_x:0,0,0.5,1\n"
    "-1,2,omega_x:1,10,10.5,11\n"
    "1,1,eps,0.75,0.85,0.95\n"
    "1,1,omega_x:0,0,0.5,1\n"
    "1,1,omega_x:1,10,10.5,11\n"
    "1,2,eps,0.65,0.75,0.85\n"
    "1,2,omega_x:0,0,0.5,1\n"
    "1,2,omega_x:1,10,10.5,11\n";

static void check_format2(void) {
  asperity_cor_table t;
  char err[200] = "";
  CHECK(asperity_cor_parse(&t, kTable2, err, sizeof err) == 0);
  if (err[0]) fprintf(stderr, "format 2: %s\n", err);
  CHECK(t.format == 2 && t.n_spins == 2 && t.n_speeds == 2 && t.n_probs == 3 && t.n_bands == 2);
  NEAR(asperity_cor_sample_spin(&t, -1.0, 1.0, 0.5), 0.75);
  NEAR(asperity_cor_sample_spin(&t, 1.0, 2.0, 1.0), 0.85);
  NEAR(asperity_cor_sample_spin(&t, 0.0, 1.5, 0.25), 0.8 - 0.05 - 0.05);  /* trilinear, exact for this linear law */
  NEAR(asperity_cor_sample_spin(&t, 5.0, 9.0, 0.5), 0.75);                /* clamped to spin 1, speed 2 */
  NEAR(asperity_cor_sample(&t, 1.0, 0.5), 0.75);                           /* the first spin */
  NEAR(asperity_cor_sample_omega(&t, 0.3, 1.7, 0.2, 0.5), 0.5);            /* band 0 */
  NEAR(asperity_cor_sample_omega(&t, 0.3, 1.7, 0.7, 0.25), 10.25);         /* band 1 */
  NEAR(asperity_cor_sample_omega(&t, 0.3, 1.7, 1.0, 1.0), 11.0);           /* u = 1: the last band */
  asperity_cor_free(&t);
  CHECK(asperity_cor_parse(&t, kTable, err, sizeof err) == 0);
  CHECK(t.format == 1 && t.n_spins == 1 && t.n_bands == 0);
  CHECK(isnan(asperity_cor_sample_omega(&t, 0.0, 1.0, 0.5, 0.5)));          /* format 1 has no omega rows */
  asperity_cor_free(&t);
}

static void check_refused(const char *text, const char *what) {
  asperity_cor_table t;
  char err[200] = "";
  int r = asperity_cor_parse(&t, text, err, sizeof err);
  CHECK(r == -1);
  CHECK(err[0] != '\0');
  CHECK(t.eps == NULL && t.n_speeds == 0);
  if (r != -1) fprintf(stderr, "accepted: %s\n", what);
}

int main(int argc, char **argv) {
  asperity_cor_table t;
  char err[200] = "";
  double u, s, prev;
  CHECK(asperity_cor_parse(&t, kTable, err, sizeof err) == 0);
  CHECK(t.n_speeds == 2 && t.n_probs == 3);
  /* nodes */
  NEAR(asperity_cor_sample(&t, 1.0, 0.0), 0.7);
  NEAR(asperity_cor_sample(&t, 1.0, 0.5), 0.8);
  NEAR(asperity_cor_sample(&t, 2.0, 1.0), 0.8);
  /* bilinear between nodes */
  NEAR(asperity_cor_sample(&t, 1.5, 0.25), 0.5 * (0.75 + 0.65));
  NEAR(asperity_cor_sample(&t, 1.25, 0.75), 0.75 * 0.85 + 0.25 * 0.75);
  /* clamped outside the grid, u clamped to [0, 1] */
  NEAR(asperity_cor_sample(&t, 0.1, 0.5), 0.8);
  NEAR(asperity_cor_sample(&t, 50.0, 0.5), 0.7);
  NEAR(asperity_cor_sample(&t, 1.0, -3.0), 0.7);
  NEAR(asperity_cor_sample(&t, 1.0, 7.0), 0.9);
  NEAR(asperity_cor_sample(&t, 1.0, NAN), 0.7);
  asperity_cor_free(&t);

  check_refused("speed_m_s,p=0,p=1\n1,0.5,0.6\n", "no format line");
  check_refused("# asperity-cor-table format=3\nspeed_m_s,p=0,p=1\n1,0.5,0.6\n", "format 3");
  check_refused("# asperity-cor-table format=2\nspeed_m_s,p=0,p=1\n1,0.5,0.6\n", "format 2 with a format-1 header");
#define F2 "# asperity-cor-table format=2\nspin_rad_s,speed_m_s,row,p=0,p=1\n"
  check_refused(F2 "1,1,eps,0.5,0.6\n0,1,eps,0.5,0.6\n", "descending spins");
  check_refused(F2 "0,1,eps,0.5,0.6\n0,2,eps,0.5,0.6\n1,1,eps,0.5,0.6\n", "a spin without all speeds");
  check_refused(F2 "0,1,eps,0.5,0.6\n1,2,eps,0.5,0.6\n", "different speeds per spin");
  check_refused(F2 "0,1,omega_x:0,0,1\n", "omega row before its eps row");
  check_refused(F2 "0,1,eps,0.5,0.6\n0,1,omega_x:1,0,1\n", "band numbering");
  check_refused(F2 "0,1,eps,0.5,0.6\n0,1,omega_x:0,0,1\n0,2,eps,0.5,0.6\n", "a block without its bands");
  check_refused(F2 "0,1,eps,0.5,0.6\n0,2,omega_x:0,0,1\n", "omega row of another speed");
  check_refused(F2 "0,1,omega,0.5,0.6\n", "unknown row kind");
  check_refused(F2 "0,1,eps,0.6,0.5\n", "decreasing quantiles");
  check_format2();
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=0.5\n1,0.5,0.6\n", "grid not ending at 1");
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=1\n1,0.5\n", "short row");
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=1\n1,0.5,0.6,0.7\n", "long row");
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=1\n1,0.6,0.5\n", "decreasing quantiles");
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=1\n2,0.5,0.6\n1,0.5,0.6\n", "descending speeds");
  check_refused("# asperity-cor-table format=1\nspeed_m_s,p=0,p=1\n", "no rows");
  CHECK(asperity_cor_load(&t, "/nonexistent/table.csv", err, sizeof err) == -1);

  if (argc > 1) {
    if (asperity_cor_load(&t, argv[1], err, sizeof err) != 0) {
      fprintf(stderr, "%s: %s\n", argv[1], err);
      return 1;
    }
    CHECK(t.n_speeds >= 1 && t.n_probs >= 2);
    for (s = t.speeds[0] * 0.5; s < t.speeds[t.n_speeds - 1] * 2.0; s *= 1.1) {
      prev = -1e300;
      for (u = 0.0; u <= 1.0; u += 1.0 / 1024.0) {
        double e = asperity_cor_sample(&t, s, u);
        CHECK(e == e && e >= prev);
        CHECK(e > 0.0 && e < 1.5);
        prev = e;
      }
    }
    printf("%s: %d speeds x %d probabilities; eps(%g m/s, u = 0.5) = %.6f\n", argv[1], t.n_speeds, t.n_probs,
           t.speeds[0], asperity_cor_sample(&t, t.speeds[0], 0.5));
    asperity_cor_free(&t);
  }
  if (failures) fprintf(stderr, "%d checks failed\n", failures);
  return failures != 0;
}
