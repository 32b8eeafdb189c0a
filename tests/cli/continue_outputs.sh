#!/bin/sh
# pwl continue on a small range writes branch.csv, bifurcations.csv and branch_section.csv with
# their headers (bifurcations.csv with the orbit's amplitudes and state of the recorded masses),
# one row of branch.csv per point and as many section rows as the points' periods add up to; then
# pwl sweep --branches draws those branches over its own diagram.
# With --switch-branches in the continuation flags, a period-2 branch must be among them.
# Usage: continue_outputs.sh PWL OUTPUT_FOLDER "CASE FLAGS" PARAMETER RANGE "CONTINUE FLAGS"
#                            BRANCH_HEADER
set -u
pwl=$1
out=$2
case_flags=$3
parameter=$4
range=$5
continue_flags=$6
branch_header=$7
rm -rf "$out"
mkdir -p "$out"
"$pwl" continue $case_flags --parameter "$parameter" --range "$range" $continue_flags --quiet \
  --out "$out/continue" \
  > "$out/continue.txt" || { cat "$out/continue.txt"; echo "pwl continue failed"; exit 1; }
cat "$out/continue.txt"
fail=0
header=$(head -n 1 "$out/continue/branch.csv")
if [ "$header" != "$branch_header" ]; then
  echo "branch.csv header: '$header', expected '$branch_header'"
  fail=1
fi
bif_header=$(head -n 1 "$out/continue/bifurcations.csv" | cut -d, -f1-9)
if [ "$bif_header" != "type,parameter,branch,period,spring,multiplier_re,multiplier_im,abs_multiplier,detail" ]; then
  echo "bifurcations.csv header: '$bif_header'"
  fail=1
fi
# After the detail: the orbit's amplitudes and its state at t = 0 of the recorded masses, the same
# columns as branch.csv's, each a number.
bif_tail=$(head -n 1 "$out/continue/bifurcations.csv" | cut -d, -f10-)
branch_middle=$(echo "$branch_header" |
  awk -F, '{ for (i = 6; i < NF; i++) printf "%s%s", $i, (i < NF - 1 ? "," : "") }')
if [ "$bif_tail" != "$branch_middle" ]; then
  echo "bifurcations.csv columns after detail: '$bif_tail', expected '$branch_middle'"
  fail=1
fi
# Every row as wide as the header, and at least one (both ranges tested hold bifurcations).
awk -F, 'NR == 1 { width = NF; next }
  NF != width { print "bifurcations.csv row " NR ": " NF " columns, not " width; bad = 1 }
  { for (i = 10; i <= NF; i++) if ($i !~ /^-?[0-9]/) {
      print "bifurcations.csv row " NR ": column " i " is \"" $i "\""; bad = 1 } }
  END { if (NR < 2) { print "bifurcations.csv: no bifurcation"; bad = 1 }; exit bad }' \
  "$out/continue/bifurcations.csv" || fail=1
points=$(($(wc -l < "$out/continue/branch.csv") - 1))
sections=$(awk -F, 'NR > 1 { k += $3 } END { print k + 0 }' "$out/continue/branch.csv")
section_rows=$(($(wc -l < "$out/continue/branch_section.csv") - 1))
printed=$(sed -n 's/^time: .* (\([0-9]*\) points)$/\1/p' "$out/continue.txt")
echo "branch.csv: $points points ($printed printed); branch_section.csv: $section_rows rows ($sections expected)"
[ "$points" -ge 3 ] || { echo "too few points"; fail=1; }
[ "$points" = "$printed" ] || { echo "branch.csv and the printed count differ"; fail=1; }
[ "$sections" = "$section_rows" ] || { echo "branch_section.csv has the wrong number of rows"; fail=1; }
case "$continue_flags" in
  *--switch-branches*)
    doubled=$(awk -F, 'NR > 1 && $3 == 2 { n++ } END { print n + 0 }' "$out/continue/branch.csv")
    switched=$(grep -c '^period-doubling,.*,starts branch [1-9]' "$out/continue/bifurcations.csv")
    echo "period-2 points: $doubled; period doublings switched from: $switched"
    [ "$doubled" -gt 0 ] && [ "$switched" -gt 0 ] || { echo "no period-2 branch followed"; fail=1; }
    ;;
esac
# The parameter column spans the range (a branch may end just past its end).
awk -F, -v range="$range" 'NR > 1 && $1 == 0 { if (!seen || $2 < lo) lo = $2; if (!seen || $2 > hi) hi = $2; seen = 1 }
  END { split(range, r, ":"); a = r[1] < r[2] ? r[1] : r[2]; b = r[1] < r[2] ? r[2] : r[1]
        printf "branch 0 spans %.6g to %.6g of [%g, %g]\n", lo, hi, a, b
        if (lo > a + 1e-9 || hi < b - 1e-6 * (b - a)) exit 1 }' "$out/continue/branch.csv" || fail=1
# The sweep of the same range draws the branches over its points.
"$pwl" sweep $case_flags --parameter "$parameter" --range "$(echo "$range" | awk -F: '{ print ($1 < $2 ? $1 ":" $2 : $2 ":" $1) }')" \
  --points 4 --transient 50 --periods 20 --no-lyapunov --record x1 --quiet \
  --branches "$out/continue" --out "$out/sweep" > "$out/sweep.txt" 2>&1 ||
  { cat "$out/sweep.txt"; echo "pwl sweep --branches failed"; fail=1; }
if command -v gnuplot > /dev/null 2>&1; then
  test -s "$out/sweep/bifurcation.png" || { echo "no bifurcation.png with the branches"; fail=1; }
  test -s "$out/continue/frequency_response.png" || { echo "no frequency_response.png"; fail=1; }
fi
[ "$fail" -eq 0 ] || exit 1
echo "pwl continue wrote its files"
