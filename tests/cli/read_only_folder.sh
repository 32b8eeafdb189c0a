#!/bin/sh
# An output folder that cannot be written is a clear error before any point is computed: exit
# code 1 and a message naming the folder and the system's reason, for a new run into a read-only
# folder and for a resumed run whose folder became read-only (its journal then left as it was);
# once writable again, --resume ends with the same files, byte for byte, as an uninterrupted run.
# A folder path through a regular file is refused the same way. As root, whom permissions do not
# stop, the folder is made immutable (chattr +i); where neither works, skipped (77).
# Usage: read_only_folder.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
# Few, short points (what is tested is the folder, not the sweep): 10 points up and down.
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 5 --mode continuation
      --transient 50 --periods 50 --threads 2 --quiet --no-plot"
# chattr -i first: a run that failed half-way may have left a folder immutable.
[ -d "$out" ] && chattr -R -i "$out" 2> /dev/null
rm -rf "$out"
mkdir -p "$out"

how=""
lock() {  # makes the folders and files given read-only (for this user)
  if [ "$(id -u)" -ne 0 ]; then
    chmod a-w "$@"
    how="chmod a-w"
  else
    chattr +i "$@" 2> /dev/null || return 1
    how="chattr +i"
  fi
}
unlock() {
  if [ "$(id -u)" -ne 0 ]; then chmod u+w "$@"; else chattr -i "$@"; fi
}

"$pwl" $args --out "$out/whole" > /dev/null || { echo "the uninterrupted run failed"; exit 1; }

# A new run into an empty read-only folder.
mkdir "$out/locked"
if ! lock "$out/locked" || touch "$out/locked/probe" 2> /dev/null; then
  rm -f "$out/locked/probe"
  echo "SKIP: no way to make a folder read-only here (root, and chattr +i does not work)"
  exit 77
fi
trap 'unlock "$out/locked" "$out/resumed" "$out/resumed/journal-0.log" 2> /dev/null' EXIT
echo "read-only by $how"
msg=$("$pwl" $args --out "$out/locked" 2>&1 > /dev/null)
code=$?
echo "$msg"
[ $code -eq 1 ] || { echo "exit code $code, not 1"; exit 1; }
echo "$msg" | grep -qE "^pwl: cannot create files in the output folder $out/locked: (Permission denied|Operation not permitted)\$" ||
  { echo "no message naming the folder and the reason"; exit 1; }
[ -z "$(ls -A "$out/locked")" ] || { echo "files were written"; exit 1; }

# A killed run (the first 4 points journaled) whose folder became read-only, resumed.
mkdir "$out/resumed"
cp "$out/whole/config.txt" "$out/resumed/"
head -n 4 "$out/whole/journal-0.log" > "$out/resumed/journal-0.log"
cp "$out/resumed/journal-0.log" "$out/journal.before"
lock "$out/resumed" "$out/resumed/journal-0.log"
msg=$("$pwl" $args --out "$out/resumed" --resume 2>&1 > /dev/null)
code=$?
echo "$msg"
[ $code -eq 1 ] || { echo "exit code $code, not 1"; exit 1; }
echo "$msg" | grep -qE "^pwl: cannot create files in the output folder $out/resumed: (Permission denied|Operation not permitted)\$" ||
  { echo "no message naming the folder and the reason"; exit 1; }
cmp "$out/journal.before" "$out/resumed/journal-0.log" || { echo "the journal changed"; exit 1; }
unlock "$out/resumed" "$out/resumed/journal-0.log"
"$pwl" $args --out "$out/resumed" --resume > /dev/null 2> "$out/resume.err" ||
  { cat "$out/resume.err"; echo "the resumed run failed"; exit 1; }
cat "$out/resume.err"
grep -qF "resuming in $out/resumed: 4 of 10 points are journaled, 6 to compute" "$out/resume.err" ||
  { echo "the 4 journaled points were not kept"; exit 1; }
for f in poincare.csv classification.csv; do
  cmp "$out/whole/$f" "$out/resumed/$f" || exit 1
done

# A folder path through a regular file.
: > "$out/a_file"
msg=$("$pwl" $args --out "$out/a_file/sweep" 2>&1 > /dev/null)
code=$?
echo "$msg"
[ $code -eq 1 ] && echo "$msg" | grep -qF "pwl: cannot create the output folder $out/a_file/sweep: Not a directory" ||
  { echo "a folder under a file was not refused with its reason ($code)"; exit 1; }
echo "read-only folders refused, nothing lost, resumed identical"
