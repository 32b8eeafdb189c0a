# Periodic-orbit branches over a brute-force bifurcation diagram (pwl continue --over-sweep): the
# Poincaré points of a sweep of the same parameter (small grey dots, both continuation directions)
# and, on top, the Poincaré points of the continued orbits (branch_section.csv: the k points of a
# period-k orbit), stable ones filled and dark, unstable ones open and light. Where the two meet the
# sweep has settled on a stable orbit; an unstable branch shows what the sweep cannot see. The
# bifurcations found are marked by kind, as in frequency_response.gp, at their orbit's state at
# t = 0 mod T.
# Variables (gnuplot -e): poincare (bifurcation_points.csv or poincare.csv of the sweep), column
# (its column drawn, 5 = the first recorded component), section (branch_section.csv:
# parameter,branch,period,stable,iterate,components), scolumn (the same component's column there),
# bifurcations (bifurcations.csv of pwl continue), bxcolumn (the same component's column there),
# nfold, ndoubling, nns, ngrazing (as bifurcation_marks.gp takes them), out, fmt, xname, yname,
# title.
if (!exists("poincare")) poincare = 'continuation/over_sweep/bifurcation_points.csv'
if (!exists("column")) column = 5
if (!exists("section")) section = 'continuation/branch_section.csv'
if (!exists("scolumn")) scolumn = 10
if (!exists("bifurcations")) bifurcations = 'continuation/bifurcations.csv'
if (!exists("bxcolumn")) bxcolumn = 19
if (!exists("nfold")) nfold = 0
if (!exists("ndoubling")) ndoubling = 0
if (!exists("nns")) nns = 0
if (!exists("ngrazing")) ngrazing = 0
if (!exists("out")) out = 'continuation/branch_over_diagram.png'
if (!exists("xname")) xname = 'parameter'
if (!exists("yname")) yname = 'x at t = kT'
if (!exists("title")) title = ''
set datafile separator ','
call 'terminal.gp' 1400 900 12
set title title font 'DejaVu Sans,11'
set xlabel xname
set ylabel yname
set key outside right top
set grid
set autoscale xfix
mcolumn = bxcolumn
msize = 1.6
load 'bifurcation_marks.gp'
plot poincare using 1:(column(column)) with points pt 7 ps 0.15 lc rgb '#9a9a9a' notitle, \
     section using 1:($4 == 1 ? column(scolumn) : NaN) with points pt 7 ps 0.4 lc rgb '#08306b' \
       notitle, \
     section using 1:($4 == 0 ? column(scolumn) : NaN) with points pt 6 ps 0.4 lw 1 \
       lc rgb '#f28e2b' notitle, \
     NaN with points pt 7 ps 0.8 lc rgb '#9a9a9a' title 'brute-force sweep (Poincaré points)', \
     NaN with points pt 7 ps 1.2 lc rgb '#08306b' title 'orbit branch, stable', \
     NaN with points pt 6 ps 1.2 lw 1 lc rgb '#f28e2b' title 'orbit branch, unstable' @marks
