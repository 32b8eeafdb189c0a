# Bifurcation diagram of a parameter sweep (pwl sweep): the Poincaré points of one state
# component against the swept parameter, the upward and downward continuation branches in two
# colours, and below them a strip coloured by the regime of every point.
# Variables (gnuplot -e): poincare (bifurcation_points.csv or poincare.csv of pwl sweep), classes
# (classification.csv), out, fmt, column (the
# column to draw, 5 = the first recorded component), xname, yname, title; and, to draw the
# periodic-orbit branches of pwl continue over the points (pwl sweep --branches), branches (its
# branch_section.csv: parameter,branch,period,stable,iterate,components) and bcolumn (the column of
# the drawn component there).
if (!exists("poincare")) poincare = 'plots/data/theta_sweep/poincare.csv'
if (!exists("classes")) classes = 'plots/data/theta_sweep/classification.csv'
if (!exists("out")) out = 'plots/figures/bifurcation.png'
if (!exists("column")) column = 5
if (!exists("xname")) xname = 'theta'
if (!exists("yname")) yname = 'x5'
if (!exists("title")) title = ''
if (!exists("branches")) branches = ''
if (!exists("bcolumn")) bcolumn = 6
# The branches' points: stable ones filled and dark, unstable ones open and light (an empty
# macro without branches, so that the plot is the same as before).
overlay = branches eq '' ? '' : \
  ", branches using 1:($4 == 1 ? column(bcolumn) : NaN) with points pt 7 ps 0.4 lc rgb '#111111' title 'orbit branch, stable', " . \
  "branches using 1:($4 == 0 ? column(bcolumn) : NaN) with points pt 6 ps 0.4 lc rgb '#e377c2' title 'orbit branch, unstable'"
set datafile separator ','
call 'terminal.gp' 1400 900 12
# Regime codes (sweep_point.hpp): 1..8 period-k, 9 longer period, 10 quasi-periodic, 11 chaotic,
# 12 unbounded, 13 uncertain.
color(c) = c == 1 ? 0x1f77b4 : c == 2 ? 0x2ca02c : c == 3 ? 0x17becf : c == 4 ? 0x9467bd : \
           c <= 8 ? 0x8c564b : c == 9 ? 0xbcbd22 : c == 10 ? 0xff7f0e : c == 11 ? 0xd62728 : \
           c == 12 ? 0x000000 : 0x7f7f7f
set multiplot title title font 'DejaVu Sans,11'
set lmargin at screen 0.09
set rmargin at screen 0.80
set tmargin at screen 0.95
set bmargin at screen 0.25
set xlabel ''
set format x ''
set ylabel yname
set key outside right top
set grid
stats poincare using 1 nooutput
# A sweep of one value (or of one value left after the unbounded points) has an empty range: give
# it a small width around that value. A range of positive width is drawn as it is.
xwidth = STATS_max > STATS_min ? 0 : (STATS_min == 0 ? 0.5 : 0.05 * abs(STATS_min))
set xrange [STATS_min - xwidth : STATS_max + xwidth]
plot poincare using 1:(strcol(2) eq 'up' ? column(column) : NaN) with points pt 7 ps 0.12 lc rgb '#1f3fbf' \
       notitle, \
     poincare using 1:(strcol(2) eq 'down' ? column(column) : NaN) with points pt 7 ps 0.12 lc rgb '#d9531e' \
       notitle, \
     NaN with points pt 7 lc rgb '#1f3fbf' title 'upward (or independent)', \
     NaN with points pt 7 lc rgb '#d9531e' title 'downward' @overlay, \
     NaN with points pt 0 lc rgb 'white' title ' ', \
     NaN with points pt 0 lc rgb 'white' title 'regime strip:', \
     NaN with points pt 5 lc rgb '#1f77b4' title 'period-1', \
     NaN with points pt 5 lc rgb '#2ca02c' title 'period-2', \
     NaN with points pt 5 lc rgb '#17becf' title 'period-3', \
     NaN with points pt 5 lc rgb '#9467bd' title 'period-4', \
     NaN with points pt 5 lc rgb '#8c564b' title 'period-5..8', \
     NaN with points pt 5 lc rgb '#bcbd22' title 'period > 8', \
     NaN with points pt 5 lc rgb '#ff7f0e' title 'quasi-periodic', \
     NaN with points pt 5 lc rgb '#d62728' title 'chaotic', \
     NaN with points pt 5 lc rgb '#000000' title 'unbounded', \
     NaN with points pt 5 lc rgb '#7f7f7f' title 'uncertain'
unset grid
set tmargin at screen 0.22
set bmargin at screen 0.08
set format x '%g'
set xlabel xname
set ylabel ''
set yrange [-0.5:1.5]
set ytics ('down' 0, 'up' 1)
unset key
plot classes using 2:(strcol(3) eq 'up' ? 1 : 0):(color($5)) with points pt 5 ps 1.2 \
       lc rgb variable notitle
unset multiplot
