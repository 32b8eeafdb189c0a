# Regime map of a two-parameter grid (pwl map): every cell coloured by its regime, with a legend,
# and a second figure of λ1 per forcing period.
# Variables (gnuplot -e): data (map.csv of pwl map), out, out_lambda (PNGs), xname, yname, dx, dy
# (the grid spacing); with curves (a curves.csv of pwl continue --curves), codim2, ncodim2, xcol
# and ycol (curve_lines.gp), the bifurcation curves drawn over the regime map.
if (!exists("data")) data = 'plots/data/theta_alpha/map.csv'
if (!exists("out")) out = 'plots/figures/regime_map.png'
if (!exists("out_lambda")) out_lambda = 'plots/figures/lambda1_map.png'
if (!exists("xname")) xname = 'theta'
if (!exists("yname")) yname = 'alpha'
if (!exists("subtitle")) subtitle = ''
if (!exists("dx")) dx = 0.1
if (!exists("dy")) dy = 1.0
# A grid step of zero (one value on an axis) would give an empty range: draw the cell one unit wide.
if (dx <= 0) dx = 1.0
if (dy <= 0) dy = 1.0
set datafile separator ','
# The curves' legend is longer: a wider canvas keeps the map as wide as without them.
mapwidth = exists("curves") ? 1400 : 1200
call 'terminal.gp' mapwidth 800 12
color(c) = c == 1 ? 0x1f77b4 : c == 2 ? 0x2ca02c : c == 3 ? 0x17becf : c == 4 ? 0x9467bd : \
           c <= 8 ? 0x8c564b : c == 9 ? 0xbcbd22 : c == 10 ? 0xff7f0e : c == 11 ? 0xd62728 : \
           c == 12 ? 0x000000 : 0x7f7f7f
set xlabel xname
set ylabel yname
set key outside right top
stats data using 3 nooutput
set xrange [STATS_min - dx/2.0 : STATS_max + dx/2.0]
stats data using 4 nooutput
set yrange [STATS_min - dy/2.0 : STATS_max + dy/2.0]
set title 'regime of the motion'.(subtitle eq '' ? '' : "\n{/*0.8 ".subtitle."}")
curvelines = ''
# Over the map's colours: black lines (folds solid, period doublings dashed, Neimark-Sacker
# dash-dotted, grazings dotted), black codimension-two points.
if (exists("curves")) { ccolors = '#000000 #000000 #000000 #000000'; cdashes = '1 2 4 3'; cmark = '#000000'; load 'curve_lines.gp' }
plot data using 3:4:(dx/2.0):(dy/2.0):(color($6)) with boxxyerror fs solid 1.0 noborder \
       lc rgb variable notitle @curvelines, \
     NaN with boxes fs solid lc rgb '#1f77b4' title 'period-1', \
     NaN with boxes fs solid lc rgb '#2ca02c' title 'period-2', \
     NaN with boxes fs solid lc rgb '#17becf' title 'period-3', \
     NaN with boxes fs solid lc rgb '#9467bd' title 'period-4', \
     NaN with boxes fs solid lc rgb '#8c564b' title 'period-5..8', \
     NaN with boxes fs solid lc rgb '#bcbd22' title 'period > 8', \
     NaN with boxes fs solid lc rgb '#ff7f0e' title 'quasi-periodic', \
     NaN with boxes fs solid lc rgb '#d62728' title 'chaotic', \
     NaN with boxes fs solid lc rgb '#000000' title 'unbounded', \
     NaN with boxes fs solid lc rgb '#7f7f7f' title 'uncertain'
set output out_lambda
set title 'largest Lyapunov exponent λ1 per forcing period'.(subtitle eq '' ? '' : "\n{/*0.8 ".subtitle."}")
set palette defined (-0.5 '#08306b', -0.05 '#c6dbef', 0 '#ffffff', 0.05 '#fcbba1', 0.5 '#67000d')
set cbrange [-0.5:0.5]
set cblabel 'λ1'
unset key
plot data using 3:4:(dx/2.0):(dy/2.0):(strcol(8) eq '' ? NaN : $8) with boxxyerror fs solid 1.0 \
       noborder lc palette
# With --starts N: a third figure, the number of coexisting attractors reached from each cell's
# starts (column 'attractors' of map.csv).
if (exists("out_attractors")) {
  set output out_attractors
  set title 'coexisting attractors reached from each cell''s starts'.(subtitle eq '' ? '' : "\n{/*0.8 ".subtitle."}")
  set palette defined (1 '#f7fbff', 2 '#6baed6', 3 '#2171b5', 4 '#08306b')
  stats data using (column('attractors')) nooutput
  set cbrange [1 : (STATS_max > 1 ? STATS_max : 2)]
  set cbtics 1
  set cblabel 'attractors'
  plot data using 3:4:(dx/2.0):(dy/2.0):(column('attractors')) with boxxyerror fs solid 1.0 \
         noborder lc palette
}
