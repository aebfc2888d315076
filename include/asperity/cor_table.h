/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. This header, and the table format it reads, are
 * MIT-licensed (the text is in LICENSE): unlike the rest of asperity (GPL-3.0-or-later), a DEM code
 * under any licence (GPL-2.0-only LAMMPS/LIGGGHTS, BSD) may include it. It depends on nothing but
 * the C standard library, so including it brings in no GPL code. */
/* asperity restitution tables for DEM codes: one self-contained C99 header, no dependencies beyond
 * the C standard library (README "Restitution tables"). Works from C and C++.
 *
 * A table (written by asperity.cor_table(...) in Python, outputs.cor_table in a scene, or
 * asperity::write_cor_table in C++) holds quantiles eps(speed_i, p_j) of the macroscopic restitution
 * coefficient of a rough sphere for a grid of impact speeds speed_i [m/s] and probabilities p_j in
 * [0, 1]; a format-2 table also has a grid of incoming spins Omega_x [rad/s] and, for bands of the
 * eps law, the quantiles of the spin after the impact Omega'_x. Sampling is inverse-cdf:
 *
 *     asperity_cor_table t;
 *     if (asperity_cor_load(&t, "steel.csv", err, sizeof err) != 0) { report err; }
 *     double eps = asperity_cor_sample(&t, speed, u);   // u: the host's own uniform in [0, 1]
 *     double eps2 = asperity_cor_sample_spin(&t, spin, speed, u);          // format 2: spin grid
 *     double w = asperity_cor_sample_omega(&t, spin, speed, u, u2);        // Omega'_x with that eps
 *     asperity_cor_free(&t);
 *
 * Interpolation is linear in each of spin, speed and p; spins and speeds outside the grid are
 * clamped to its ends (the law is not extrapolated), u is clamped to [0, 1]. For fixed spin and
 * speed eps is nondecreasing in u, so a u kept for the whole contact gives a consistent draw. Draw
 * u (and u2) ONCE when a contact begins and keep them (or eps) in the contact's history: a new draw
 * every time step would average the scatter away. asperity_cor_sample uses the first spin of a
 * format-2 table. asperity_cor_sample_omega draws Omega'_x jointly with the eps of the same u: from
 * the drops whose eps fell in the band of u (band b = floor(u * n_bands)), with its own uniform u2.
 *
 * CSV format 1: lines starting with '#' are comments (the first is "# asperity-cor-table format=1");
 * then a header "speed_m_s,p=<p_0>,...,p=<p_{P-1}>" and one row per speed "<speed>,<eps_0>,...".
 * CSV format 2: first line "# asperity-cor-table format=2"; header
 * "spin_rad_s,speed_m_s,row,p=<p_0>,...,p=<p_{P-1}>"; then, for each spin (ascending) and each speed
 * (ascending, the same speeds for every spin), a row "<spin>,<speed>,eps,<eps_0>,..." followed by
 * n_bands rows "<spin>,<speed>,omega_x:<b>,<q_0>,..." for b = 0..n_bands-1 (n_bands the same for
 * every block, possibly 0): quantiles of Omega'_x among the drops whose eps lies in the band
 * [b / n_bands, (b + 1) / n_bands) of that block's eps law. */
#ifndef ASPERITY_COR_TABLE_H
#define ASPERITY_COR_TABLE_H

#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct asperity_cor_table {
  int n_speeds;      /* speeds of the grid */
  int n_probs;       /* columns of quantiles */
  double *speeds;    /* [n_speeds], strictly ascending [m/s] */
  double *probs;     /* [n_probs], strictly ascending, probs[0] = 0, probs[n_probs-1] = 1 */
  double *eps;       /* [n_spins * n_speeds * n_probs]: eps[(k * n_speeds + i) * n_probs + j] */
  int format;        /* 1 or 2 */
  int n_spins;       /* 1 for format 1 (the spin in the table's comment and JSON header) */
  double *spins;     /* [n_spins], strictly ascending [rad/s]; format 1: one entry, 0 */
  int n_bands;       /* eps bands with Omega'_x quantiles; 0: none (always 0 in format 1) */
  double *omega;     /* [((k * n_speeds + i) * n_bands + b) * n_probs + j] */
} asperity_cor_table;

#define ASPERITY_COR_TABLE_FORMAT 2 /* the newest format this header reads (it reads 1 too) */

static inline void asperity_cor__error(char *err, size_t n, const char *what, long line) {
  if (err && n) {
    if (line > 0) snprintf(err, n, "line %ld: %s", line, what);
    else snprintf(err, n, "%s", what);
  }
}

static inline int asperity_cor__push(double **v, int *n, int *cap, double x) {
  if (*n == *cap) {
    int c = *cap ? 2 * *cap : 64;
    double *p = (double *)realloc(*v, (size_t)c * sizeof(double));
    if (!p) return -1;
    *v = p;
    *cap = c;
  }
  (*v)[(*n)++] = x;
  return 0;
}

/* Frees what asperity_cor_load allocated; the table is then empty. */
static inline void asperity_cor_free(asperity_cor_table *t) {
  if (!t) return;
  free(t->speeds);
  free(t->probs);
  free(t->eps);
  free(t->spins);
  free(t->omega);
  memset(t, 0, sizeof *t);
}

/* Parses "<x>," at *c (a number followed by a comma); returns 0 and advances *c, or -1. */
static inline int asperity_cor__key(const char **c, double *x) {
  char *e;
  *x = strtod(*c, &e);
  if (e == *c || *e != ',') return -1;
  *c = e + 1;
  return 0;
}

/* The n quantiles at c (",q0,q1,...": c points at the first comma), nondecreasing, up to the line's
 * end; pushed onto v. Returns NULL on success, else the problem. */
static inline const char *asperity_cor__values(const char *c, const char *line_end, int n, double **v, int *len,
                                               int *cap) {
  int j;
  char *e;
  double x, prev = 0.0;
  for (j = 0; j < n; ++j) {
    if (*c != ',') return "row has fewer values than the header";
    x = strtod(c + 1, &e);
    if (e == c + 1 || !isfinite(x) || (j > 0 && x < prev)) return "quantiles must be finite numbers, nondecreasing along a row";
    if (asperity_cor__push(v, len, cap, x)) return "out of memory";
    prev = x;
    c = e;
  }
  if (c < line_end && *c != '\r') return "row has more values than the header";
  return NULL;
}

/* The header's probability columns ",p=<p0>,...", from c to the line's end. */
static inline const char *asperity_cor__probs(asperity_cor_table *t, const char *c, const char *line_end, int *cap) {
  char *e;
  double p;
  while ((c = strchr(c, ',')) != NULL && c < line_end) {
    c += 1;
    if (strncmp(c, "p=", 2) != 0) return "header column is not p=<probability>";
    p = strtod(c + 2, &e);
    if (e == c + 2 || !(p >= 0.0 && p <= 1.0) || (t->n_probs > 0 && !(p > t->probs[t->n_probs - 1])))
      return "probabilities must ascend strictly within [0, 1]";
    if (asperity_cor__push(&t->probs, &t->n_probs, cap, p)) return "out of memory";
  }
  if (t->n_probs < 2 || t->probs[0] != 0.0 || t->probs[t->n_probs - 1] != 1.0)
    return "the probability grid must run from p=0 to p=1";
  return NULL;
}

/* Parser state of the grid blocks of a format-2 table. */
typedef struct asperity_cor__grid {
  int cap_s, cap_k, cap_e, cap_o, n_e, n_o;
  int block_speed;   /* index of the current block's speed in speeds */
  int block_bands;   /* omega rows seen in the current block */
  int bands_known;   /* n_bands is fixed (after the first block) */
} asperity_cor__grid;

/* Checks that the block that just ended is complete: its bands, and at a spin's end all speeds. */
static inline const char *asperity_cor__end_block(asperity_cor_table *t, asperity_cor__grid *g, int spin_ends) {
  if (t->n_spins == 0) return NULL;
  if (!g->bands_known) t->n_bands = g->block_bands, g->bands_known = 1;
  else if (g->block_bands != t->n_bands) return "every speed needs the same number of omega_x rows";
  if (spin_ends && t->n_spins > 1 && g->block_speed != t->n_speeds - 1) return "every spin needs the same speeds";
  return NULL;
}

/* One data row "<spin>,<speed>,<row>,..." of format 2. */
static inline const char *asperity_cor__row2(asperity_cor_table *t, asperity_cor__grid *g, const char *s,
                                             const char *line_end) {
  const char *c = s, *why;
  double spin, speed;
  if (asperity_cor__key(&c, &spin) || !isfinite(spin) || asperity_cor__key(&c, &speed) || !(speed > 0.0) || !isfinite(speed))
    return "a row starts with <spin>,<speed>,<row> (finite numbers, speed > 0)";
  if (strncmp(c, "eps,", 4) == 0) {
    const int new_spin = t->n_spins == 0 || spin != t->spins[t->n_spins - 1];
    if ((why = asperity_cor__end_block(t, g, new_spin)) != NULL) return why;
    if (new_spin) {
      if (t->n_spins > 0 && !(spin > t->spins[t->n_spins - 1])) return "spins must ascend strictly";
      if (asperity_cor__push(&t->spins, &t->n_spins, &g->cap_k, spin)) return "out of memory";
      g->block_speed = 0;
    } else {
      g->block_speed += 1;
    }
    if (t->n_spins == 1) {
      if (t->n_speeds > 0 && !(speed > t->speeds[t->n_speeds - 1])) return "speeds must be > 0 and ascend strictly";
      if (asperity_cor__push(&t->speeds, &t->n_speeds, &g->cap_s, speed)) return "out of memory";
    } else if (g->block_speed >= t->n_speeds || speed != t->speeds[g->block_speed]) {
      return "every spin needs the same speeds";
    }
    g->block_bands = 0;
    return asperity_cor__values(c + 3, line_end, t->n_probs, &t->eps, &g->n_e, &g->cap_e);
  }
  if (strncmp(c, "omega_x:", 8) == 0) {
    char *e;
    const long b = strtol(c + 8, &e, 10);
    if (t->n_spins == 0 || spin != t->spins[t->n_spins - 1] || speed != t->speeds[g->block_speed])
      return "an omega_x row follows the eps row of its spin and speed";
    if (e == c + 8 || b != g->block_bands || (g->bands_known && b >= t->n_bands))
      return "omega_x rows are numbered 0, 1, ... n_bands-1 after their eps row";
    g->block_bands += 1;
    return asperity_cor__values(e, line_end, t->n_probs, &t->omega, &g->n_o, &g->cap_o);
  }
  return "the row column must be eps or omega_x:<band>";
}

/* One data row "<speed>,..." of format 1. */
static inline const char *asperity_cor__row1(asperity_cor_table *t, asperity_cor__grid *g, const char *s,
                                             const char *line_end) {
  char *e;
  double v = strtod(s, &e);
  if (e == s || !(v > 0.0) || !isfinite(v) || (t->n_speeds > 0 && !(v > t->speeds[t->n_speeds - 1])))
    return "speeds must be finite, > 0 and ascend strictly";
  if (asperity_cor__push(&t->speeds, &t->n_speeds, &g->cap_s, v)) return "out of memory";
  return asperity_cor__values(e, line_end, t->n_probs, &t->eps, &g->n_e, &g->cap_e);
}

/* The first line: "# asperity-cor-table format=1|2". */
static inline const char *asperity_cor__format(asperity_cor_table *t, const char *s, const char *line_end) {
  const char *f = strstr(s, "format=");
  if (strncmp(s, "# asperity-cor-table", 20) != 0 || !f || f > line_end)
    return "not an asperity restitution table (first line)";
  t->format = atoi(f + 7);
  if (t->format != 1 && t->format != 2) return "unsupported table format (this header reads format=1 and format=2)";
  return NULL;
}

/* Parses the CSV text (NUL-terminated). Returns 0, or -1 with a message in err (may be NULL). */
static inline int asperity_cor_parse(asperity_cor_table *t, const char *text, char *err, size_t err_size) {
  const char *s = text, *why = NULL;
  long line = 0;
  int header = 0, cap_p = 0;
  asperity_cor__grid g;
  memset(t, 0, sizeof *t);
  memset(&g, 0, sizeof g);
  while (*s && !why) {
    const char *end = strchr(s, '\n');
    const size_t len = end ? (size_t)(end - s) : strlen(s);
    const char *line_end = s + len;
    ++line;
    if (line == 1) {
      why = s[0] == '#' ? asperity_cor__format(t, s, line_end) : "missing '# asperity-cor-table format=N' line";
    } else if (len > 0 && s[0] != '#' && !(len == 1 && s[0] == '\r')) {
      if (!header) {
        const char *key = t->format == 1 ? "speed_m_s" : "spin_rad_s,speed_m_s,row";
        why = strncmp(s, key, strlen(key)) != 0
                  ? (t->format == 1 ? "header must start with speed_m_s" : "header must start with spin_rad_s,speed_m_s,row")
                  : asperity_cor__probs(t, s + strlen(key), line_end, &cap_p);
        header = 1;
      } else {
        why = t->format == 1 ? asperity_cor__row1(t, &g, s, line_end) : asperity_cor__row2(t, &g, s, line_end);
      }
    }
    if (!end) break;
    s = end + 1;
  }
  if (!why && t->format == 2) why = asperity_cor__end_block(t, &g, 1);
  if (!why && (!header || t->n_speeds == 0)) why = "no header or no rows", line = 0;
  if (!why && t->format == 1) {
    t->n_spins = 1;
    t->spins = (double *)calloc(1, sizeof(double));
    if (!t->spins) why = "out of memory", line = 0;
  }
  if (why) {
    asperity_cor__error(err, err_size, why, line);
    asperity_cor_free(t);
    return -1;
  }
  return 0;
}

/* Reads and parses a table file. Returns 0, or -1 with a message in err (may be NULL). */
static inline int asperity_cor_load(asperity_cor_table *t, const char *path, char *err, size_t err_size) {
  FILE *f = fopen(path, "rb");
  char *text;
  long n;
  int r;
  memset(t, 0, sizeof *t);
  if (!f) {
    asperity_cor__error(err, err_size, "cannot open the table file", 0);
    return -1;
  }
  if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
    fclose(f);
    asperity_cor__error(err, err_size, "cannot read the table file", 0);
    return -1;
  }
  text = (char *)malloc((size_t)n + 1);
  if (!text) {
    fclose(f);
    asperity_cor__error(err, err_size, "out of memory", 0);
    return -1;
  }
  if (fread(text, 1, (size_t)n, f) != (size_t)n) {
    free(text);
    fclose(f);
    asperity_cor__error(err, err_size, "cannot read the table file", 0);
    return -1;
  }
  fclose(f);
  text[n] = '\0';
  r = asperity_cor_parse(t, text, err, err_size);
  free(text);
  return r;
}

/* The cell of x in the ascending grid v[0..n-1]: index i and weight w in [0, 1] between v[i] and
 * v[i+1]; x beyond the ends is clamped (w = 0 at the first node, w = 1 at the last). */
static inline void asperity_cor__cell(const double *v, int n, double x, int *i, double *w) {
  int lo = 0, hi = n - 1, mid;
  *i = 0, *w = 0.0;
  if (n < 2 || !(x > v[0])) return;
  if (x >= v[n - 1]) {
    *i = n - 2, *w = 1.0;
    return;
  }
  while (hi - lo > 1) { /* v[lo] < x < v[hi] */
    mid = (lo + hi) / 2;
    if (v[mid] <= x) lo = mid;
    else hi = mid;
  }
  *i = lo, *w = (x - v[lo]) / (v[hi] - v[lo]);
}

/* The quantile row q[0..n_probs-1] at probability u (linear between grid probabilities). */
static inline double asperity_cor__at(const asperity_cor_table *t, const double *q, double u) {
  int j;
  double w;
  asperity_cor__cell(t->probs, t->n_probs, u, &j, &w);
  if (w > 1.0) w = 1.0;
  return q[j] + w * (q[j + 1] - q[j]);
}

static inline double asperity_cor__clamp01(double u) { return !(u > 0.0) ? 0.0 : (u > 1.0 ? 1.0 : u); } /* NaN -> 0 */

/* Interpolates rows(k, i) (a quantile row per spin k and speed i) at (spin, speed, u). */
static inline double asperity_cor__interp(const asperity_cor_table *t, const double *base, size_t stride_block,
                                          double spin, double speed, double u) {
  int k, i, dk, di;
  double wk, wi, r = 0.0;
  asperity_cor__cell(t->spins, t->n_spins, spin, &k, &wk);
  asperity_cor__cell(t->speeds, t->n_speeds, speed, &i, &wi);
  for (dk = 0; dk < (t->n_spins > 1 ? 2 : 1); ++dk)
    for (di = 0; di < (t->n_speeds > 1 ? 2 : 1); ++di) {
      const double w = (dk ? wk : (t->n_spins > 1 ? 1.0 - wk : 1.0)) * (di ? wi : (t->n_speeds > 1 ? 1.0 - wi : 1.0));
      const size_t block = (size_t)(k + dk) * (size_t)t->n_speeds + (size_t)(i + di);
      if (w != 0.0) r += w * asperity_cor__at(t, base + block * stride_block, u);
    }
  return r;
}

/* eps for an impact at `speed` [m/s] with incoming spin `spin` [rad/s] and the host's uniform u in
 * [0, 1]: trilinear in (spin, speed, p). Format 1 tables have one spin (the argument is ignored). */
static inline double asperity_cor_sample_spin(const asperity_cor_table *t, double spin, double speed, double u) {
  return asperity_cor__interp(t, t->eps, (size_t)t->n_probs, spin, speed, asperity_cor__clamp01(u));
}

/* eps for an impact at `speed` [m/s] and the host's uniform u in [0, 1]: bilinear interpolation of
 * the quantile table in (speed, p), at the table's first spin. */
static inline double asperity_cor_sample(const asperity_cor_table *t, double speed, double u) {
  return asperity_cor_sample_spin(t, t->n_spins > 0 ? t->spins[0] : 0.0, speed, u);
}

/* Omega'_x [rad/s] after the impact whose eps was drawn with u: quantile u2 of Omega'_x among the
 * drops whose eps fell in the band of u, interpolated in (spin, speed, u2). NAN when the table has
 * no omega_x rows (format 1, or n_bands = 0). */
static inline double asperity_cor_sample_omega(const asperity_cor_table *t, double spin, double speed, double u,
                                               double u2) {
  int b;
  if (t->n_bands < 1 || !t->omega) return (double)NAN;
  u = asperity_cor__clamp01(u);
  b = (int)(u * t->n_bands);
  if (b >= t->n_bands) b = t->n_bands - 1;
  return asperity_cor__interp(t, t->omega + (size_t)b * (size_t)t->n_probs, (size_t)t->n_bands * (size_t)t->n_probs,
                              spin, speed, asperity_cor__clamp01(u2));
}

#ifdef __cplusplus
}
#endif
#endif /* ASPERITY_COR_TABLE_H */
