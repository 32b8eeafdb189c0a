#!/bin/sh
# SIGINT and SIGTERM stop pwl continue --curves between two rows: exit code 130 or 143, a message
# saying the files written so far are whole, and curves.csv and branch.csv with whole rows only,
# each with as many fields as its header, all of them numbers where numbers are due. The curves
# of figure 5's chain in (theta, alpha) take about 40 s; the signal comes once 30 curve rows are
# written. Usage: stop_curves.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
args="continue --figure 5 --parameter theta --range 0.5:3 --curves alpha=1:15 --transient 200
      --quiet --no-plot"
rm -rf "$out"
mkdir -p "$out"
. "$(dirname "$0")/signal_launch.sh"  # sets $launch (SIGINT at its default)
for signal in INT TERM; do
  folder="$out/stopped_$signal"
  $launch "$pwl" $args --out "$folder" > /dev/null 2> "$out/$signal.err" &
  pid=$!
  tries=0
  while [ "$(cat "$folder/curves.csv" 2> /dev/null | wc -l)" -lt 31 ]; do
    tries=$((tries + 1))
    if [ "$tries" -gt 30000 ]; then
      kill -9 "$pid"
      echo "no curve rows in time"
      exit 1
    fi
    if ! kill -0 "$pid" 2> /dev/null; then
      cat "$out/$signal.err"
      echo "the run ended before it was stopped"
      exit 1
    fi
    sleep 0.01
  done
  kill -"$signal" "$pid"
  wait "$pid"
  code=$?
  cat "$out/$signal.err"
  expected=130
  [ "$signal" = TERM ] && expected=143
  [ "$code" -eq "$expected" ] || { echo "exit code $code, not $expected"; exit 1; }
  grep -qF "stopped by SIG$signal: every row written so far is whole in $folder" "$out/$signal.err" ||
    { echo "no stop message"; exit 1; }
  for f in curves.csv codim2.csv branch.csv bifurcations.csv; do
    [ -s "$folder/$f" ] || { echo "$f missing or empty"; exit 1; }
    [ "$(tail -c 1 "$folder/$f" | od -An -c | tr -d ' ')" = '\n' ] ||
      { echo "$f does not end with a whole line"; exit 1; }
  done
  # Every row of curves.csv: the header's number of fields, and from the third field on numbers
  # (or empty: a grazing row has no multiplier).
  awk -F, 'NR == 1 { n = NF; next }
           NF != n { print "curves.csv row " NR ": " NF " fields, not " n; bad = 1 }
           { for (i = 3; i <= NF; ++i) if ($i !~ /^(-?[0-9.]+(e[-+]?[0-9]+)?|nan)?$/) {
               print "curves.csv row " NR " field " i ": " $i; bad = 1 } }
           END { exit bad }' "$folder/curves.csv" || exit 1
  rows=$(($(wc -l < "$folder/curves.csv") - 1))
  echo "SIG$signal: exit code $code, $rows whole curve rows"
done
echo "stopped by SIGINT and SIGTERM, every row whole"
