/* SPDX-License-Identifier: GPL-3.0-or-later */
/* examples/bouncing_ball.c, checked: its 10^4 rebounds, each with a gamma set per contact from an eps
 * drawn from a table, must reproduce the table's eps law at the impact speed; the same test must
 * reject the run when the conversion is wrong (gamma scaled by 1.1, or gamma computed from eps^2).
 *
 * The test: each achieved eps'_i is mapped through the table's own cdf at its impact speed,
 * w_i = F(eps'_i | speed_i), F inverted from asperity_cor_sample by bisection in u (the sampler is
 * nondecreasing in u, and strictly increasing for this table). If eps' follows the table's law the
 * w_i are uniform on [0, 1]: one-sample Kolmogorov-Smirnov against U(0, 1), n = 10^4, statistic
 * D_n = sup |F_n(w) - w|, p-value from the Kolmogorov distribution with Stephens' correction
 * Q((sqrt(n) + 0.12 + 0.11 / sqrt(n)) D_n) (Numerical Recipes 3rd ed. 14.3.3), level alpha = 0.01:
 * accept when p >= alpha. The seed (12345, fixed before the first run) makes the run deterministic;
 * the D of the drawn eps themselves is printed beside it: the two differ by the integrator's error
 * (velocity Verlet, 1000 steps per contact time; contact start and end fall between steps, O(dt)),
 * which is far below the sampling noise. Because drawn and achieved eps are paired, the test also
 * requires |achieved - drawn| < 2e-3 for every rebound, a check a wrong conversion fails by far. */
#define BOUNCING_BALL_NO_MAIN
#include "../../examples/bouncing_ball.c"

#include <time.h>

#include "check.h"

/* A skewed law with a sharp upper edge, like asperity's: eps(p) = top - w (1 - p)^2, with top and w
 * depending on the speed; the impact (~0.99 m/s) falls between the grid speeds 0.5 and 2. */
static const char *kTable =
    "# asperity-cor-table format=1 speeds=3 probabilities=11\n"
    "# eps = top - w (1 - p)^2; (top, w) = (0.95, 0.5), (0.9, 0.45), (0.8, 0.4) at 0.5, 2, 4 m/s\n"
    "speed_m_s,p=0,p=0.1,p=0.2,p=0.3,p=0.4,p=0.5,p=0.6,p=0.7,p=0.8,p=0.9,p=1\n"
    "0.5,0.45,0.545,0.63,0.705,0.77,0.825,0.87,0.905,0.93,0.945,0.95\n"
    "2,0.45,0.5355,0.612,0.6795,0.738,0.7875,0.828,0.8595,0.882,0.8955,0.9\n"
    "4,0.4,0.476,0.544,0.604,0.656,0.7,0.736,0.764,0.784,0.796,0.8\n";

static double cdf(const asperity_cor_table *t, double speed, double eps) {
  double lo = 0.0, hi = 1.0;
  int it;
  if (eps <= asperity_cor_sample(t, speed, 0.0)) return 0.0;
  if (eps >= asperity_cor_sample(t, speed, 1.0)) return 1.0;
  for (it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (asperity_cor_sample(t, speed, mid) < eps) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

static int by_value(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* Kolmogorov's Q(lambda) = 2 sum_{j>=1} (-1)^(j-1) exp(-2 j^2 lambda^2). */
static double kolmogorov_q(double lambda) {
  double sum = 0.0, sign = 1.0;
  int j;
  if (lambda < 0.2) return 1.0;
  for (j = 1; j <= 100; ++j) {
    const double term = sign * exp(-2.0 * j * j * lambda * lambda);
    sum += term;
    if (fabs(term) < 1e-16) break;
    sign = -sign;
  }
  return fmin(1.0, fmax(0.0, 2.0 * sum));
}

#define N_REBOUNDS 10000
static double g_worst;
static double g_speed[N_REBOUNDS], g_drawn[N_REBOUNDS], g_achieved[N_REBOUNDS], g_w[N_REBOUNDS];

/* Runs the example with a conversion; returns the KS p-value of the achieved eps against the table. */
static double run_and_test(const asperity_cor_table *t, bouncing_ball_gamma conversion, const char *name) {
  const bouncing_ball b = bouncing_ball_default();
  const double n = N_REBOUNDS, sq = sqrt(n);
  double d = 0.0, d_drawn = 0.0, p, worst = 0.0;
  long i;
  if (bouncing_ball_run(&b, t, N_REBOUNDS, conversion, 12345, g_speed, g_drawn, g_achieved) != 0) {
    fprintf(stderr, "%s: the simulation failed\n", name);
    ++failures;
    return -1.0;
  }
  for (i = 0; i < N_REBOUNDS; ++i) {
    g_w[i] = cdf(t, g_speed[i], g_achieved[i]);
    worst = fmax(worst, fabs(g_achieved[i] - g_drawn[i]));
  }
  qsort(g_w, N_REBOUNDS, sizeof(double), by_value);
  for (i = 0; i < N_REBOUNDS; ++i) d = fmax(d, fmax((i + 1) / n - g_w[i], g_w[i] - i / n));
  p = kolmogorov_q((sq + 0.12 + 0.11 / sq) * d);
  for (i = 0; i < N_REBOUNDS; ++i) g_w[i] = cdf(t, g_speed[i], g_drawn[i]);
  qsort(g_w, N_REBOUNDS, sizeof(double), by_value);
  for (i = 0; i < N_REBOUNDS; ++i) d_drawn = fmax(d_drawn, fmax((i + 1) / n - g_w[i], g_w[i] - i / n));
  printf("%-27s n = %d, impact %.6f m/s, D = %.5f, p = %.3g (alpha = 0.01: %s); drawn eps: D = %.5f; "
         "max |achieved - drawn| = %.2e\n", name, N_REBOUNDS, g_speed[0], d, p, p >= 0.01 ? "accepted" : "rejected",
         d_drawn, worst);
  g_worst = worst;
  return p;
}

static double gamma_scaled(double eps, double k, double m) { return 1.1 * asperity_cor_linear_gamma(eps, k, m); }
static double gamma_of_eps2(double eps, double k, double m) { return asperity_cor_linear_gamma(eps * eps, k, m); }
static double gamma_hertz(double eps, double k, double m) { return asperity_cor_tsuji_alpha(eps) * sqrt(m * k); }

int main(void) {
  asperity_cor_table t;
  char err[300] = "";
  const clock_t c0 = clock();
  if (asperity_cor_parse(&t, kTable, err, sizeof err) != 0) {
    fprintf(stderr, "table: %s\n", err);
    return 1;
  }
  CHECK(run_and_test(&t, asperity_cor_linear_gamma, "asperity_cor_linear_gamma") >= 0.01);
  CHECK(g_worst < 2e-3);
  /* the same tests reject wrong conversions */
  CHECK(run_and_test(&t, gamma_scaled, "1.1 x gamma") < 0.01 && g_worst > 2e-3);
  CHECK(run_and_test(&t, gamma_of_eps2, "gamma from eps^2") < 0.01 && g_worst > 2e-3);
  CHECK(run_and_test(&t, gamma_hertz, "Hertz-Tsuji alpha as gamma") < 0.01 && g_worst > 2e-3);
  asperity_cor_free(&t);
  printf("%.2f s CPU\n", (double)(clock() - c0) / CLOCKS_PER_SEC);
  if (failures) fprintf(stderr, "%d checks failed\n", failures);
  return failures != 0;
}
