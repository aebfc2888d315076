/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. This header, and the table format it reads, are
 * MIT-licensed (the text is in LICENSE): unlike the rest of asperity (GPL-3.0-or-later), a DEM code
 * under any licence (GPL-2.0-only LAMMPS/LIGGGHTS, BSD) may include it. It depends on nothing but
 * the C standard library (and, on POSIX systems, <fcntl.h>, <sys/stat.h> and <unistd.h> to refuse
 * directories and special files), so including it brings in no GPL code. */
/** \file
 * asperity restitution tables for DEM codes: one self-contained C99 header (docs/dem-coupling.md).
 * Works from C and C++. The format, the sampling rules and the contact-model relations follow
 * (shown as written in the header).
 * \verbatim
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
 * THE FORMAT (a text file, '\n' or "\r\n" line ends, every line -- the last included -- ends in a
 * line end). Line 1 is exactly
 *     "# asperity-cor-table format=1 speeds=<S> probabilities=<P>"                      (format 1)
 *     "# asperity-cor-table format=2 spins=<K> speeds=<S> probabilities=<P> bands=<B>"  (format 2)
 * (keys in this order, one space apart, values unsigned decimal integers without sign or leading
 * zeros). Then lines starting with '#' are comments and empty lines are skipped, anywhere. The first
 * other line is the column header, then the data rows:
 *   format 1: header "speed_m_s,p=<p_0>,...,p=<p_{P-1}>", then S rows "<speed>,<eps_0>,...,<eps_{P-1}>",
 *     speeds ascending.
 *   format 2: header "spin_rad_s,speed_m_s,row,p=<p_0>,...,p=<p_{P-1}>"; then K*S blocks: for each spin
 *     (ascending) and each speed (ascending, the same speeds for every spin) a row
 *     "<spin>,<speed>,eps,<eps_0>,..." followed by B rows "<spin>,<speed>,omega_x:<b>,<q_0>,..." for
 *     b = 0..B-1: quantiles of Omega'_x among the drops whose eps lies in the band [b/B, (b+1)/B) of
 *     that block's eps law.
 * Numbers are plain decimal literals: [+-]digits[.digits][(e|E)[+-]digits] (or .digits), at most 64
 * characters, read by strtod independently of the C locale; no spaces, no hex, no inf/nan, nothing
 * that overflows to infinity or underflows to 0. Ranges (checked; anything else is refused):
 *   S in [1, 10^6], P in [2, 100001], K in [1, 1000], B in [0, 1000];
 *   p_j in [0, 1], strictly ascending, p_0 = 0 and p_{P-1} = 1;
 *   speeds in (0, 1e8] m/s and spins in [-1e6, 1e6] rad/s, each grid strictly ascending;
 *   eps in [0, ASPERITY_COR_EPS_MAX = 1000] (eps is a ratio of normal speeds; > 1 only where spin
 *     energy is returned; a value above 1000 is a damaged table), nondecreasing along a row;
 *   Omega'_x quantiles in [-1e15, 1e15] rad/s, nondecreasing along a row;
 *   a file loaded by asperity_cor_load: a regular file (POSIX: directories, FIFOs, devices are
 *     refused before reading) of at most ASPERITY_COR_MAX_BYTES (default 1 GiB; #define it before
 *     including this header to change it), with no NUL byte.
 * The row and block counts are checked against line 1: a table missing a row or a block, or with a
 * row too many, is refused. Every refusal returns -1 and writes a message naming the line, the key
 * or the value to err. (Tables written before asperity 1.0 lack the counts on line 1 and are
 * refused with a message saying so: add the counts, or write the table again.)
 *
 * CONTACT MODELS (pure functions, per contact, a few ns each; docs/dem-coupling.md): a drawn eps
 * becomes the damping parameter of the host's normal contact model. delta is the overlap, m the
 * effective mass m1 m2 / (m1 + m2) of the pair; the contact begins and ends at delta = 0 and the
 * force is NOT clipped at zero (near the end of a contact the dashpot pulls: a code that clips the
 * force to max(0, F), or ends the contact when F = 0, gets a larger eps than these relations give).
 *   Linear spring-dashpot, F = -k delta - gamma d(delta)/dt (asperity_cor_linear_gamma / _eps):
 *     gamma = -2 ln(eps) sqrt(m k) / sqrt(pi^2 + ln^2 eps),
 *     eps   = exp(-pi z / sqrt(1 - z^2)) with the damping ratio z = gamma / (2 sqrt(m k)); 0 if z >= 1.
 *     The overlap is a damped sine, delta = (v0 / w) e^(-z w0 t) sin(w t), w = w0 sqrt(1 - z^2),
 *     w0^2 = k / m, which returns to 0 at t = pi / w with speed v0 e^(-z w0 pi / w). (J. Schaefer,
 *     S. Dippel, D. E. Wolf, J. Phys. I France 6, 5 (1996); T. Poeschel, T. Schwager, Computational
 *     Granular Dynamics, Springer 2005, ch. 3.) eps does not depend on the impact speed v0.
 *   Hertz with Tsuji-type damping, F = -k_n delta^(3/2) - alpha sqrt(m k_n) delta^(1/4) d(delta)/dt
 *     (Y. Tsuji, T. Tanaka, T. Ishida, Powder Technol. 71, 239 (1992)) (asperity_cor_tsuji_alpha /
 *     _eps):
 *     alpha = -sqrt(5) ln(eps) / sqrt(pi^2 + ln^2 eps),   eps = exp(-pi alpha / sqrt(5 - alpha^2)),
 *     exact, not a fit: with u = d(delta)/dt, m u du/d(delta) = -k_n delta^(3/2) - alpha sqrt(m k_n)
 *     delta^(1/4) u; in w = delta^(5/4) (dw = 5/4 delta^(1/4) d(delta)) this is
 *     m u du/dw = -(4/5) k_n w - (4/5) alpha sqrt(m k_n) u, the phase-plane equation of a LINEAR
 *     oscillator with stiffness 4 k_n / 5 and damping 4 alpha sqrt(m k_n) / 5, i.e. damping ratio
 *     z = alpha / sqrt(5). The rebound runs along the same curve from (w, u) = (0, v0) to (0, -eps v0)
 *     in both, so eps is the linear oscillator's. (The same expression is LAMMPS's "damping
 *     coeff_restitution" for Hertz; tests/c/test_cor_table.c checks it against a direct integration
 *     of the Hertz-Tsuji equation to 1e-6.) alpha >= sqrt(5): no rebound (eps = 0).
 * The functions return NAN outside their domain (eps > 1 cannot come from a passive dashpot: a host
 * that draws eps > 1 from a table with spin must decide itself, e.g. clamp to 1).
 * \endverbatim */
#ifndef ASPERITY_COR_TABLE_H
#define ASPERITY_COR_TABLE_H

#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <locale.h>
#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#define ASPERITY_COR__POSIX 1
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** A loaded restitution table: the grids and the quantiles, all owned by the table (free it with
 * asperity_cor_free). asperity_cor_load and asperity_cor_parse overwrite every field (free a loaded
 * table before loading another into it). Read-only after loading: any number of threads may sample
 * it at once. */
typedef struct asperity_cor_table {
  int n_speeds;      /**< speeds of the grid */
  int n_probs;       /**< columns of quantiles */
  double *speeds;    /**< [n_speeds], strictly ascending [m/s] */
  double *probs;     /**< [n_probs], strictly ascending, probs[0] = 0, probs[n_probs-1] = 1 */
  double *eps;       /**< [n_spins * n_speeds * n_probs]: eps[(k * n_speeds + i) * n_probs + j] */
  int format;        /**< 1 or 2 */
  int n_spins;       /**< 1 for format 1 (the spin in the table's comment and JSON header) */
  double *spins;     /**< [n_spins], strictly ascending [rad/s]; format 1: one entry, 0 */
  int n_bands;       /**< eps bands with Omega'_x quantiles; 0: none (always 0 in format 1) */
  double *omega;     /**< [((k * n_speeds + i) * n_bands + b) * n_probs + j] */
} asperity_cor_table;

#define ASPERITY_COR_TABLE_FORMAT 2 /**< the newest format this header reads (it reads 1 too) */
#ifndef ASPERITY_COR_MAX_BYTES
#define ASPERITY_COR_MAX_BYTES (1L << 30) /**< the largest table file asperity_cor_load reads [bytes]; define it before including to change it */
#endif
#define ASPERITY_COR_EPS_MAX 1000.0  /**< the largest eps a table may hold (a larger one is a damaged table) */
#define ASPERITY_COR_SPEED_MAX 1e8   /**< the largest grid speed a table may hold [m/s] */
#define ASPERITY_COR_SPIN_MAX 1e6    /**< the largest |spin| of a format-2 spin grid [rad/s] */
#define ASPERITY_COR_OMEGA_MAX 1e15  /**< the largest |Omega'_x| quantile a table may hold [rad/s] */

/* Parser state: the declared counts, where it is, and what the next message quotes. */
typedef struct asperity_cor__parser {
  asperity_cor_table *t;
  long line;                 /* 1-based line of the text being read */
  const char *tok, *tok_end; /* the text a message quotes (NULL: none) */
  long spins, speeds, probs, bands; /* counts stated on line 1 (-1: not stated) */
  long rows;                 /* data rows read */
  size_t n_e, n_o;           /* values stored in eps and omega */
  const char *point;         /* the C locale's decimal point, which strtod reads */
} asperity_cor__parser;

static inline void asperity_cor__error(char *err, size_t n, const char *what, long line, const char *tok,
                                       const char *tok_end) {
  char q[48];
  size_t i = 0;
  if (!err || !n) return;
  if (tok) {
    for (; tok + i < tok_end && i < 40; ++i) {
      const unsigned char c = (unsigned char)tok[i];
      q[i] = (c >= 32 && c < 127) ? (char)c : '?';
    }
    if (tok + i < tok_end) q[i++] = '.', q[i++] = '.', q[i++] = '.';
  }
  q[i] = '\0';
  if (line > 0 && tok) snprintf(err, n, "line %ld: '%s': %s", line, q, what);
  else if (line > 0) snprintf(err, n, "line %ld: %s", line, what);
  else snprintf(err, n, "%s", what);
}

/** Frees what asperity_cor_load allocated; the table is then empty. */
static inline void asperity_cor_free(asperity_cor_table *t) {
  if (!t) return;
  free(t->speeds);
  free(t->probs);
  free(t->eps);
  free(t->spins);
  free(t->omega);
  memset(t, 0, sizeof *t);
}

/* The end of the token at c: the next ',' or the line's end. */
static inline const char *asperity_cor__tok_end(const char *c, const char *end) {
  while (c < end && *c != ',') ++c;
  return c;
}

/* A plain decimal literal at c (before end): [+-]digits[.digits][(e|E)[+-]digits] or [+-].digits[...].
 * Stores the value and the literal's end; returns NULL or the problem (p->tok names the text). */
static inline const char *asperity_cor__number(asperity_cor__parser *p, const char *c, const char *end, double *x,
                                               const char **next) {
  const char *d = c, *dp = NULL;
  char buf[72];
  char *e;
  size_t n = 0, k, pl;
  int digits = 0, nonzero = 0;
  const char *point = p->point;
  p->tok = c, p->tok_end = asperity_cor__tok_end(c, end);
  if (c == end || *c == ',') return "empty value (a row ending in ',', or ',,')";
  if (d < end && (*d == '+' || *d == '-')) ++d;
  for (; d < end && *d >= '0' && *d <= '9'; ++d) digits = 1, nonzero |= *d != '0';
  if (d < end && *d == '.') {
    dp = d++;
    for (; d < end && *d >= '0' && *d <= '9'; ++d) digits = 1, nonzero |= *d != '0';
  }
  if (!digits) return "not a plain decimal number";
  if (d < end && (*d == 'e' || *d == 'E')) {
    const char *x0;
    ++d;
    if (d < end && (*d == '+' || *d == '-')) ++d;
    x0 = d;
    while (d < end && *d >= '0' && *d <= '9') ++d;
    if (d == x0) return "not a plain decimal number (exponent without digits)";
  }
  if (d < end && *d != ',') return "not a plain decimal number (trailing characters)";
  if ((size_t)(d - c) > 64) return "number longer than 64 characters";
  /* strtod reads the C locale's decimal point: hand it that one. */
  pl = strlen(point);
  for (k = 0; c + k < d; ++k) {
    if (c + k == dp) {
      if (n + pl >= sizeof buf) return "number longer than 64 characters";
      memcpy(buf + n, point, pl), n += pl;
    } else {
      buf[n++] = c[k];
    }
  }
  buf[n] = '\0';
  *x = strtod(buf, &e);
  if (e != buf + n) return "not a plain decimal number (strtod stopped early)";
  if (!isfinite(*x)) return "number overflows a double";
  if (*x == 0.0 && nonzero) return "number underflows to 0";
  *next = d;
  return NULL;
}

/* "<key>=<unsigned integer>" at *c, the key given; advances *c past it (and one following space). */
static inline const char *asperity_cor__count(asperity_cor__parser *p, const char **c, const char *end, const char *key,
                                              long lo, long hi, long *v) {
  const size_t kl = strlen(key);
  const char *d, *s = *c;
  long x = 0;
  p->tok = s;
  d = s;
  while (d < end && *d != ' ') ++d;
  p->tok_end = d;
  if ((size_t)(end - s) <= kl || strncmp(s, key, kl) != 0 || s[kl] != '=')
    return "line 1 must read '# asperity-cor-table format=1 speeds=<S> probabilities=<P>' or '... format=2 spins=<K> "
           "speeds=<S> probabilities=<P> bands=<B>' (one space apart; tables written before asperity 1.0 lack the "
           "counts: add them or write the table again)";
  s += kl + 1;
  if (s == d) return "the value is empty";
  if (*s == '0' && d - s > 1) return "the value has a leading zero";
  for (; s < d; ++s) {
    if (*s < '0' || *s > '9') return "the value is not an unsigned decimal integer";
    if (x > 100000000L) return "the value is out of range";
    x = 10 * x + (*s - '0');
  }
  if (x < lo || x > hi) return "the value is out of range (S in [1, 10^6], P in [2, 100001], K in [1, 1000], B in [0, 1000])";
  *v = x;
  *c = d < end ? d + 1 : d;
  if (d < end && d + 1 == end) return "line 1 ends in a space";
  return NULL;
}

/* Line 1: "# asperity-cor-table format=F <counts>". */
static inline const char *asperity_cor__first(asperity_cor__parser *p, const char *s, const char *end) {
  static const char magic[] = "# asperity-cor-table ";
  const char *c = s, *why;
  long format = 0;
  p->tok = s, p->tok_end = end;
  if ((size_t)(end - s) < sizeof magic - 1 || strncmp(s, magic, sizeof magic - 1) != 0)
    return "not an asperity restitution table (line 1 must start with '# asperity-cor-table format=')";
  c += sizeof magic - 1;
  if ((why = asperity_cor__count(p, &c, end, "format", 1, 1000000, &format)) != NULL) return why;
  if (format != 1 && format != 2) return "unsupported table format (this header reads format=1 and format=2)";
  p->t->format = (int)format;
  if (format == 2 && (why = asperity_cor__count(p, &c, end, "spins", 1, 1000, &p->spins)) != NULL) return why;
  if ((why = asperity_cor__count(p, &c, end, "speeds", 1, 1000000, &p->speeds)) != NULL) return why;
  if ((why = asperity_cor__count(p, &c, end, "probabilities", 2, 100001, &p->probs)) != NULL) return why;
  if (format == 2 && (why = asperity_cor__count(p, &c, end, "bands", 0, 1000, &p->bands)) != NULL) return why;
  if (format == 1) p->spins = 1, p->bands = 0;
  p->tok = c, p->tok_end = end;
  if (c != end) return "unexpected text after the counts on line 1";
  return NULL;
}

/* Allocates the arrays for the counts of line 1, once the text is known to be long enough. */
static inline const char *asperity_cor__alloc(asperity_cor__parser *p, size_t text_len) {
  asperity_cor_table *t = p->t;
  const double values = (double)p->spins * (double)p->speeds * (double)(1 + p->bands) * (double)p->probs;
  p->tok = NULL;
  if (2.0 * values > (double)text_len) return "line 1 states more values than the text holds (a truncated table)";
  t->speeds = (double *)malloc((size_t)p->speeds * sizeof(double));
  t->spins = (double *)malloc((size_t)p->spins * sizeof(double));
  t->probs = (double *)malloc((size_t)p->probs * sizeof(double));
  t->eps = (double *)malloc((size_t)p->spins * (size_t)p->speeds * (size_t)p->probs * sizeof(double));
  if (p->bands > 0)
    t->omega = (double *)malloc((size_t)p->spins * (size_t)p->speeds * (size_t)p->bands * (size_t)p->probs * sizeof(double));
  if (!t->speeds || !t->spins || !t->probs || !t->eps || (p->bands > 0 && !t->omega)) return "out of memory";
  return NULL;
}

/* The column header: "<key>,p=<p_0>,...,p=<p_{P-1}>". */
static inline const char *asperity_cor__header(asperity_cor__parser *p, const char *s, const char *end) {
  asperity_cor_table *t = p->t;
  const char *key = t->format == 1 ? "speed_m_s" : "spin_rad_s,speed_m_s,row", *c, *why;
  const size_t kl = strlen(key);
  double x;
  p->tok = s, p->tok_end = asperity_cor__tok_end(s, end);
  if ((size_t)(end - s) < kl || strncmp(s, key, kl) != 0 || (s + kl < end && s[kl] != ','))
    return t->format == 1 ? "the column header must start with speed_m_s" : "the column header must start with spin_rad_s,speed_m_s,row";
  c = s + kl;
  while (c < end) {
    ++c; /* the ',' */
    p->tok = c, p->tok_end = asperity_cor__tok_end(c, end);
    if (end - c < 2 || c[0] != 'p' || c[1] != '=') return "a column of the header is not p=<probability>";
    if (t->n_probs == p->probs) return "the header has more p= columns than line 1 states";
    if ((why = asperity_cor__number(p, c + 2, end, &x, &c)) != NULL) return why;
    if (!(x >= 0.0 && x <= 1.0) || (t->n_probs > 0 && !(x > t->probs[t->n_probs - 1])))
      return "probabilities must lie in [0, 1] and ascend strictly";
    t->probs[t->n_probs++] = x;
  }
  p->tok = NULL;
  if (t->n_probs != p->probs) return "the header has fewer p= columns than line 1 states";
  if (t->probs[0] != 0.0 || t->probs[t->n_probs - 1] != 1.0) return "the probability grid must run from p=0 to p=1";
  return NULL;
}

/* The P quantiles ",q_0,...,q_{P-1}" at c up to the line's end, nondecreasing, in [lo, hi]. */
static inline const char *asperity_cor__values(asperity_cor__parser *p, const char *c, const char *end, double *out,
                                               double lo, double hi, const char *range) {
  long j;
  const char *why;
  double x;
  for (j = 0; j < p->probs; ++j) {
    if (c >= end) {
      p->tok = NULL;
      return "the row has fewer values than the header has p= columns";
    }
    if ((why = asperity_cor__number(p, c + 1, end, &x, &c)) != NULL) return why;
    if (!(x >= lo && x <= hi)) return range;
    if (j > 0 && x < out[j - 1]) return "quantiles must not decrease along a row";
    out[j] = x;
  }
  p->tok = c, p->tok_end = end;
  if (c < end) return "the row has more values than the header has p= columns";
  return NULL;
}

/* A key number "<x>," at *c; advances past the comma. */
static inline const char *asperity_cor__key(asperity_cor__parser *p, const char **c, const char *end, double *x) {
  const char *why = asperity_cor__number(p, *c, end, x, c);
  if (why) return why;
  if (*c >= end) return "the row ends after its first columns";
  *c += 1;
  return NULL;
}

static inline const char *asperity_cor__speed(asperity_cor__parser *p, long i, double v) {
  asperity_cor_table *t = p->t;
  if (!(v > 0.0 && v <= ASPERITY_COR_SPEED_MAX)) return "speeds must lie in (0, 1e8] m/s";
  if (i == t->n_speeds) {
    if (i > 0 && !(v > t->speeds[i - 1])) return "speeds must ascend strictly";
    t->speeds[t->n_speeds++] = v;
  } else if (v != t->speeds[i]) {
    return "every spin needs the same speeds, in the same order";
  }
  return NULL;
}

/* Data row r (0-based) of the table. */
static inline const char *asperity_cor__row(asperity_cor__parser *p, const char *s, const char *end) {
  asperity_cor_table *t = p->t;
  const long r = p->rows, per_block = 1 + p->bands, block = r / per_block, within = r % per_block;
  const long k = block / p->speeds, i = block % p->speeds;
  const char *c = s, *why, *kind_end;
  double spin = 0.0, speed;
  char expect[48];
  if (r >= p->spins * p->speeds * per_block) {
    p->tok = NULL;
    return "more data rows than line 1 states";
  }
  if (t->format == 2) {
    if ((why = asperity_cor__key(p, &c, end, &spin)) != NULL) return why;
  }
  if ((why = asperity_cor__number(p, c, end, &speed, &c)) != NULL) return why;
  if (t->format == 1) {
    if ((why = asperity_cor__speed(p, i, speed)) != NULL) return why;
    ++p->rows;
    if (c >= end) {
      p->tok = NULL;
      return "the row has fewer values than the header has p= columns";
    }
    why = asperity_cor__values(p, c, end, t->eps + p->n_e, 0.0, ASPERITY_COR_EPS_MAX, "eps must lie in [0, 1000]");
    p->n_e += (size_t)p->probs;
    return why;
  }
  if (c >= end) {
    p->tok = NULL;
    return "the row ends after its first columns";
  }
  ++c;
  if (within == 0) strcpy(expect, "eps");
  else snprintf(expect, sizeof expect, "omega_x:%ld", within - 1);
  p->tok = c, p->tok_end = asperity_cor__tok_end(c, end);
  if ((size_t)(p->tok_end - c) != strlen(expect) || strncmp(c, expect, strlen(expect)) != 0)
    return within == 0 ? "expected the eps row of the next block (a band row too many, or rows out of order)"
                       : "expected the next omega_x:<b> row (b = 0..bands-1 after each eps row)";
  kind_end = p->tok_end;
  p->tok = s, p->tok_end = asperity_cor__tok_end(s, end);
  if (!(spin >= -ASPERITY_COR_SPIN_MAX && spin <= ASPERITY_COR_SPIN_MAX)) return "spins must lie in [-1e6, 1e6] rad/s";
  if (i == 0 && within == 0) {
    if (k > 0 && !(spin > t->spins[k - 1])) return "spins must ascend strictly (or: the previous spin has too few speeds)";
    t->spins[t->n_spins++] = spin;
  } else if (spin != t->spins[k]) {
    return "the spin differs from its block's (a speed or a band row is missing, or rows are out of order)";
  }
  p->tok = asperity_cor__tok_end(s, end) + 1, p->tok_end = asperity_cor__tok_end(p->tok, end);
  if ((why = asperity_cor__speed(p, i, speed)) != NULL) return why;
  c = kind_end;
  ++p->rows;
  if (within == 0) {
    why = asperity_cor__values(p, c, end, t->eps + p->n_e, 0.0, ASPERITY_COR_EPS_MAX, "eps must lie in [0, 1000]");
    p->n_e += (size_t)p->probs;
  } else {
    why = asperity_cor__values(p, c, end, t->omega + p->n_o, -ASPERITY_COR_OMEGA_MAX, ASPERITY_COR_OMEGA_MAX,
                               "Omega'_x quantiles must lie in [-1e15, 1e15] rad/s");
    p->n_o += (size_t)p->probs;
  }
  return why;
}

/** Parses the CSV text (NUL-terminated). Returns 0, or -1 with a message in err (may be NULL). */
static inline int asperity_cor_parse(asperity_cor_table *t, const char *text, char *err, size_t err_size) {
  const char *s = text, *why = NULL;
  const size_t text_len = strlen(text);
  int header = 0;
  asperity_cor__parser p;
  const struct lconv *lc = localeconv();
  memset(t, 0, sizeof *t);
  memset(&p, 0, sizeof p);
  p.t = t;
  p.point = (lc && lc->decimal_point && lc->decimal_point[0]) ? lc->decimal_point : ".";
  p.spins = p.speeds = p.probs = p.bands = -1;
  while (*s && !why) {
    const char *nl = strchr(s, '\n');
    const char *end = nl ? nl : s + strlen(s);
    ++p.line;
    p.tok = NULL;
    if (!nl) {
      why = "the last line does not end in a line end (a truncated table)";
      break;
    }
    if (end > s && end[-1] == '\r') --end;
    if (p.line == 1) {
      if ((why = asperity_cor__first(&p, s, end)) == NULL) why = asperity_cor__alloc(&p, text_len);
    } else if (end > s && s[0] != '#') {
      if (!header) why = asperity_cor__header(&p, s, end), header = 1;
      else why = asperity_cor__row(&p, s, end);
    }
    s = nl + 1;
  }
  if (!why && p.line == 0) why = "empty text";
  if (!why && !header) why = "no column header (the text ends before it)", p.tok = NULL, p.line = 0;
  if (!why && p.rows != p.spins * p.speeds * (1 + p.bands)) {
    ++p.line, p.tok = NULL;
    why = p.bands > 0 ? "the table ends early: fewer data rows than line 1 states (spins x speeds x (1 + bands))"
                      : "the table ends early: fewer data rows than line 1 states";
  }
  if (!why) {
    t->n_bands = (int)p.bands;
    if (t->format == 1) t->spins[0] = 0.0, t->n_spins = 1;
    if (p.bands == 0) free(t->omega), t->omega = NULL;
    return 0;
  }
  asperity_cor__error(err, err_size, why, p.line, p.tok, p.tok_end);
  asperity_cor_free(t);
  return -1;
}

/* Doubles the read buffer (one byte more for the terminating NUL), up to one byte past
 * ASPERITY_COR_MAX_BYTES so that a larger file is seen to be larger. NULL, or why it cannot. */
static inline const char *asperity_cor__grow(char **text, size_t *cap) {
  char *q;
  const size_t was = *cap;
  *cap = was ? 2 * was : 65536;
  if (*cap > (size_t)ASPERITY_COR_MAX_BYTES + 1) *cap = (size_t)ASPERITY_COR_MAX_BYTES + 1;
  if (*cap == was) return "the table file is larger than ASPERITY_COR_MAX_BYTES";
  if ((q = (char *)realloc(*text, *cap + 1)) == NULL) return "out of memory";
  *text = q;
  return NULL;
}

/** Reads and parses a table file. Returns 0, or -1 with a message in err (may be NULL). */
static inline int asperity_cor_load(asperity_cor_table *t, const char *path, char *err, size_t err_size) {
  char *text = NULL;
  size_t n = 0, cap = 0;
  const char *why = NULL;
  int r;
#ifdef ASPERITY_COR__POSIX
  struct stat st;
  int fd;
#ifdef O_CLOEXEC
  fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
#else
  fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY);
#endif
  memset(t, 0, sizeof *t);
  if (fd < 0) why = "cannot open the table file";
  else if (fstat(fd, &st) != 0) why = "cannot read the table file";
  else if (!S_ISREG(st.st_mode)) why = "the table file is not a regular file (a directory, FIFO or device)";
  else if (st.st_size > (off_t)ASPERITY_COR_MAX_BYTES) why = "the table file is larger than ASPERITY_COR_MAX_BYTES";
  while (!why) {
    long got;
    if (n == cap && (why = asperity_cor__grow(&text, &cap)) != NULL) break;
    got = (long)read(fd, text + n, cap - n);
    if (got < 0) why = "cannot read the table file";
    else if (got == 0) break;
    else n += (size_t)got;
  }
  if (fd >= 0) close(fd);
#else
  FILE *f = fopen(path, "rb");
  memset(t, 0, sizeof *t);
  if (!f) why = "cannot open the table file";
  while (!why) {
    size_t got;
    if (n == cap && (why = asperity_cor__grow(&text, &cap)) != NULL) break;
    got = fread(text + n, 1, cap - n, f);
    n += got;
    if (got == 0) {
      if (ferror(f)) why = "cannot read the table file";
      break;
    }
  }
  if (f) fclose(f);
#endif
  if (!why && n > (size_t)ASPERITY_COR_MAX_BYTES) why = "the table file is larger than ASPERITY_COR_MAX_BYTES";
  if (!why && !text) why = "the table file is empty";
  if (!why && memchr(text, '\0', n)) why = "the table file holds a NUL byte (not a text table)";
  if (why) {
    free(text);
    if (err && err_size) snprintf(err, err_size, "%s: %s", path, why);
    return -1;
  }
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

/* Whether `t` holds a table: a failed or absent load leaves it empty (every field 0 or NULL), and
 * sampling an empty table dereferenced NULL (issue 33 item 8); the samplers return NAN instead. */
static inline int asperity_cor__loaded(const asperity_cor_table *t) {
  return t && t->n_speeds >= 1 && t->n_probs >= 2 && t->n_spins >= 1 && t->speeds && t->probs && t->spins && t->eps;
}

/** eps for an impact at `speed` [m/s] with incoming spin `spin` [rad/s] and the host's uniform u in
 * [0, 1]: trilinear in (spin, speed, p). Format 1 tables have one spin (the argument is ignored).
 * NAN for a table that is not loaded (NULL, or one whose asperity_cor_load failed). */
static inline double asperity_cor_sample_spin(const asperity_cor_table *t, double spin, double speed, double u) {
  if (!asperity_cor__loaded(t)) return (double)NAN;
  return asperity_cor__interp(t, t->eps, (size_t)t->n_probs, spin, speed, asperity_cor__clamp01(u));
}

/** eps for an impact at `speed` [m/s] and the host's uniform u in [0, 1]: bilinear interpolation of
 * the quantile table in (speed, p), at the table's first spin. */
static inline double asperity_cor_sample(const asperity_cor_table *t, double speed, double u) {
  if (!asperity_cor__loaded(t)) return (double)NAN;
  return asperity_cor_sample_spin(t, t->spins[0], speed, u);
}

/** Omega'_x [rad/s] after the impact whose eps was drawn with u: quantile u2 of Omega'_x among the
 * drops whose eps fell in the band of u, interpolated in (spin, speed, u2). NAN when the table has
 * no omega_x rows (format 1, or n_bands = 0). */
static inline double asperity_cor_sample_omega(const asperity_cor_table *t, double spin, double speed, double u,
                                               double u2) {
  int b;
  if (!asperity_cor__loaded(t) || t->n_bands < 1 || !t->omega) return (double)NAN;
  u = asperity_cor__clamp01(u);
  b = (int)(u * t->n_bands);
  if (b >= t->n_bands) b = t->n_bands - 1;
  return asperity_cor__interp(t, t->omega + (size_t)b * (size_t)t->n_probs, (size_t)t->n_bands * (size_t)t->n_probs,
                              spin, speed, asperity_cor__clamp01(u2));
}


/* ---- Contact models: eps <-> damping, per contact (formulas and sources in the top comment) ---- */

#define ASPERITY_COR__PI 3.14159265358979323846

/* exp(-pi z / sqrt(1 - z^2)) for a damping ratio z >= 0 of a linear oscillator (0 for z >= 1). */
static inline double asperity_cor__eps_of_ratio(double z) {
  return z >= 1.0 ? 0.0 : exp(-ASPERITY_COR__PI * z / sqrt((1.0 - z) * (1.0 + z)));
}

/* The damping ratio z in [0, 1] of a linear oscillator that rebounds with eps in [0, 1]. */
static inline double asperity_cor__ratio_of_eps(double eps) {
  double l;
  if (eps == 0.0) return 1.0;
  l = log(eps);
  return -l / sqrt(ASPERITY_COR__PI * ASPERITY_COR__PI + l * l);
}

static inline int asperity_cor__positive(double x) { return x > 0.0 && x < HUGE_VAL; }

/** Linear spring-dashpot F = -k delta - gamma d(delta)/dt, effective mass m: the gamma giving the
 * restitution coefficient eps in [0, 1] (eps = 0: critical damping 2 sqrt(m k)). NAN outside the
 * domain (eps not in [0, 1], k or m not finite and > 0). */
static inline double asperity_cor_linear_gamma(double eps, double k, double m) {
  if (!(eps >= 0.0 && eps <= 1.0) || !asperity_cor__positive(k) || !asperity_cor__positive(m)) return (double)NAN;
  return 2.0 * sqrt(m * k) * asperity_cor__ratio_of_eps(eps);
}

/** The inverse: eps of a linear spring-dashpot with damping gamma >= 0 (0 when critically or over-
 * damped: the overlap then never returns to 0). NAN outside the domain. */
static inline double asperity_cor_linear_eps(double gamma, double k, double m) {
  if (!(gamma >= 0.0 && gamma < HUGE_VAL) || !asperity_cor__positive(k) || !asperity_cor__positive(m)) return (double)NAN;
  return asperity_cor__eps_of_ratio(gamma / (2.0 * sqrt(m * k)));
}

/** Hertz with Tsuji-type damping F = -k_n delta^(3/2) - alpha sqrt(m k_n) delta^(1/4) d(delta)/dt:
 * the dimensionless alpha giving eps in [0, 1] (eps = 0: alpha = sqrt(5)); it depends on eps only.
 * NAN outside the domain. */
static inline double asperity_cor_tsuji_alpha(double eps) {
  if (!(eps >= 0.0 && eps <= 1.0)) return (double)NAN;
  return sqrt(5.0) * asperity_cor__ratio_of_eps(eps);
}

/** The inverse: eps of a Hertz-Tsuji contact with alpha >= 0 (0 for alpha >= sqrt(5)). */
static inline double asperity_cor_tsuji_eps(double alpha) {
  if (!(alpha >= 0.0 && alpha < HUGE_VAL)) return (double)NAN;
  return asperity_cor__eps_of_ratio(alpha / sqrt(5.0));
}

#ifdef __cplusplus
}
#endif
#endif /* ASPERITY_COR_TABLE_H */
