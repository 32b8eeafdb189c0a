#!/bin/sh
# A sweep killed with SIGKILL part-way and resumed with --resume ends with the same files, byte for
# byte, as a run that was never interrupted.
# Usage: sweep_kill_resume.sh PWL OUTPUT_FOLDER [TRANSIENT PERIODS [FLAGS]] (per point; 1000 and
# 200; FLAGS more flags of the sweep, such as --quick)
set -u
pwl=$1
out=$2
transient=${3:-1000}
periods=${4:-200}
flags=${5:-}
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 60 --mode continuation
      --transient $transient --periods $periods --threads 1 --quiet --no-plot $flags"
rm -rf "$out"
mkdir -p "$out"
"$pwl" $args --out "$out/whole" > /dev/null || { echo "the uninterrupted run failed"; exit 1; }
"$pwl" $args --out "$out/killed" > /dev/null &
pid=$!
tries=0
while :; do
  done_points=$(cat "$out"/killed/journal-*.log 2> /dev/null | wc -l)
  [ "$done_points" -ge 10 ] && break
  tries=$((tries + 1))
  if [ "$tries" -gt 60000 ]; then
    kill -9 "$pid"
    echo "no points finished in time"
    exit 1
  fi
  sleep 0.01
done
kill -9 "$pid"
wait "$pid" 2> /dev/null
done_points=$(cat "$out"/killed/journal-*.log | wc -l)
echo "killed after $done_points of 120 points"
if [ "$done_points" -ge 120 ] || [ -e "$out/killed/poincare.csv" ]; then
  echo "the run finished before it was killed"
  exit 1
fi
# What a kill in the middle of a write leaves: a torn last line.
printf '17 0123456789abcdef period-1 1 0.5' >> "$out/killed/journal-0.log"
"$pwl" $args --out "$out/killed" --resume > /dev/null || { echo "the resumed run failed"; exit 1; }
cmp "$out/whole/poincare.csv" "$out/killed/poincare.csv" || exit 1
cmp "$out/whole/classification.csv" "$out/killed/classification.csv" || exit 1
echo "identical"
