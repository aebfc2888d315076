/* SPDX-License-Identifier: GPL-3.0-or-later */
/* A DEM code's view of a restitution table: this file is built against include/asperity/cor_table.h
 * alone (C99, no asperity library linked). Without arguments it checks the sampler on a small table
 * written here; with a path it also loads that table (one asperity wrote) and checks its shape. */
/* A smaller bound than the default 1 GiB, so that the test can write a file over it. */
#define ASPERITY_COR_MAX_BYTES 65536L
#include "asperity/cor_table.h"

#include <math.h>
#include <stdio.h>

#include "check.h"
#define NEAR(a, b) CHECK(fabs((a) - (b)) < 1e-12)

static const char *kTable =
    "# asperity-cor-table format=1 speeds=2 probabilities=3\n"
    "# a hand-made table: eps = 0.9 - 0.1 speed + 0.2 (p - 0.5) at speeds 1 and 2\n"
    "speed_m_s,p=0,p=0.5,p=1\n"
    "1,0.7,0.8,0.9\n"
    "2,0.6,0.7,0.8\n";

/* Format 2: spins -1 and 1, speeds 1 and 2, two eps bands with their Omega'_x quantiles.
 * eps = 0.8 + 0.05 spin - 0.1 (speed - 1) + 0.2 (p - 0.5); omega rows: band b at p -> 10 b + p. */
static const char *kTable2 =
    "# asperity-cor-table format=2 spins=2 speeds=2 probabilities=3 bands=2\n"
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

/* ---- Malformed tables: each must be refused, with a message naming its line (0: no line) and
 * holding `what`. Every case is a valid table with one defect. ---- */
#define H1 "# asperity-cor-table format=1 speeds=2 probabilities=3\n"
#define C1 "speed_m_s,p=0,p=0.5,p=1\n"
#define R1 "1,0.7,0.8,0.9\n"
#define R2 "2,0.6,0.7,0.8\n"
#define H2 "# asperity-cor-table format=2 spins=2 speeds=2 probabilities=2 bands=1\nspin_rad_s,speed_m_s,row,p=0,p=1\n"
#define B(spin, speed) spin "," speed ",eps,0.5,0.6\n" spin "," speed ",omega_x:0,-1,1\n"
typedef struct {
  const char *text;
  long line;
  const char *what;
} bad_table;
static const bad_table kBad[] = {
    /* separators and numbers */
    {H1 C1 "1,0.7,0.8,\n0.9\n" R2, 3, "empty value"},           /* the last value is not taken from the next line */
    {H1 C1 "1,0.7,0.8,0.9,\n" R2, 3, "more values"},
    {H1 C1 "1,0.7,,0.9\n" R2, 3, "empty value"},
    {H1 C1 "1,0.7,0.8x,0.9\n" R2, 3, "trailing characters"},
    {H1 C1 "1,0.7,0.8,0.9 \n" R2, 3, "trailing characters"},
    {H1 C1 "1,x0.7,0.8,0.9\n" R2, 3, "not a plain decimal"},
    {H1 C1 "1, 0.7,0.8,0.9\n" R2, 3, "not a plain decimal"},
    {H1 C1 "1,0x1p-1,0.8,0.9\n" R2, 3, "trailing characters"},    /* hex float: strtod would read 0.5 */
    {H1 C1 "0x1p0,0.7,0.8,0.9\n" R2, 3, "trailing characters"},
    {H1 C1 "1,0.7,0.8,inf\n" R2, 3, "not a plain decimal"},
    {H1 C1 "1,nan,0.8,0.9\n" R2, 3, "not a plain decimal"},
    {H1 C1 "1,0.7,0.8,1e999\n" R2, 3, "overflows"},
    {H1 C1 "1,1e-999,0.8,0.9\n" R2, 3, "underflows"},
    {H1 C1 "1,0.7,0.8,0.9e\n" R2, 3, "exponent without digits"},
    {H1 C1 "1,0.7,0.8,.\n" R2, 3, "not a plain decimal"},
    {H1 C1 "1,0.7,0.8,00000000000000000000000000000000000000000000000000000000000000000000.9\n" R2, 3, "longer than 64"},
    {H1 "speed_m_s,p=0,p=0.5x,p=1\n" R1 R2, 2, "trailing characters"},
    /* line 1: keys and values */
    {"# asperity-cor-table format=1abc speeds=2 probabilities=3\n" C1 R1 R2, 1, "not an unsigned decimal integer"},
    {"# asperity-cor-table format=01 speeds=2 probabilities=3\n" C1 R1 R2, 1, "leading zero"},
    {"# asperity-cor-table format=3 speeds=2 probabilities=3\n" C1 R1 R2, 1, "unsupported table format"},
    {"# asperity-cor-table format=1\n" C1 R1 R2, 1, "lack the counts"},
    {"# asperity-cor-table format=1 probabilities=3 speeds=2\n" C1 R1 R2, 1, "must read"},
    {"# asperity-cor-table format=1 speeds=2 probabilities=3 bands=0\n" C1 R1 R2, 1, "unexpected text"},
    {"# asperity-cor-table format=1 speeds=2 probabilities=3 \n" C1 R1 R2, 1, "ends in a space"},
    {"# asperity-cor-table format=1  speeds=2 probabilities=3\n" C1 R1 R2, 1, "must read"},
    {"# asperity-cor-table format=1 speeds= probabilities=3\n" C1 R1 R2, 1, "empty"},
    {"# asperity-cor-table format=1 speeds=-2 probabilities=3\n" C1 R1 R2, 1, "not an unsigned decimal integer"},
    {"# asperity-cor-table format=1 speeds=0 probabilities=3\n" C1 R1 R2, 1, "out of range"},
    {"# asperity-cor-table format=1 speeds=2 probabilities=99999999999999999999\n" C1 R1 R2, 1, "out of range"},
    {"# asperity-cor-table format=1 speeds=2e0 probabilities=3\n" C1 R1 R2, 1, "not an unsigned decimal integer"},
    {"# asperity-cor-table format=2 speeds=2 probabilities=3\n" C1 R1 R2, 1, "must read"},
    {"# asperity-cor-table format=1 speeds=2000 probabilities=3\n" C1 R1 R2, 1, "more values than the text holds"},
    {"#asperity-cor-table format=1 speeds=2 probabilities=3\n" C1 R1 R2, 1, "not an asperity restitution table"},
    {C1 R1 R2, 1, "not an asperity restitution table"},
    /* counts: rows and blocks against line 1 */
    {H1 C1 R1, 4, "ends early"},                                           /* one row missing */
    {H1 C1 R1 R2 "3,0.5,0.6,0.7\n", 5, "more data rows"},                  /* one row too many */
    {H1 C1 R1 "2,0.6,0.7,0.8", 4, "does not end in a line end"},           /* cut inside the last row */
    {H1 "speed_m_s,p=0,p=1\n1,0.7,0.9\n2,0.6,0.8\n", 2, "fewer p= columns"},
    {H1 "speed_m_s,p=0,p=0.5,p=0.7,p=1\n" R1 R2, 2, "more p= columns"},
    {H1 C1 "1,0.7,0.8\n" R2, 3, "fewer values"},
    {H1 C1 "1,0.7,0.8,0.9,1\n" R2, 3, "more values"},
    {H1 C1 "1\n" R2, 3, "fewer values"},
    {H2 B("0", "1") B("0", "2") B("1", "1"), 9, "ends early"},             /* one block missing */
    {H2 B("0", "1") B("0", "2") B("1", "1") "1,2,eps,0.5,0.6\n", 10, "ends early"}, /* its band row missing */
    {H2 B("0", "1") B("0", "2") B("1", "1") B("1", "2") B("2", "1"), 11, "more data rows"},
    {H2 B("0", "1") B("1", "1") B("1", "2"), 5, "spin differs"},           /* spin 0 lacks speed 2 */
    {H2 B("0", "1") "0,1,omega_x:1,-1,1\n" B("0", "2") B("1", "1") B("1", "2"), 5, "expected the eps row"},
    {H2 "0,1,eps,0.5,0.6\n0,1,omega_x:1,-1,1\n" B("0", "2") B("1", "1") B("1", "2"), 4, "expected the next omega_x"},
    {H2 "0,1,eps,0.5,0.6\n" B("0", "2") B("1", "1") B("1", "2"), 4, "expected the next omega_x"},
    {H2 B("0", "1") B("0", "2") B("1", "1") B("1", "3"), 9, "same speeds"},
    {H2 B("1", "1") B("1", "2") B("0", "1") B("0", "2"), 7, "spins must ascend"},
    {H2 "0,1,omega,0.5,0.6\n", 3, "expected the eps row"},
    {"# asperity-cor-table format=2 spins=2 speeds=2 probabilities=2 bands=1\nspeed_m_s,p=0,p=1\n", 2, "spin_rad_s"},
    {"# asperity-cor-table format=1 speeds=2 probabilities=3\nspin_rad_s,speed_m_s,row,p=0,p=0.5,p=1\n" R1 R2, 2, "speed_m_s"},
    /* values out of range */
    {H1 "speed_m_s,p=0,p=1.5,p=1\n" R1 R2, 2, "[0, 1]"},
    {H1 "speed_m_s,p=0,p=-0.5,p=1\n" R1 R2, 2, "[0, 1]"},
    {H1 "speed_m_s,p=0,p=0.5,p=0.5\n" R1 R2, 2, "ascend strictly"},
    {H1 "speed_m_s,p=0.1,p=0.5,p=1\n" R1 R2, 2, "from p=0 to p=1"},
    {H1 "speed_m_s,p=0,p=0.5,p=0.9\n" R1 R2, 2, "from p=0 to p=1"},
    {H1 "speed_m_s,q=0,p=0.5,p=1\n" R1 R2, 2, "not p=<probability>"},
    {H1 C1 "0,0.7,0.8,0.9\n" R2, 3, "(0, 1e8]"},
    {H1 C1 "-1,0.7,0.8,0.9\n" R2, 3, "(0, 1e8]"},
    {H1 C1 R1 "2e8,0.6,0.7,0.8\n", 4, "(0, 1e8]"},
    {H1 C1 R2 R1, 4, "ascend strictly"},
    {H1 C1 R1 "1,0.6,0.7,0.8\n", 4, "ascend strictly"},
    {H1 C1 "1,-0.1,0.8,0.9\n" R2, 3, "[0, 1000]"},
    {H1 C1 "1,0.7,0.8,1e4\n" R2, 3, "[0, 1000]"},
    {H1 C1 "1,0.7,0.9,0.8\n" R2, 3, "not decrease"},
    {H2 B("0", "1") B("0", "2") B("1e7", "1") B("1e7", "2"), 7, "[-1e6, 1e6]"},
    {H2 B("0", "1") B("0", "2") B("1", "1") "1,2,eps,0.5,0.6\n1,2,omega_x:0,-1,1e16\n", 10, "[-1e15, 1e15]"},
    {H2 B("0", "1") B("0", "2") B("1", "1") "1,2,eps,0.5,0.6\n1,2,omega_x:0,1,-1\n", 10, "not decrease"},
    /* nothing there */
    {"", 0, "empty text"},
    {H1, 0, "no column header"},
};

static int g_verbose = 0;

static void check_bad_tables(void) {
  size_t i;
  for (i = 0; i < sizeof kBad / sizeof kBad[0]; ++i) {
    asperity_cor_table t;
    char err[300] = "", want[32];
    const int r = asperity_cor_parse(&t, kBad[i].text, err, sizeof err);
    int ok = r == -1 && strstr(err, kBad[i].what) != NULL && t.eps == NULL && t.speeds == NULL && t.n_speeds == 0;
    if (kBad[i].line > 0) {
      snprintf(want, sizeof want, "line %ld: ", kBad[i].line);
      ok = ok && strncmp(err, want, strlen(want)) == 0;
    } else {
      ok = ok && strncmp(err, "line ", 5) != 0;
    }
    if (!ok) {
      fprintf(stderr, "malformed table %u (want line %ld, '%s'): returned %d, message '%s'\n", (unsigned)i,
              kBad[i].line, kBad[i].what, r, err);
      ++failures;
    } else if (g_verbose) {
      printf("refused %2u: %s\n", (unsigned)i, err);
    }
    if (r == 0) asperity_cor_free(&t);
  }
  printf("%u malformed tables refused, each naming its line\n", (unsigned)(sizeof kBad / sizeof kBad[0]));
}

/* A test that can fail: the same check passes a valid table through (it must not be refused). */
static void check_valid_variants(void) {
  asperity_cor_table t;
  char err[300] = "";
  const char *crlf = "# asperity-cor-table format=1 speeds=2 probabilities=3\r\nspeed_m_s,p=0,p=0.5,p=1\r\n"
                     "1,0.7,0.8,0.9\r\n2,0.6,0.7,0.8\r\n";
  const char *forms = "# asperity-cor-table format=1 speeds=2 probabilities=3\n\n# comment\nspeed_m_s,p=0,p=0.5,p=1.0\n"
                      "+1.0,.7,8e-1,0.90\n# between rows\n2E0,6.0E-1,0.7,0.8\n";
  CHECK(asperity_cor_parse(&t, crlf, err, sizeof err) == 0);
  if (err[0]) fprintf(stderr, "crlf: %s\n", err);
  NEAR(asperity_cor_sample(&t, 1.5, 0.25), 0.5 * (0.75 + 0.65));
  asperity_cor_free(&t);
  CHECK(asperity_cor_parse(&t, forms, err, sizeof err) == 0);
  if (err[0]) fprintf(stderr, "number forms: %s\n", err);
  NEAR(asperity_cor_sample(&t, 1.5, 0.25), 0.5 * (0.75 + 0.65));
  asperity_cor_free(&t);
}

/* Files: a written table loads; a NUL byte, a directory and a device are refused. */
static void check_files(void) {
  asperity_cor_table t;
  char err[300] = "";
  const char *path = "test_cor_table_c.tmp.csv";
  FILE *f = fopen(path, "wb");
  CHECK(f != NULL);
  if (!f) return;
  fputs(kTable, f);
  fclose(f);
  CHECK(asperity_cor_load(&t, path, err, sizeof err) == 0);
  if (err[0]) fprintf(stderr, "load: %s\n", err);
  NEAR(asperity_cor_sample(&t, 1.25, 0.75), 0.75 * 0.85 + 0.25 * 0.75);
  asperity_cor_free(&t);
  f = fopen(path, "wb");
  if (f) {
    fwrite(kTable, 1, 40, f);
    fputc('\0', f);
    fputs(kTable + 40, f);
    fclose(f);
  }
  CHECK(asperity_cor_load(&t, path, err, sizeof err) == -1 && strstr(err, "NUL byte") && strstr(err, path));
  remove(path);
  CHECK(asperity_cor_load(&t, "/nonexistent/table.csv", err, sizeof err) == -1 && strstr(err, "/nonexistent/table.csv"));
  /* Issue 33 item 8: sampling the table a failed load left empty is NAN, not a NULL dereference. */
  CHECK(isnan(asperity_cor_sample(&t, 1.0, 0.5)) && isnan(asperity_cor_sample_spin(&t, 0.0, 1.0, 0.5)));
  CHECK(isnan(asperity_cor_sample_omega(&t, 0.0, 1.0, 0.5, 0.5)) && isnan(asperity_cor_sample(NULL, 1.0, 0.5)));
#if defined(__unix__) || defined(__APPLE__)
  CHECK(asperity_cor_load(&t, ".", err, sizeof err) == -1 && strstr(err, "not a regular file"));
  CHECK(asperity_cor_load(&t, "/dev/zero", err, sizeof err) == -1 && strstr(err, "not a regular file"));
  CHECK(asperity_cor_load(&t, "/dev/null", err, sizeof err) == -1 && strstr(err, "not a regular file"));
  /* a FIFO with no writer: refused at once, not waited on */
  remove("test_cor_table_c.tmp.fifo");
  if (mkfifo("test_cor_table_c.tmp.fifo", 0600) == 0) {
    CHECK(asperity_cor_load(&t, "test_cor_table_c.tmp.fifo", err, sizeof err) == -1 && strstr(err, "not a regular file"));
    remove("test_cor_table_c.tmp.fifo");
  }
#endif
  /* a file of exactly the table but without its final line end: refused (a cut table) */
  f = fopen(path, "wb");
  if (f) {
    fwrite(kTable, 1, strlen(kTable) - 1, f);
    fclose(f);
  }
  CHECK(asperity_cor_load(&t, path, err, sizeof err) == -1 && strstr(err, "line 5: ") && strstr(err, "line end"));
  /* a valid table padded with comments past ASPERITY_COR_MAX_BYTES: refused before parsing */
  f = fopen(path, "wb");
  if (f) {
    int i;
    fputs(kTable, f);
    for (i = 0; i < 1200; ++i) /* 1200 x 58 bytes > 65536 */ fputs("# padding padding padding padding padding padding padding\n", f);
    fclose(f);
  }
  if (asperity_cor_load(&t, path, err, sizeof err) == 0) {
    asperity_cor_free(&t);
    CHECK(!"a file over ASPERITY_COR_MAX_BYTES was read");
  }
  CHECK(strstr(err, "larger than ASPERITY_COR_MAX_BYTES") != NULL);
  remove(path);
}

/* ---- Contact models: one two-body head-on impact integrated directly, the drawn eps recovered ----
 * The integrator is generic and independent of the header: classical RK4 in time on the physical
 * equation m x'' = F(x, x') (x: overlap), from x = 0, x' = v0, with a step h = t_c / n (t_c: the
 * contact's duration scale); a step that would end at x < 0 is retried at half the step (down to
 * 1e-13 t_c), so the contact's end x = 0 is hit to ~1e-13 t_c and the final x' is the rebound speed.
 * Hertz-Tsuji's force is not smooth at x = 0 (x^(1/4)): there RK4 converges only like h^(5/4)
 * (measured at eps = 0.5: error 1.8e-6, 3.2e-7, 5.7e-8, 1.0e-8 at n = 5e3, 2e4, 8e4, 3.2e5 steps per
 * t_c, a factor 5.6 = 4^1.25 per 4x). The test runs n = 60000 and 2n and requires them to agree to
 * 1e-7: for an error ~ C h^(5/4) the error of the 2n run is then below 1e-7 / (2^1.25 - 1) < 1e-7,
 * so the 1e-6 tolerance on eps is met with a margin of > 10 whatever C is. The linear model's
 * force is smooth: RK4's h^4 makes its error ~1e-14. */
typedef struct {
  int hertz;
  double m, k, damp; /* linear: F = -k x - damp x'; Hertz: F = -k x^1.5 - damp sqrt(m k) x^0.25 x' */
} impact_model;

static double impact_force(const impact_model *c, double x, double v) {
  if (x < 0.0) return 0.0; /* a stage beyond the contact's end (that step is then retried shorter) */
  if (!c->hertz) return -c->k * x - c->damp * v;
  return -c->k * pow(x, 1.5) - c->damp * sqrt(c->m * c->k) * pow(x, 0.25) * v;
}

static double impact_eps(const impact_model *c, double v0, double tc, long n) {
  double x = 0.0, v = v0, h = tc / (double)n;
  long steps = 0;
  while (steps++ < 100 * n) {
    const double k1x = v, k1v = impact_force(c, x, v) / c->m;
    const double k2x = v + 0.5 * h * k1v, k2v = impact_force(c, x + 0.5 * h * k1x, k2x) / c->m;
    const double k3x = v + 0.5 * h * k2v, k3v = impact_force(c, x + 0.5 * h * k2x, k3x) / c->m;
    const double k4x = v + h * k3v, k4v = impact_force(c, x + h * k3x, k4x) / c->m;
    const double x1 = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    const double v1 = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    if (x1 < 0.0 && steps > 1) {
      if (h < 1e-13 * tc) return -v / v0;
      h *= 0.5;
      continue;
    }
    x = x1, v = v1;
  }
  return NAN;
}

static void check_contact_models(void) {
  static const double eps_list[] = {0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 0.95, 0.99};
  const long n = 60000;
  double worst_lin = 0, worst_hz = 0, worst_ref = 0;
  size_t i;
  for (i = 0; i < sizeof eps_list / sizeof eps_list[0]; ++i) {
    const double eps = eps_list[i];
    /* linear: a 2 g particle pair, k = 1e5 N/m, v0 = 0.7 m/s; t_c = pi sqrt(m / k) */
    impact_model lin = {0, 2e-3, 1e5, 0.0};
    impact_model hz = {1, 1.3e-3, 4e8, 0.0};
    const double v0_lin = 0.7, v0_hz = 1.7;
    const double tc_lin = 3.14159265358979 * sqrt(lin.m / lin.k);
    const double tc_hz = 3.2 * pow(hz.m * hz.m / (hz.k * hz.k * v0_hz), 0.2);
    double e1, e2;
    lin.damp = asperity_cor_linear_gamma(eps, lin.k, lin.m);
    hz.damp = asperity_cor_tsuji_alpha(eps);
    e1 = impact_eps(&lin, v0_lin, tc_lin, n);
    e2 = impact_eps(&lin, v0_lin, tc_lin, 2 * n);
    CHECK(fabs(e2 - eps) < 1e-6 && fabs(e1 - e2) < 1e-7);
    worst_lin = fmax(worst_lin, fabs(e2 - eps));
    worst_ref = fmax(worst_ref, fabs(e1 - e2));
    e1 = impact_eps(&hz, v0_hz, tc_hz, n);
    e2 = impact_eps(&hz, v0_hz, tc_hz, 2 * n);
    CHECK(fabs(e2 - eps) < 1e-6 && fabs(e1 - e2) < 1e-7);
    if (!(fabs(e2 - eps) < 1e-6)) fprintf(stderr, "hertz-tsuji eps %g: integrated %.12f\n", eps, e2);
    worst_hz = fmax(worst_hz, fabs(e2 - eps));
    worst_ref = fmax(worst_ref, fabs(e1 - e2));
    /* the inverses, and the impact speed does not matter */
    CHECK(fabs(asperity_cor_linear_eps(lin.damp, lin.k, lin.m) - eps) < 1e-14);
    CHECK(fabs(asperity_cor_tsuji_eps(hz.damp) - eps) < 1e-14);
    CHECK(fabs(impact_eps(&hz, 0.01, 3.2 * pow(hz.m * hz.m / (hz.k * hz.k * 0.01), 0.2), n / 3) - eps) < 1e-6);
    /* a wrong conversion is caught by the same integration: 1 % more damping */
    lin.damp *= 1.01, hz.damp *= 1.01;
    CHECK(fabs(impact_eps(&lin, v0_lin, tc_lin, n / 3) - eps) > 1e-5);
    CHECK(fabs(impact_eps(&hz, v0_hz, tc_hz, n / 3) - eps) > 1e-5);
    /* a linear gamma used as a Hertz alpha is wrong too (the two relations differ) */
    hz.damp = asperity_cor_linear_gamma(eps, 1.0, 1.0);
    CHECK(fabs(impact_eps(&hz, v0_hz, tc_hz, n / 3) - eps) > 1e-3);
  }
  /* domains */
  CHECK(asperity_cor_linear_gamma(0.0, 4.0, 1.0) == 4.0 && asperity_cor_linear_gamma(1.0, 4.0, 1.0) == 0.0);
  CHECK(fabs(asperity_cor_tsuji_alpha(0.0) - sqrt(5.0)) < 1e-15 && asperity_cor_tsuji_eps(3.0) == 0.0);
  CHECK(asperity_cor_linear_eps(4.0, 4.0, 1.0) == 0.0);
  CHECK(isnan(asperity_cor_linear_gamma(1.01, 1, 1)) && isnan(asperity_cor_linear_gamma(-0.1, 1, 1)));
  CHECK(isnan(asperity_cor_linear_gamma(0.5, 0, 1)) && isnan(asperity_cor_linear_gamma(0.5, 1, -1)));
  CHECK(isnan(asperity_cor_linear_gamma(NAN, 1, 1)) && isnan(asperity_cor_tsuji_alpha(1.5)));
  CHECK(isnan(asperity_cor_tsuji_eps(-1.0)) && isnan(asperity_cor_linear_eps(-1.0, 1, 1)));
  printf("contact models: |eps integrated - eps drawn| <= %.1e (linear), %.1e (Hertz-Tsuji); "
         "n vs 2n steps differ by <= %.1e\n", worst_lin, worst_hz, worst_ref);
}

int main(int argc, char **argv) {
  asperity_cor_table t;
  char err[300] = "";
  double u, s, prev;
  g_verbose = getenv("COR_TABLE_VERBOSE") != NULL;
  CHECK(asperity_cor_parse(&t, kTable, err, sizeof err) == 0);
  if (err[0]) fprintf(stderr, "table: %s\n", err);
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

  check_format2();
  check_valid_variants();
  check_bad_tables();
  check_files();
  check_contact_models();

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
