#!/bin/sh
# A folder whose journals are of an older format (config.txt names another journal_format) is
# refused by --resume with exit code 2, naming the format it has and the one this version writes,
# and nothing in the folder is touched; the same command without --resume starts over.
# Usage: journal_format.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
rm -rf "$out"
mkdir -p "$out"
map() {
  "$pwl" map --figure 5 --x theta --x-range 1.8:1.9 --x-points 2 --y alpha --y-range 4:5 \
    --y-points 1 --transient 50 --periods 100 --quick --quiet --no-plot --out "$out/map" "$@"
}
map > /dev/null || { echo "the first map failed"; exit 1; }
grep -q '^journal_format = 5$' "$out/map/config.txt" || { echo "config.txt names no journal_format = 5"; exit 1; }
sed -i 's/^journal_format = 5$/journal_format = 4/' "$out/map/config.txt"
cp "$out/map/journal-0.log" "$out/journal.before"
map --resume > /dev/null 2> "$out/resume.err"
code=$?
[ "$code" -eq 2 ] || { echo "--resume into a format-4 folder exited $code, not 2"; cat "$out/resume.err"; exit 1; }
grep -q 'journal_format = 4' "$out/resume.err" && grep -q 'journal_format = 5' "$out/resume.err" \
  && grep -q 'older format' "$out/resume.err" \
  || { echo "the refusal does not name both formats:"; cat "$out/resume.err"; exit 1; }
cmp -s "$out/journal.before" "$out/map/journal-0.log" || { echo "the refused resume changed the journal"; exit 1; }
map > /dev/null || { echo "starting over failed"; exit 1; }
echo "an older journal format is refused by --resume: $(cat "$out/resume.err")"
