#!/bin/sh
# A full output folder loses nothing that was finished. Under a file size limit (ulimit -f) a
# sweep's journal stops growing part-way: the run ends with exit code 1 and a message naming the
# journal and the system's reason (EFBIG: pwl ignores SIGXFSZ, which would kill it with no word),
# the journal keeps whole lines only, and --resume without the limit ends with the same files,
# byte for byte, as an uninterrupted run. With a limit that the journal fits and poincare.csv
# does not, the result files fail instead: exit code 1, every point kept, and --resume only
# writes the files. With MODE tmpfs, the first case on a 64 KiB tmpfs (ENOSPC) mounted in a
# mount namespace of its own; skipped (77) where no mount namespace can be made.
# Usage: full_disk.sh PWL OUTPUT_FOLDER [ulimit|tmpfs]
set -u
pwl=$1
out=$2
mode=${3:-ulimit}
# On one line: it goes into sh -c below.
# The plain record (--quick): this test is about the journal's faults, not the verdicts; the
# evidence ladder's journaling is checked by the kill-and-resume and identical-runs tests.
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 30 --mode continuation --transient 100 --periods 300 --record x5 --threads 2 --quiet --no-plot --quick"
rm -rf "$out"
mkdir -p "$out"
"$pwl" $args --out "$out/whole" > /dev/null || { echo "the uninterrupted run failed"; exit 1; }
journal_bytes=$(wc -c < "$out/whole/journal-0.log")

# A whole line at the end and every line valid: the resumed run, told to go on, finds as many
# records as the journal has lines, and no damaged or torn line.
resume_and_compare() {
  folder=$1
  lines=$(wc -l < "$folder/journal-0.log")
  [ "$(tail -c 1 "$folder/journal-0.log" | od -An -c | tr -d ' ')" = '\n' ] ||
    { echo "the journal does not end with a whole line"; exit 1; }
  "$pwl" $args --out "$folder" --resume > /dev/null 2> "$folder.resume.err" ||
    { cat "$folder.resume.err"; echo "the resumed run failed"; exit 1; }
  cat "$folder.resume.err"
  grep -qF "resuming in $folder: $lines of 60 points are journaled" "$folder.resume.err" ||
    { echo "the resumed run did not find the $lines lines"; exit 1; }
  grep -q "warning\|note" "$folder.resume.err" && { echo "the journal had damaged lines"; exit 1; }
  for f in poincare.csv classification.csv; do
    cmp "$out/whole/$f" "$folder/$f" || exit 1
  done
}

if [ "$mode" = tmpfs ]; then
  mkdir "$out/disk"
  # The run inside the namespace, then its folder copied out before the tmpfs goes with it.
  inside="mount -t tmpfs -o size=64k tmpfs '$out/disk' || exit 77
          '$pwl' $args --out '$out/disk/full' > /dev/null 2> '$out/full.err'
          echo \$? > '$out/full.code'
          cp -r '$out/disk/full' '$out/full'"
  unshare -m sh -c "$inside" 2> /dev/null || unshare -rm sh -c "$inside" 2> /dev/null ||
    { echo "SKIP: no mount namespace with a tmpfs can be made here"; exit 77; }
  reason="No space left on device"
else
  # The unit of ulimit -f in this shell (512 or 1024 bytes): the size of a file it cut at 1.
  (trap '' XFSZ; ulimit -f 1; head -c 4096 /dev/zero > "$out/unit") 2> /dev/null
  unit=$(wc -c < "$out/unit")
  # A third of the journal fits.
  sh -c "ulimit -f $((journal_bytes / 3 / unit)); exec '$pwl' $args --out '$out/full'" \
     > /dev/null 2> "$out/full.err"
  echo $? > "$out/full.code"
  reason="File too large"
fi
cat "$out/full.err"
code=$(cat "$out/full.code")
[ "$code" -eq 1 ] || { echo "exit code $code, not 1"; exit 1; }
lines=$(wc -l < "$out/full/journal-0.log")
[ "$lines" -ge 1 ] && [ "$lines" -lt 60 ] || { echo "$lines points journaled"; exit 1; }
grep -qE "^pwl: cannot append point [0-9]+ to $out/(disk/)?full/journal-0.log: $reason; the $lines of 60 points journaled before are kept in $out/(disk/)?full: once it can be written, run the same command with --resume to finish\$" "$out/full.err" ||
  { echo "no message naming the journal, '$reason' and $lines points"; exit 1; }
[ -e "$out/full/poincare.csv" ] && { echo "result files written"; exit 1; }
resume_and_compare "$out/full"
echo "journal full after $lines points: resumed, identical"
[ "$mode" = tmpfs ] && exit 0

# The journal fits, poincare.csv (two fifths larger per point here) does not.
poincare_bytes=$(wc -c < "$out/whole/poincare.csv")
limit=$(((journal_bytes + poincare_bytes) / 2 / unit))
[ $((limit * unit)) -gt "$journal_bytes" ] && [ $((limit * unit)) -lt "$poincare_bytes" ] ||
  { echo "no limit between the journal ($journal_bytes bytes) and poincare.csv ($poincare_bytes)"; exit 1; }
sh -c "ulimit -f $limit; exec '$pwl' $args --out '$out/files'" > /dev/null 2> "$out/files.err"
code=$?
cat "$out/files.err"
[ "$code" -eq 1 ] || { echo "exit code $code, not 1"; exit 1; }
grep -qF "every point is journaled in $out/files: once it can be written, run the same command with --resume to write the result files" "$out/files.err" ||
  { echo "no message saying every point is kept"; exit 1; }
[ "$(wc -l < "$out/files/journal-0.log")" -eq 60 ] || { echo "not every point journaled"; exit 1; }
resume_and_compare "$out/files"
grep -qF "60 of 60 points are journaled, 0 to compute" "$out/files.resume.err" || exit 1
echo "result files too large: every point kept, files written by --resume, identical"
