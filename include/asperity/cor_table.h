/* asperity restitution tables for DEM codes: one self-contained C99 header, no dependencies beyond
 * the C standard library (README "Restitution tables"). Works from C and C++.
 *
 * A table (written by asperity.cor_table(...) in Python or asperity::write_cor_table in C++) holds
 * quantiles eps(speed_i, p_j) of the macroscopic restitution coefficient of a rough sphere for a
 * grid of impact speeds speed_i [m/s] and probabilities p_j in [0, 1]. Sampling is inverse-cdf:
 *
 *     asperity_cor_table t;
 *     if (asperity_cor_load(&t, "steel.csv", err, sizeof err) != 0) { report err; }
 *     double eps = asperity_cor_sample(&t, speed, u);   // u: the host's own uniform in [0, 1]
 *     asperity_cor_free(&t);
 *
 * asperity_cor_sample is bilinear in (speed, p): speeds outside the grid are clamped to its ends
 * (the law is not extrapolated), u is clamped to [0, 1]. For a fixed speed it is nondecreasing in u,
 * so a u kept for the whole contact gives a consistent draw. Draw u ONCE when a contact begins and
 * keep it (or eps) in the contact's history: a new draw every time step would average the scatter away.
 *
 * CSV format 1: lines starting with '#' are comments (the first is "# asperity-cor-table format=1");
 * then a header "speed_m_s,p=<p_0>,...,p=<p_{P-1}>" and one row per speed "<speed>,<eps_0>,...". */
#ifndef ASPERITY_COR_TABLE_H
#define ASPERITY_COR_TABLE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct asperity_cor_table {
  int n_speeds;      /* rows */
  int n_probs;       /* columns of quantiles */
  double *speeds;    /* [n_speeds], strictly ascending [m/s] */
  double *probs;     /* [n_probs], strictly ascending, probs[0] = 0, probs[n_probs-1] = 1 */
  double *eps;       /* [n_speeds * n_probs], row-major: eps[i * n_probs + j] */
} asperity_cor_table;

#define ASPERITY_COR_TABLE_FORMAT 1

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
  memset(t, 0, sizeof *t);
}

/* Parses the CSV text (NUL-terminated). Returns 0, or -1 with a message in err (may be NULL). */
static inline int asperity_cor_parse(asperity_cor_table *t, const char *text, char *err, size_t err_size) {
  const char *s = text;
  long line = 0;
  int header = 0, cap_p = 0, cap_s = 0, cap_e = 0, n_e = 0, version_seen = 0;
  memset(t, 0, sizeof *t);
  while (*s) {
    const char *end = strchr(s, '\n');
    size_t len = end ? (size_t)(end - s) : strlen(s);
    ++line;
    if (len > 0 && s[0] == '#') {
      if (line == 1) {
        const char *f = strstr(s, "format=");
        if (strncmp(s, "# asperity-cor-table", 20) != 0 || !f || f > s + len) {
          asperity_cor__error(err, err_size, "not an asperity restitution table (first line)", line);
          goto fail;
        }
        if (atoi(f + 7) != ASPERITY_COR_TABLE_FORMAT) {
          asperity_cor__error(err, err_size, "unsupported table format (this header reads format=1)", line);
          goto fail;
        }
        version_seen = 1;
      }
    } else if (len > 0 && !(len == 1 && s[0] == '\r')) {
      if (!version_seen) {
        asperity_cor__error(err, err_size, "missing '# asperity-cor-table format=1' line", line);
        goto fail;
      }
      if (!header) {
        const char *c = s;
        if (strncmp(c, "speed_m_s", 9) != 0) {
          asperity_cor__error(err, err_size, "header must start with speed_m_s", line);
          goto fail;
        }
        while ((c = strchr(c, ',')) != NULL && c < s + len) {
          char *e;
          double p;
          c += 1;
          if (strncmp(c, "p=", 2) != 0) {
            asperity_cor__error(err, err_size, "header column is not p=<probability>", line);
            goto fail;
          }
          p = strtod(c + 2, &e);
          if (e == c + 2 || !(p >= 0.0 && p <= 1.0) || (t->n_probs > 0 && !(p > t->probs[t->n_probs - 1]))) {
            asperity_cor__error(err, err_size, "probabilities must ascend strictly within [0, 1]", line);
            goto fail;
          }
          if (asperity_cor__push(&t->probs, &t->n_probs, &cap_p, p)) goto oom;
        }
        if (t->n_probs < 2 || t->probs[0] != 0.0 || t->probs[t->n_probs - 1] != 1.0) {
          asperity_cor__error(err, err_size, "the probability grid must run from p=0 to p=1", line);
          goto fail;
        }
        header = 1;
      } else {
        const char *c = s;
        char *e;
        int j;
        double v = strtod(c, &e);
        if (e == c || !(v > 0.0) || (t->n_speeds > 0 && !(v > t->speeds[t->n_speeds - 1]))) {
          asperity_cor__error(err, err_size, "speeds must be > 0 and ascend strictly", line);
          goto fail;
        }
        if (asperity_cor__push(&t->speeds, &t->n_speeds, &cap_s, v)) goto oom;
        c = e;
        for (j = 0; j < t->n_probs; ++j) {
          if (*c != ',') {
            asperity_cor__error(err, err_size, "row has fewer values than the header", line);
            goto fail;
          }
          v = strtod(c + 1, &e);
          if (e == c + 1 || v != v || (j > 0 && v < t->eps[n_e - 1])) {
            asperity_cor__error(err, err_size, "quantiles must be numbers, nondecreasing along a row", line);
            goto fail;
          }
          if (asperity_cor__push(&t->eps, &n_e, &cap_e, v)) goto oom;
          c = e;
        }
        if (c < s + len && *c != '\r') {
          asperity_cor__error(err, err_size, "row has more values than the header", line);
          goto fail;
        }
      }
    }
    if (!end) break;
    s = end + 1;
  }
  if (!header || t->n_speeds == 0) {
    asperity_cor__error(err, err_size, "no header or no rows", 0);
    goto fail;
  }
  return 0;
oom:
  asperity_cor__error(err, err_size, "out of memory", 0);
fail:
  asperity_cor_free(t);
  return -1;
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

/* eps for an impact at `speed` [m/s] and the host's uniform u in [0, 1]: bilinear interpolation of
 * the quantile table in (speed, p). Speeds beyond the grid are clamped to its ends; u is clamped. */
static inline double asperity_cor_sample(const asperity_cor_table *t, double speed, double u) {
  int i = 0, j = 0, lo, hi, mid;
  double ws = 0.0, wp = 0.0, e0, e1;
  const double *row0, *row1;
  if (!(u > 0.0)) u = 0.0; /* also NaN */
  if (u > 1.0) u = 1.0;
  if (t->n_speeds > 1) {
    if (!(speed > t->speeds[0])) {
      i = 0, ws = 0.0;
    } else if (speed >= t->speeds[t->n_speeds - 1]) {
      i = t->n_speeds - 2, ws = 1.0;
    } else {
      lo = 0, hi = t->n_speeds - 1; /* speeds[lo] < speed < speeds[hi] */
      while (hi - lo > 1) {
        mid = (lo + hi) / 2;
        if (t->speeds[mid] <= speed) lo = mid;
        else hi = mid;
      }
      i = lo, ws = (speed - t->speeds[lo]) / (t->speeds[hi] - t->speeds[lo]);
    }
  }
  lo = 0, hi = t->n_probs - 1; /* probs[0] = 0 <= u <= 1 = probs[n-1] */
  while (hi - lo > 1) {
    mid = (lo + hi) / 2;
    if (t->probs[mid] <= u) lo = mid;
    else hi = mid;
  }
  j = lo;
  wp = (u - t->probs[lo]) / (t->probs[hi] - t->probs[lo]);
  if (wp > 1.0) wp = 1.0;
  row0 = t->eps + (size_t)i * (size_t)t->n_probs;
  e0 = row0[j] + wp * (row0[j + 1] - row0[j]);
  if (t->n_speeds == 1) return e0;
  row1 = row0 + t->n_probs;
  e1 = row1[j] + wp * (row1[j + 1] - row1[j]);
  return e0 + ws * (e1 - e0);
}

#ifdef __cplusplus
}
#endif
#endif /* ASPERITY_COR_TABLE_H */
