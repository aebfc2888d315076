/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The C tests' one assertion: CHECK(cond) reports the failed condition with its line and counts it
 * in `failures` (main returns failures != 0). Included once per test program. */
#ifndef ASPERITY_TESTS_C_CHECK_H
#define ASPERITY_TESTS_C_CHECK_H
#include <stdio.h>

static int failures = 0;
#define CHECK(cond)                                                              \
  do {                                                                           \
    if (!(cond)) {                                                               \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                                \
    }                                                                            \
  } while (0)

#endif
