#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# MPI scaling of a streaming run (docs/mpi.md): one process with 1 and 2 threads,
# two processes with 1 thread each; wall of the whole command and each process's CPU and wall.
# Usage: bench/mpi_scaling.sh [validate-geometry] (default build/release/validate-geometry)
V=${1:-build/release/validate-geometry}
M="mpirun --allow-run-as-root --oversubscribe --mca btl self,vader"
A="-q --asperities 10000 --drops 10000000 --spheres 4000 --statistics streaming --no-plots"
T="/usr/bin/time -f %U+%S_cpu_%e_wall"
for rep in 1 2 3; do
  for cfg in np1t1 np2t1 np1t2; do
    rm -rf /tmp/sc-$cfg
    l=$(uptime | sed 's/.*average: //')
    s=$(date +%s.%N)
    case $cfg in
      np1t1) r=$($T $V $A --threads 1 --out /tmp/sc-$cfg 2>&1 >/dev/null | tail -1);;
      np2t1) r=$($M -np 2 $T $V $A --threads 1 --out /tmp/sc-$cfg 2>&1 >/dev/null | grep cpu | tr '\n' ' ');;
      np1t2) r=$($T $V $A --threads 2 --out /tmp/sc-$cfg 2>&1 >/dev/null | tail -1);;
    esac
    e=$(date +%s.%N)
    echo "$cfg rep $rep wall $(echo "$e-$s"|bc) [$r] load $l"
  done
done
