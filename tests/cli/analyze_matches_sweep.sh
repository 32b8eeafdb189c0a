#!/bin/sh
# pwl analyze and a one-point pwl sweep of the same case and record length print and write the
# same regime, period, λ1 (with its error) and K, digit for digit, because both run the one study
# pipeline, evidence ladder included (its minimal period, multiplier, the method the verdict rests
# on and the periods it was seen over); and the one-point sweep draws its bifurcation diagram.
# Usage: analyze_matches_sweep.sh PWL OUTPUT_FOLDER FIGURE THETA TRANSIENT RECORDED
#                                 "ANALYZE FLAGS" "SWEEP FLAGS"
set -u
pwl=$1
out=$2
figure=$3
theta=$4
transient=$5
recorded=$6
analyze_flags=$7
sweep_flags=$8
rm -rf "$out"
mkdir -p "$out"
"$pwl" analyze --figure "$figure" --transient "$transient" --periods $((transient + recorded)) \
  $analyze_flags --out "$out/analyze" > "$out/analyze.txt" || { echo "analyze failed"; exit 1; }
"$pwl" sweep --figure "$figure" --parameter theta --range "$theta:$theta" --points 1 \
  --transient "$transient" --periods "$recorded" $sweep_flags --quiet --out "$out/sweep" \
  > "$out/sweep.txt" || { echo "the sweep failed"; exit 1; }
test -s "$out/sweep/bifurcation.png" || { echo "the one-point sweep drew no bifurcation.png"; exit 1; }
row=$(tail -n 1 "$out/sweep/classification.csv")
field() { echo "$row" | cut -d, -f"$1"; }
regime=$(field 4)
period=$(field 6)
lambda1=$(field 7)
lambda1_error=$(field 8)
k=$(field 9)
# What analyze printed and wrote, and the sweep's numbers in the same formats.
printed_regime=$(sed -n 's/^regime: //p' "$out/analyze.txt")
printed_lambda=$(sed -n 's/^  lambda1: \([^ ]*\) ± \([^ ]*\) per period.*/\1 \2/p' "$out/analyze.txt")
printed_k=$(sed -n 's/^  0-1 test: K = //p' "$out/analyze.txt")
written=$(tail -n 1 "$out/analyze/classification.csv")
fail=0
check() {
  if [ "$2" != "$3" ]; then
    echo "$1: analyze gives '$2', the one-point sweep '$3'"
    fail=1
  fi
}
check regime "$printed_regime" "$regime"
check "printed lambda1" "$printed_lambda" "$(printf '%.5f %.1e' "$lambda1" "$lambda1_error")"
check "printed K" "$printed_k" "$(printf '%.3f' "$k")"
check "classification.csv" "$(echo "$written" | cut -d, -f1-5)" \
  "$(printf '%s,%s,%.10g,%.3g,%.6g' "$regime" "$period" "$lambda1" "$lambda1_error" "$k")"
# The ladder's columns, by name in each file's header.
column() {  # FILE NAME: the last row's cell under NAME
  awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == name) c = i }
                        END { if (c) print $c; else print "(no column " name ")" }' "$1"
}
for name in minimal_period record_period decided_by confirmation observed_periods halves rotation_pq; do
  check "$name" "$(column "$out/analyze/classification.csv" "$name")" \
    "$(column "$out/sweep/classification.csv" "$name")"
done
multiplier=$(column "$out/sweep/classification.csv" multiplier)
[ -n "$multiplier" ] && multiplier=$(printf '%.10g' "$multiplier")
check multiplier "$(column "$out/analyze/classification.csv" multiplier)" "$multiplier"
[ "$fail" -eq 0 ] || exit 1
echo "analyze and the one-point sweep agree: $regime, period $period, lambda1 $lambda1 ± $lambda1_error, K $k, minimal period $(column "$out/sweep/classification.csv" minimal_period), decided by $(column "$out/sweep/classification.csv" decided_by)"
