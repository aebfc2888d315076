// SPDX-License-Identifier: GPL-3.0-or-later
// The TSan pass's power check: a deliberate data race in an OpenMP loop. scripts/test requires
// ThreadSanitizer (with archer and the options it uses for the real tests) to REPORT it; a TSan
// pass that stays silent here would be silent for real races too.
#include <cstdio>

int main() {
  long sum = 0;  // shared, updated without synchronisation: the race
#pragma omp parallel for num_threads(2) schedule(static, 1)
  for (int i = 0; i < 100000; ++i) sum += i;
  std::printf("sum %ld\n", sum);
  return 0;
}
