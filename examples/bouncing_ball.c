/* SPDX-License-Identifier: MIT */
/* A DEM-style bouncing ball with restitution drawn from an asperity table, per contact.
 *
 * Copy this into a DEM code: it uses include/asperity/cor_table.h only (C99, MIT). A ball (mass m)
 * falls onto a fixed plate under gravity; the contact is a linear spring-dashpot, F = k d - gamma
 * d' (d the overlap, pushing the ball up), integrated with velocity Verlet at a fixed step, as
 * LAMMPS's fix nve does (the damping sees the half-step velocity). When a contact begins (the first
 * step with d > 0) the ball draws u once, takes eps = asperity_cor_sample(table, impact speed, u)
 * and sets THIS contact's gamma = asperity_cor_linear_gamma(eps, k, m); the contact keeps it until
 * it ends (d back to 0). The achieved restitution eps' = rebound speed / impact speed is printed
 * for every rebound. To collect 10^4 rebounds at one impact speed in well under a second, each
 * drop starts 1 um above the plate with the speed of a fall from `height` (the flight above that
 * gap is ballistic and not stepped).
 *
 *   cc -std=c99 -O2 -I include examples/bouncing_ball.c -lm -o bouncing_ball
 *   ./bouncing_ball table.csv [rebounds=10000] [height_m=0.05] [seed=1]
 *
 * Output: one line per rebound "eps_drawn eps_achieved", then a summary line starting with '#'.
 * tests/c/test_bouncing_ball.c includes this file (BOUNCING_BALL_NO_MAIN) and checks with a KS test
 * that the achieved eps follow the table's law at the impact speed, and that wrong conversions
 * fail that test. */
#include "asperity/cor_table.h"

#include <stdint.h>

typedef struct bouncing_ball {
  double m;      /* ball mass [kg] (the plate is fixed: the effective mass is m) */
  double k;      /* contact stiffness [N/m] */
  double g;      /* gravity [m/s^2] */
  double height; /* drop height [m] */
  double gap;    /* each drop starts this far above the plate [m] */
  double dt;     /* time step [s] */
} bouncing_ball;

/* The steel ball of the example: 2 mm radius, k = 1e7 N/m (contact time pi sqrt(m/k) = 16 us),
 * a fall from 5 cm (impact ~0.99 m/s), 1000 steps per contact time (the velocity-Verlet error in eps
 * is O(dt): the contact's start and end fall between steps). */
static bouncing_ball bouncing_ball_default(void) {
  bouncing_ball b;
  b.m = 7850.0 * 4.0 / 3.0 * 3.14159265358979 * 0.002 * 0.002 * 0.002;
  b.k = 1e7;
  b.g = 9.81;
  b.height = 0.05;
  b.gap = 1e-6;
  b.dt = 3.14159265358979 * sqrt(b.m / b.k) / 1000.0;
  return b;
}

/* The host's random stream (splitmix64): a uniform in [0, 1). */
static double bouncing_ball_uniform(uint64_t *state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* eps -> the dashpot's gamma for one contact; the example uses asperity_cor_linear_gamma. */
typedef double (*bouncing_ball_gamma)(double eps, double k, double m);

/* Runs n drops. Per drop i: speed[i] the impact speed the draw used, drawn[i] the eps drawn from the
 * table, achieved[i] the rebound speed / impact speed. Returns 0, or -1 if a contact did not end
 * (or a gamma was not finite). */
static int bouncing_ball_run(const bouncing_ball *b, const asperity_cor_table *table, long n, bouncing_ball_gamma gamma_of,
                             uint64_t seed, double *speed, double *drawn, double *achieved) {
  long i;
  for (i = 0; i < n; ++i) {
    /* state: z = height of the ball's lowest point above the plate, v = vertical velocity */
    double z = b->gap, v = -sqrt(2.0 * b->g * (b->height - b->gap)), gamma = 0.0, a, v_in = 0.0;
    int in_contact = 0;
    long step;
    a = -b->g;
    for (step = 0; step < 1000000; ++step) {
      double d;
      v += 0.5 * b->dt * a; /* velocity Verlet: half kick, drift, force, half kick */
      z += b->dt * v;
      d = -z;
      if (d > 0.0 && !in_contact) { /* a contact begins: draw its eps once, from its impact speed */
        const double u = bouncing_ball_uniform(&seed);
        in_contact = 1;
        v_in = -v;
        speed[i] = v_in;
        drawn[i] = asperity_cor_sample(table, v_in, u);
        gamma = gamma_of(drawn[i], b->k, b->m);
        if (!(gamma >= 0.0 && gamma < HUGE_VAL)) return -1;
      }
      if (d <= 0.0 && in_contact) { /* the contact ended: the ball leaves the plate */
        achieved[i] = v / v_in;
        break;
      }
      a = -b->g + (d > 0.0 ? (b->k * d - gamma * v) / b->m : 0.0);
      v += 0.5 * b->dt * a;
    }
    if (step == 1000000) return -1;
  }
  return 0;
}

#ifndef BOUNCING_BALL_NO_MAIN
int main(int argc, char **argv) {
  asperity_cor_table table;
  char err[300];
  bouncing_ball b = bouncing_ball_default();
  const long n = argc > 2 ? atol(argv[2]) : 10000;
  const uint64_t seed = argc > 4 ? (uint64_t)strtoull(argv[4], NULL, 10) : 1;
  double *speed, *drawn, *achieved, worst = 0.0, mean = 0.0;
  long i;
  if (argc < 2 || n < 1) {
    fprintf(stderr, "usage: %s table.csv [rebounds=10000] [height_m=0.05] [seed=1]\n", argv[0]);
    return 2;
  }
  if (argc > 3) b.height = atof(argv[3]);
  if (!(b.height > b.gap && b.height < 1e3)) {
    fprintf(stderr, "height must lie in (%g, 1000) m\n", b.gap);
    return 2;
  }
  if (asperity_cor_load(&table, argv[1], err, sizeof err) != 0) {
    fprintf(stderr, "%s\n", err);
    return 2;
  }
  speed = (double *)malloc((size_t)n * sizeof(double));
  drawn = (double *)malloc((size_t)n * sizeof(double));
  achieved = (double *)malloc((size_t)n * sizeof(double));
  if (!speed || !drawn || !achieved || bouncing_ball_run(&b, &table, n, asperity_cor_linear_gamma, seed, speed, drawn, achieved) != 0) {
    fprintf(stderr, "the simulation failed (out of memory, or eps outside [0, 1] in the table)\n");
    return 1;
  }
  for (i = 0; i < n; ++i) {
    printf("%.9f %.9f\n", drawn[i], achieved[i]);
    mean += achieved[i] / (double)n;
    if (fabs(achieved[i] - drawn[i]) > worst) worst = fabs(achieved[i] - drawn[i]);
  }
  printf("# %ld rebounds at %.6f m/s: mean achieved eps %.6f, max |achieved - drawn| %.2e (time step %.3g s)\n", n,
         speed[0], mean, worst, b.dt);
  free(speed), free(drawn), free(achieved);
  asperity_cor_free(&table);
  return 0;
}
#endif
