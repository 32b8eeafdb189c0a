#!/bin/sh
# Damage in the middle of a finished sweep's journal is found by the lines' checksums: one byte of
# a value, one digit of a checksum, an id made into another point's and an id made out of range.
# --resume names each damaged line by its number, computes those points again and ends with the
# same files, byte for byte, as the uninterrupted run. A valid record of a point the study does
# not have, or a second valid record of a point with another result, is refused (exit code 2)
# with the file and line(s) named. Usage: journal_damage.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
# The plain record (--quick): this test is about the journal's faults, not the verdicts; the
# evidence ladder's journaling is checked by the kill-and-resume and identical-runs tests.
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 20 --mode continuation
      --transient 200 --periods 100 --threads 2 --quiet --no-plot --quick"
rm -rf "$out"
mkdir -p "$out"
"$pwl" $args --out "$out/whole" > /dev/null || { echo "the uninterrupted run failed"; exit 1; }
cp -r "$out/whole" "$out/damaged"
rm "$out/damaged/poincare.csv" "$out/damaged/classification.csv"
journal="$out/damaged/journal-0.log"
lines=$(wc -l < "$journal")
[ "$lines" -eq 40 ] || { echo "the journal has $lines lines, not 40"; exit 1; }
# Line 10: the 40th byte (inside a value) changed; line 15: the checksum's 5th digit changed;
# line 22: its id replaced by the id of line 30's point; line 27: its id made 999 (no such point).
awk -v id30="$(sed -n 30p "$journal" | cut -d' ' -f1)" '
  function flip(c, other) { return c == other ? "7" : other }
  NR == 10 { $0 = substr($0, 1, 39) flip(substr($0, 40, 1), "3") substr($0, 41) }
  NR == 15 { split($0, f, " "); c = f[2]; c = substr(c, 1, 4) flip(substr(c, 5, 1), "e") substr(c, 6)
             $0 = f[1] " " c substr($0, length(f[1]) + 18) }
  NR == 22 { $0 = id30 substr($0, index($0, " ")) }
  NR == 27 { $0 = "999" substr($0, index($0, " ")) }
  { print }' "$out/whole/journal-0.log" > "$journal"
changed=$(cmp -l "$out/whole/journal-0.log" "$journal" 2> /dev/null | wc -l)
[ "$changed" -ge 4 ] || { echo "the damage did not take ($changed bytes differ)"; exit 1; }
"$pwl" $args --out "$out/damaged" --resume > /dev/null 2> "$out/resume.err"
code=$?
cat "$out/resume.err"
[ $code -eq 0 ] || { echo "the resumed run failed ($code)"; exit 1; }
for n in 10 15 22 27; do
  grep -qF "pwl: warning: $journal line $n is damaged (its checksum does not match its contents): the line is ignored and its point computed again" "$out/resume.err" ||
    { echo "no warning for line $n"; exit 1; }
done
[ "$(grep -c 'warning' "$out/resume.err")" -eq 4 ] || { echo "not 4 warnings"; exit 1; }
grep -qF "resuming in $out/damaged: 36 of 40 points are journaled, 4 to compute" "$out/resume.err" ||
  { echo "not 4 points to compute"; exit 1; }
for f in poincare.csv classification.csv; do
  cmp "$out/whole/$f" "$out/damaged/$f" || exit 1
done
echo "4 damaged lines named and recomputed; files identical"

# Records that cannot belong: the same configuration with 25 points has points 40..49, which a
# study of 20 points (ids 0..39) does not have, and other θ values for points 0..39.
"$pwl" $(echo "$args" | sed 's/--points 20/--points 25/') --out "$out/other" > /dev/null ||
  { echo "the 25-point run failed"; exit 1; }
cp -r "$out/whole" "$out/foreign"
grep '^45 ' "$out/other/journal-0.log" >> "$out/foreign/journal-0.log"
msg=$("$pwl" $args --out "$out/foreign" --resume 2>&1 > /dev/null)
code=$?
echo "$msg"
[ $code -eq 2 ] || { echo "a record of point 45 was not refused ($code)"; exit 1; }
echo "$msg" | grep -qF "$out/foreign/journal-0.log line 41: a valid record of point 45, which is not a point of this study" ||
  { echo "the refusal does not name line 41"; exit 1; }
cp -r "$out/whole" "$out/conflict"
first=$(grep -n '^3 ' "$out/conflict/journal-0.log" | cut -d: -f1)
grep '^3 ' "$out/other/journal-0.log" >> "$out/conflict/journal-0.log"
msg=$("$pwl" $args --out "$out/conflict" --resume 2>&1 > /dev/null)
code=$?
echo "$msg"
[ $code -eq 2 ] || { echo "two results for point 3 were not refused ($code)"; exit 1; }
echo "$msg" | grep -qF "$out/conflict/journal-0.log line $first and $out/conflict/journal-0.log line 41 are valid records of point 3 with different results" ||
  { echo "the refusal does not name lines $first and 41"; exit 1; }
echo "foreign and conflicting records refused"
