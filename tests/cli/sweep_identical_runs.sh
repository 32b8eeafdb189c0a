#!/bin/sh
# A small sweep run serially, on two OpenMP threads and (when an mpirun is given) on two MPI ranks
# writes identical files. Usage: sweep_identical_runs.sh PWL OUTPUT_FOLDER MODE [MPIRUN...]
set -u
pwl=$1
out=$2
mode=$3
shift 3
args="sweep --figure 5 --parameter theta --range 0.8:2.6 --points 12 --mode $mode
      --transient 50 --periods 120 --quiet --no-plot"
rm -rf "$out"
mkdir -p "$out"
if [ $# -gt 0 ]; then
  "$@" "$pwl" $args --threads 1 --out "$out/mpi" > /dev/null || { echo "the MPI run failed"; exit 1; }
  other=mpi
else
  "$pwl" $args --threads 2 --out "$out/openmp" > /dev/null || { echo "the OpenMP run failed"; exit 1; }
  other=openmp
fi
"$pwl" $args --threads 1 --out "$out/serial" > /dev/null || { echo "the serial run failed"; exit 1; }
for f in poincare.csv classification.csv; do
  cmp "$out/serial/$f" "$out/$other/$f" || exit 1
done
lines=$(wc -l < "$out/serial/classification.csv")
echo "serial and $other identical ($lines lines)"
