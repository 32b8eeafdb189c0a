#!/bin/sh
# --force-degree end to end: the switching PIM at d = 4 (order 7) follows figure 4a's exact
# Poincaré points to 1e-8 at T/50 over 5 periods where d = 2 (order 5) does not (8e-8), so the flag
# reaches the integrator; a method without a force degree refuses it (exit code 2, naming the flag
# and the method), with --rtol before searching for a step; --compare-with runs its own method at its own default beside it; and `pwl orbit`
# given a degree takes the switching PIM and names the degree.
# Usage: force_degree.sh PWL COMPARE_POINCARE_SCRIPT OUTPUT_FOLDER
set -u
pwl=$1
compare=$2
out=$3
rm -rf "$out"
mkdir -p "$out"
"$pwl" simulate --figure 4a --periods 5 --method exact --quiet --out "$out/exact" || exit 1
for d in 2 4; do
  "$pwl" simulate --figure 4a --periods 5 --method pim-switching --force-degree $d \
         --steps-per-period 50 --quiet --out "$out/d$d" || { echo "d = $d failed"; exit 1; }
done
sh "$compare" "$out/d4/poincare.csv" "$out/exact/poincare.csv" 6 1e-8 ||
  { echo "d = 4 is not within 1e-8"; exit 1; }
if sh "$compare" "$out/d2/poincare.csv" "$out/exact/poincare.csv" 6 1e-8; then
  echo "d = 2 is within 1e-8 too: the degree does not show"
  exit 1
fi
"$pwl" simulate --figure 4a --periods 2 --method dopri5 --force-degree 4 --quiet \
       --out "$out/dopri5" 2> "$out/dopri5.txt"
code=$?
cat "$out/dopri5.txt"
if [ $code -ne 2 ] || ! grep -q -- "--force-degree = 4: dopri5 takes no force degree" "$out/dopri5.txt"; then
  echo "dopri5 with --force-degree: exit $code, not the refusal"
  exit 1
fi
"$pwl" simulate --figure 4a --periods 2 --method pim --rtol 1e-6 --force-degree 4 --quiet \
       --out "$out/pim_rtol" 2> "$out/pim_rtol.txt"
code=$?
cat "$out/pim_rtol.txt"
if [ $code -ne 2 ] || grep -q "note: --rtol" "$out/pim_rtol.txt"; then
  echo "pim with --rtol and --force-degree: exit $code, or refused only after the step search"
  exit 1
fi
"$pwl" simulate --figure 4a --periods 2 --method pim-switching --force-degree 4 \
       --compare-with dopri5 --record 1 --quiet --out "$out/compare" ||
  { echo "--compare-with dopri5 beside --force-degree 4 failed"; exit 1; }
"$pwl" orbit --figure 4a --force-degree 4 --out "$out/orbit" > "$out/orbit.txt" 2>&1 ||
  { cat "$out/orbit.txt"; echo "orbit with --force-degree failed"; exit 1; }
grep -q "by switching PIM, d = 4" "$out/orbit.txt" || { cat "$out/orbit.txt"; echo "orbit did not take d = 4"; exit 1; }
echo "force degree: reaches the integrator, refused where it does not apply"
