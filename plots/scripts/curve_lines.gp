# The bifurcation curves of pwl continue --curves (curves.csv) and their codimension-two points
# (codim2.csv) as plot clauses: folds black, period doublings red and dashed, Neimark-Sacker blue,
# grazings green and dotted, the codimension-two points marked and named. Loaded by the figures
# that draw them (bifurcation_curves.gp; regime_map.gp over a map), which append @curvelines to
# their plot command.
# Variables set before loading: curves, codim2 (the files), ncodim2 (codim2.csv's rows), xcol, ycol
# (the columns of curves.csv drawn across and up: 3 and 4 for (P, Q), 4 and 3 for (Q, P)).
# Each curve's rows: its first point, the points one way; its first point again, the points the
# other way. A line restarts at the second copy of the first point: dir says which way a row
# belongs to (pc, fp, fq: the row before's curve, the curve's first point).
track(c, p, q) = (c != pc ? (pc = c, fp = p, fq = q, dir = 0) : \
                 (p == fp && q == fq ? (dir = 1) : 0), dir)
restart(row) = row == 0 ? (pc = -1, dir = 0) : 0
pc = -1
dir = 0
ctypes = 'fold period-doubling neimark-sacker grazing'
cline(i, d, color, dash, name) = sprintf(", curves using (column(%d)):(restart($0), track($1, column(%d), column(%d)) == %d && strcol(2) eq '%s' ? column(%d) : NaN) with lines lw 2 dt %d lc rgb '%s' title '%s'", xcol, xcol, ycol, d, word(ctypes, i), ycol, dash, color, d == 0 ? name : '')
curvelines = cline(1, 0, '#000000', 1, 'fold curve') . cline(1, 1, '#000000', 1, 'fold curve') . \
             cline(2, 0, '#d62728', 2, 'period-doubling curve') . cline(2, 1, '#d62728', 2, '') . \
             cline(3, 0, '#1f77b4', 1, 'Neimark-Sacker curve') . cline(3, 1, '#1f77b4', 1, '') . \
             cline(4, 0, '#2ca02c', 3, 'grazing curve') . cline(4, 1, '#2ca02c', 3, '')
# (gnuplot 5.4.4 crashes on labels from a file without data rows: the points are added only when
# there are some, `ncodim2` of them.)
if (!exists("ncodim2")) ncodim2 = 0
if (ncodim2 > 0) { \
  curvelines = curvelines . \
    sprintf(", codim2 using (column(%d)):(column(%d)) with points pt 7 ps 1.4 lc rgb '#ff7f0e' title 'codimension two'", xcol - 1, ycol - 1) . \
    sprintf(", codim2 using (column(%d)):(column(%d)):1 with labels left offset 0.8,0.6 font ',8' notitle", xcol - 1, ycol - 1) \
}
