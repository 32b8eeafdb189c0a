#!/bin/sh
# Compares two CSV files of states row by row (poincare.csv of `pwl simulate` with a hyperplane
# section, orbit.csv of `pwl orbit`): both must have `rows` data rows (after the header), and
# every column, the crossing time t first if there is one, must differ by at most `tolerance`. Prints the largest differences of t and of the states and
# the row count; exits 1 otherwise.
# Usage: compare_sections.sh A.csv B.csv rows tolerance
a=$1 b=$2 rows=$3 tolerance=$4
awk -F, -v rows="$rows" -v tol="$tolerance" '
  FNR == 1 { next }
  NR == FNR { n_a++; for (i = 1; i <= NF; i++) value[FNR, i] = $i; next }
  {
    n_b++
    d = $1 - value[FNR, 1]; if (d < 0) d = -d
    if (d > worst_t) worst_t = d
    for (i = 2; i <= NF; i++) {
      d = $i - value[FNR, i]; if (d < 0) d = -d
      if (d > worst) worst = d
    }
  }
  END {
    printf "rows %d and %d (expected %d); largest difference of t %.3e, of the states %.3e (tolerance %g)\n", n_a, n_b, rows, worst_t, worst, tol
    if (n_a != rows || n_b != rows || !(worst_t <= tol) || !(worst <= tol)) exit 1
    print "section points agree"
  }' "$a" "$b"
