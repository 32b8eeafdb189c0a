#!/bin/sh
# pwl bench chain's banded switching PIM rows on a small chain (n = 100, t in [0, 5] s): with
# --without-dense the dense PIM is left out even when --methods names it; the rows at η = 0.1 s and
# η = 0.02 s are within reach of the kink-located rkf78 reference at 1e-12 (the finer below 1e-10
# in x1 and x1') and their errors fall like η^5 or faster (the method's order with force degree 2
# is 5: measured order >= 4.5); and for each dopri5 row the table names the fastest pwl row at or
# below both its errors. The rows of the accuracy requests 1e-6 and 1e-9 (--rtol-rows: the step
# and degree found on the run's first 5 s) are within them in x1 and x1' (the motion's size is about 1).
# The order-7 rows (--switching-degrees 2,4: force degree 4) are at least 100x more accurate than
# the order-5 rows at η = 0.1 s and at rounding (below 1e-13) at η = 0.02 s. The floor tables list
# every banded row (with its steps) and each step of --floor-steps with the band the steppers choose there
# (q = 5 at η = 0.02 s, 8 at 0.2 s, as `cli_bench_scaling_small` finds for the stepper itself).
# No timing is asserted.
# Usage: bench_chain_switching.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
rm -rf "$out"
mkdir -p "$(dirname "$out")"
"$pwl" bench chain --n 100 --t-end 5 --runs 1 --methods pim-switching,pim-rtol,pim-dense,dopri5-1e-10 \
       --without-dense --switching-steps 0.1,0.02 --switching-degrees 2,4 --rtol-rows 1e-6,1e-9 \
       --floor-steps 0.02,0.2 --out "$out" --quiet > "$out.txt" 2>&1 ||
  { cat "$out.txt"; echo "pwl bench chain failed"; exit 1; }
cat "$out.txt"
if grep -q '| dense PIM |' "$out/bench_chain.md"; then
  echo "--without-dense ran the dense PIM"
  exit 1
fi
awk -F'|' '
  $2 ~ /banded switching PIM/ && NF == 13 && $3 ~ /η = 0.1 s, order 5/ { coarse_x = $9 + 0; coarse_v = $10 + 0; n++ }
  $2 ~ /banded switching PIM/ && NF == 13 && $3 ~ /η = 0.02 s, order 5/ { fine_x = $9 + 0; fine_v = $10 + 0; n++ }
  $2 ~ /banded switching PIM/ && NF == 13 && $3 ~ /η = 0.1 s, order 7/ { coarse7_x = $9 + 0; coarse7_v = $10 + 0; n7++ }
  $2 ~ /banded switching PIM/ && NF == 13 && $3 ~ /η = 0.02 s, order 7/ { fine7_x = $9 + 0; fine7_v = $10 + 0; n7++ }
  NF == 13 && $2 ~ /banded switching PIM/ { steps[$3] = $8 + 0 }
  NF == 7 && $2 ~ /banded switching PIM/ && $5 + 0 > 0 && $6 + 0 > 0 {
    floors++
    if (steps[$3] != $4 + 0) { print "floor row" $3 "has " $4 " steps, its row " steps[$3]; bad_steps++ }
  }
  NF == 9 && $2 + 0 == 0.02 { q_fine = $3 + 0; by_step++ }
  NF == 9 && $2 + 0 == 0.2 { q_coarse = $3 + 0; by_step++ }
  $0 ~ /^- dopri5 \(plain, like ode45\) \(rtol = atol = 1e-10\): banded switching PIM/ { named = 1 }
  $2 ~ /--rtol/ && NF == 13 && $3 ~ /rtol = 1e-06/ { r6 = ($9 + 0 <= 1e-6 && $10 + 0 <= 1e-6); m++ }
  $2 ~ /--rtol/ && NF == 13 && $3 ~ /rtol = 1e-09/ { r9 = ($9 + 0 <= 1e-9 && $10 + 0 <= 1e-9); m++ }
  END {
    if (n != 2) { print "expected two switching rows, found " n; exit 1 }
    order_x = log(coarse_x / fine_x) / log(5); order_v = log(coarse_v / fine_v) / log(5)
    printf "switching PIM: x1 %.2e -> %.2e, x1p %.2e -> %.2e from η = 0.1 to 0.02 s: order %.2f, %.2f\n", coarse_x, fine_x, coarse_v, fine_v, order_x, order_v
    if (!(fine_x < 1e-10 && fine_v < 1e-10)) { print "the fine row is not below 1e-10"; exit 1 }
    if (!(order_x >= 4.5 && order_v >= 4.5)) { print "the measured order is below 4.5"; exit 1 }
    if (!named) { print "no pwl row named against dopri5 at 1e-10"; exit 1 }
    if (m != 2) { print "expected two rows of accuracy requests, found " m; exit 1 }
    if (!(r6 && r9)) { print "an accuracy request row misses its tolerance"; exit 1 }
    if (n7 != 2) { print "expected two order-7 rows, found " n7; exit 1 }
    printf "order 7: x1 %.2e -> %.2e, x1p %.2e -> %.2e\n", coarse7_x, fine7_x, coarse7_v, fine7_v
    if (!(100 * coarse7_x <= coarse_x && 100 * coarse7_v <= coarse_v)) { print "order 7 is not 100x more accurate than order 5 at 0.1 s"; exit 1 }
    if (!(fine7_x < 1e-13 && fine7_v < 1e-13)) { print "the order-7 row at 0.02 s is not at rounding"; exit 1 }
    if (floors != 6) { print "expected a floor for each of the 6 switching and --rtol rows, found " floors; exit 1 }
    if (bad_steps > 0) { print "a floor row counts other steps than its row"; exit 1 }
    if (by_step != 2 || q_fine != 5 || q_coarse != 8) { print "floor by step: " by_step " rows, q " q_fine " and " q_coarse " (expected 5 and 8)"; exit 1 }
    print "switching rows: accurate, order 5, named against dopri5"
  }' "$out/bench_chain.md"
