#!/bin/sh
# pwl orbit on a case whose period-1 orbit is stable: the orbit it writes is the Poincaré point
# that pwl simulate (the same exact solver) settles on after enough periods, to 1e-8; floquet.csv
# has the 2n multipliers, largest modulus first; the printed verdict agrees with the largest one.
# The orbit's guess is taken after a short transient, so that Newton has work to do.
# Usage: orbit_matches_simulate.sh PWL OUTPUT_FOLDER "CASE FLAGS" PERIODS "ORBIT FLAGS"
set -u
pwl=$1
out=$2
case_flags=$3
periods=$4
orbit_flags=$5
rm -rf "$out"
mkdir -p "$out"
"$pwl" orbit $case_flags $orbit_flags --period 1 --out "$out/orbit" > "$out/orbit.txt" ||
  { cat "$out/orbit.txt"; echo "pwl orbit failed"; exit 1; }
cat "$out/orbit.txt"
"$pwl" simulate $case_flags --method exact --periods "$periods" --skip-periods $((periods - 1)) \
  --quiet --out "$out/simulate" || { echo "pwl simulate failed"; exit 1; }
n=$(head -n 1 "$out/orbit/orbit.csv" | awk -F, '{ print NF / 2 }')
fail=0
# The settled Poincaré point (its t column left out) against the orbit's state.
awk -F, -v tol=1e-8 '
  FNR == 1 { next }
  NR == FNR { for (i = 1; i <= NF; i++) y[i] = $i; width = NF; next }
  { last = $0 }
  END {
    k = split(last, p, ",")
    if (k != width + 1) { print "simulate has " k " columns, the orbit " width; exit 1 }
    for (i = 1; i <= width; i++) { d = p[i + 1] - y[i]; if (d < 0) d = -d; if (d > worst) worst = d }
    printf "orbit against the settled Poincaré point: largest difference %.3e (tolerance %g)\n", worst, tol
    if (!(worst <= tol)) exit 1
  }' "$out/orbit/orbit.csv" "$out/simulate/poincare.csv" || fail=1
# floquet.csv: re,im,abs; 2n rows; abs non-increasing and equal to |re + i im|.
awk -F, -v n="$n" '
  NR == 1 { if ($0 != "re,im,abs") { print "floquet.csv header: " $0; bad = 1 }; next }
  {
    rows++
    m = sqrt($1 * $1 + $2 * $2); d = m - $3; if (d < 0) d = -d
    if (d > 1e-12 * (1 + m)) { print "row " NR ": abs " $3 " is not |re + i im| = " m; bad = 1 }
    if (rows > 1 && $3 > previous * (1 + 1e-12)) { print "row " NR ": not sorted by abs"; bad = 1 }
    previous = $3
    if (rows == 1) largest = $3
  }
  END {
    if (rows != 2 * n) { print "floquet.csv has " rows " rows, expected " 2 * n; bad = 1 }
    print "largest |multiplier| " largest
    print (largest < 1 ? "expected verdict: stable" : "expected verdict: unstable")
    exit bad
  }' "$out/orbit/floquet.csv" > "$out/floquet_check.txt" || fail=1
cat "$out/floquet_check.txt"
expected=$(sed -n 's/^expected verdict: //p' "$out/floquet_check.txt")
printed=$(sed -n 's/^verdict: \([a-z]*\).*/\1/p' "$out/orbit.txt")
if [ "$expected" != "$printed" ]; then
  echo "printed verdict '$printed', the multipliers say '$expected'"
  fail=1
fi
iterations=$(sed -n 's/^Newton: \([0-9]*\) iteration.*/\1/p' "$out/orbit.txt")
if [ "${iterations:-0}" -lt 2 ]; then
  echo "Newton took ${iterations:-no} iterations: the guess was already the orbit"
  fail=1
fi
if [ "$printed" != "stable" ]; then
  echo "the case's period-1 orbit should be stable"
  fail=1
fi
[ "$fail" -eq 0 ] || exit 1
echo "pwl orbit matches the settled motion: verdict $printed"
