#!/bin/sh
# Compares two poincare.csv files of `pwl simulate` row by row: both must have `rows` data rows
# (after the header), the same times, and states that differ by at most `tolerance` in every
# column. Prints the largest difference and the row count; exits 1 otherwise.
# Usage: compare_poincare.sh A.csv B.csv rows tolerance
a=$1 b=$2 rows=$3 tolerance=$4
awk -F, -v rows="$rows" -v tol="$tolerance" '
  FNR == 1 { next }
  NR == FNR { n_a++; for (i = 1; i <= NF; i++) value[FNR, i] = $i; width = NF; next }
  {
    n_b++
    if ($1 != value[FNR, 1] && ($1 - value[FNR, 1]) ^ 2 > 1e-24) { bad = "times differ at row " FNR }
    for (i = 2; i <= NF; i++) {
      d = $i - value[FNR, i]; if (d < 0) d = -d
      if (d > worst) worst = d
    }
  }
  END {
    printf "rows %d and %d (expected %d); largest difference %.3e (tolerance %g)\n", n_a, n_b, rows, worst, tol
    if (bad != "") { print bad; exit 1 }
    if (n_a != rows || n_b != rows || !(worst <= tol)) exit 1
    print "poincare points agree"
  }' "$a" "$b"
