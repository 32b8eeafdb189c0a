#!/bin/sh
# A sweep of an explicit structure's gap, checked against the closed form: the two-mass stop of
# apps/scenes/two_mass_stop.toml with its clearance spring moved out of reach, its stop's gap swept
# over values the motion never reaches. There the motion is the linear structure's, and every
# Poincaré point (t = kT after the transient) is the steady state of M x'' + C x' + K x = F sin ωt:
# x = Im X, v = ω Re X with (K - ω² M + iω C) X = F. Also a map of the gap and the load amplitude,
# whose cells far from the stop are period-1 with λ1 = -c/(2m) T.
# Usage: structure_sweep_linear.sh PWL OUTPUT_FOLDER
set -u
pwl=$1
out=$2
rm -rf "$out"
mkdir -p "$out"
cat > "$out/linear.toml" << 'SCENE'
job = "sweep"
[structure]
mass = [[1.0, 0.0], [0.0, 1.0]]
damping = [[0.1, 0.0], [0.0, 0.1]]
stiffness = [[2.0, -1.0], [-1.0, 1.0]]
spring = [{ mass = 2, stiffness = 4.0, gap = 0.2 },
          { mass = 1, other_mass = 2, direction = -1, stiffness = 1.0, gap = 50.0 }]
load = [{ mass = 2, amplitude = 1.0, omega = 1.2 }]
SCENE
"$pwl" run "$out/linear.toml" --set sweep.parameter=spring1.gap --set sweep.range=50:100 \
  --set sweep.points=3 --set run.transient=400 --set run.periods=100 \
  --set run.record=x1,x2,v1,v2 --set output.out="$out/sweep" > /dev/null \
  || { echo "the sweep failed"; exit 1; }
test -s "$out/sweep/bifurcation.png" || { echo "no bifurcation.png"; exit 1; }
head -n 1 "$out/sweep/classification.csv" | grep -q '^index,spring1.gap,direction,regime,' \
  || { echo "classification.csv does not name spring1.gap"; exit 1; }
# The closed form for M = I, C = 0.1 I, K = [2 -1; -1 1], F = (0, 1), ω = 1.2:
# A = K - ω² + iωC, X = A⁻¹ F = (1, a11) / (a11 a22 - 1).
awk -F, -v w=1.2 '
  NR == 1 { next }
  { last[$3] = $0 }
  END {
    ar = 2 - w * w; ai = 0.1 * w          # a11
    br = 1 - w * w; bi = 0.1 * w          # a22
    dr = ar * br - ai * bi - 1; di = ar * bi + ai * br
    m = dr * dr + di * di
    x1r = dr / m; x1i = -di / m           # 1 / det
    x2r = (ar * dr + ai * di) / m; x2i = (ai * dr - ar * di) / m  # a11 / det
    want[5] = x1i; want[6] = x2i; want[7] = w * x1r; want[8] = w * x2r
    worst = 0; rows = 0
    for (i in last) {
      split(last[i], f, ",")
      for (c = 5; c <= 8; ++c) { d = f[c] - want[c]; if (d < 0) d = -d; if (d > worst) worst = d }
      ++rows
    }
    printf "largest difference from the steady state over %d gaps: %.3g\n", rows, worst
    exit !(rows == 3 && worst < 1e-8)
  }' "$out/sweep/poincare.csv" || { echo "not the linear steady state"; exit 1; }
grep -c ',period-1,1,1,' "$out/sweep/classification.csv" | grep -q '^3$' \
  || { echo "the points far from the stop are not period-1"; exit 1; }
# A map of the gap and the load amplitude.
"$pwl" map --structure-scene "$out/linear.toml" --x spring1.gap --x-range 0.05:60 --x-points 3 \
  --y load1.amplitude --y-range 0.5:1 --y-points 2 --transient 300 --periods 100 --quiet \
  --out "$out/map" > /dev/null || { echo "the map failed"; exit 1; }
test -s "$out/map/regime_map.png" && test -s "$out/map/lambda1_map.png" \
  || { echo "no map figures"; exit 1; }
head -n 1 "$out/map/map.csv" | grep -q '^i,j,spring1.gap,load1.amplitude,regime,code,' \
  || { echo "map.csv does not name its parameters"; exit 1; }
awk -F, -v t=5.235987755982988 'NR > 1 && $3 > 1 {
    d = $8 + 0.05 * t; if (d < 0) d = -d
    if ($5 != "period-1" || d > $9 + 1e-3) bad = 1; ++cells
  } END { exit !(cells == 4 && !bad) }' "$out/map/map.csv" \
  || { echo "the map's cells far from the stop are not the linear motion"; exit 1; }
echo "the sweep and the map of the explicit structure meet the linear steady state"
