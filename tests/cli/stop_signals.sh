#!/bin/sh
# SIGINT and SIGTERM stop a sweep at once, even in the middle of long points on two OpenMP
# threads: exit code 130 or 143, a message with the points done and how to go on, a journal of
# whole, valid lines only; --resume then ends with the same files, byte for byte, as a run never
# stopped. Usage: stop_signals.sh PWL OUTPUT_FOLDER [TRANSIENT]
set -u
pwl=$1
out=$2
transient=${3:-40000}
# Points of TRANSIENT forcing periods (40000: about a second each in a Release build; the
# sanitizer build, about 20 times slower, passes 4000), two at a time. The signal is sent just
# after a point is journaled, when that thread has begun a new point: a stop that waited for the
# points in progress would take about a point's time; it must take less than a quarter of it.
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 6 --mode continuation
      --transient $transient --periods 200 --threads 2 --quiet --no-plot"
total=12
rm -rf "$out"
mkdir -p "$out"
. "$(dirname "$0")/signal_launch.sh"  # sets $launch (SIGINT at its default)
now_ms() { echo $(($(date +%s%N) / 1000000)); }
begin=$(now_ms)
"$pwl" $args --out "$out/whole" > /dev/null || { echo "the uninterrupted run failed"; exit 1; }
point_ms=$(((($(now_ms) - begin) * 2) / total))
echo "uninterrupted: $total points, $point_ms ms a point"
for signal in INT TERM; do
  folder="$out/stopped_$signal"
  $launch "$pwl" $args --out "$folder" > /dev/null 2> "$out/$signal.err" &
  pid=$!
  tries=0
  while [ "$(cat "$folder"/journal-*.log 2> /dev/null | wc -l)" -lt 2 ]; do
    tries=$((tries + 1))
    if [ "$tries" -gt 60000 ]; then
      kill -9 "$pid"
      echo "no points finished in time"
      exit 1
    fi
    sleep 0.01
  done
  sent=$(now_ms)
  kill -"$signal" "$pid"
  wait "$pid"
  code=$?
  latency=$(($(now_ms) - sent))
  cat "$out/$signal.err"
  done_points=$(wc -l < "$folder/journal-0.log")
  echo "SIG$signal: exit code $code after $latency ms, $done_points of $total points journaled"
  expected=130
  [ "$signal" = TERM ] && expected=143
  [ "$code" -eq "$expected" ] || { echo "exit code $code, not $expected"; exit 1; }
  [ "$latency" -lt $((point_ms / 4)) ] ||
    { echo "the stop took $latency ms, a point $point_ms ms"; exit 1; }
  [ "$done_points" -lt "$total" ] || { echo "the run finished before it was stopped"; exit 1; }
  [ -e "$folder/poincare.csv" ] && { echo "a stopped run wrote result files"; exit 1; }
  [ "$(tail -c 1 "$folder/journal-0.log" | od -An -c | tr -d ' ')" = '\n' ] ||
    { echo "the journal does not end with a whole line"; exit 1; }
  grep -qF "pwl: stopped by SIG$signal: $done_points of $total points are done and journaled in $folder; run the same command with --resume to compute the other $((total - done_points))" "$out/$signal.err" ||
    { echo "no stop message with $done_points points"; exit 1; }
  # Every line valid: the resumed run finds them all, with no warning and no torn line.
  "$pwl" $args --out "$folder" --resume > /dev/null 2> "$out/$signal.resume.err" ||
    { cat "$out/$signal.resume.err"; echo "the resumed run failed"; exit 1; }
  cat "$out/$signal.resume.err"
  grep -qF "resuming in $folder: $done_points of $total points are journaled, $((total - done_points)) to compute" "$out/$signal.resume.err" ||
    { echo "the resumed run did not find $done_points valid lines"; exit 1; }
  grep -q "warning\|note" "$out/$signal.resume.err" && { echo "the journal had damaged lines"; exit 1; }
  for f in poincare.csv classification.csv; do
    cmp "$out/whole/$f" "$folder/$f" || exit 1
  done
done
echo "stopped by SIGINT and SIGTERM, resumed, identical"
