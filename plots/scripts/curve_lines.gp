# The bifurcation curves of pwl continue --curves (curves.csv) and their codimension-two points
# (codim2.csv) as plot clauses: folds black, period doublings red and dashed, Neimark-Sacker blue,
# grazings green and dotted, the codimension-two points marked. Loaded by the figures
# that draw them (bifurcation_curves.gp; regime_map.gp over a map), which append @curvelines to
# their plot command.
# Variables set before loading: curves, codim2 (the files), ncodim2 (codim2.csv's rows), xcol, ycol
# (the columns of curves.csv drawn across and up: 3 and 4 for (P, Q), 4 and 3 for (Q, P)), and
# optionally ccolors and cdashes (the four types' colours and dash types) and cmark (the
# codimension-two points' colour), which a figure over a coloured map sets to stand out from it.
# Each curve's rows: its first point, the points one way; its first point again, the points the
# other way. A line restarts at the second copy of the first point: dir says which way a row
# belongs to (pc, fp, fq: the row before's curve, the curve's first point).
track(c, p, q) = (c != pc ? (pc = c, fp = p, fq = q, dir = 0) : \
                 (p == fp && q == fq ? (dir = 1) : 0), dir)
restart(row) = row == 0 ? (pc = -1, dir = 0) : 0
pc = -1
dir = 0
ctypes = 'fold period-doubling neimark-sacker grazing'
cline(i, d, color, dash, name) = sprintf(", curves using (column(%d)):(restart($0), track($1, column(%d), column(%d)) == %d && strcol(2) eq '%s' ? column(%d) : NaN) with lines lw 2.5 dt %d lc rgb '%s' title '%s'", xcol, xcol, ycol, d, word(ctypes, i), ycol, dash, color, d == 0 ? name : '')
if (!exists("ccolors")) { ccolors = '#000000 #d62728 #1f77b4 #1a7a1a' }
if (!exists("cdashes")) { cdashes = '1 2 1 3' }
if (!exists("cmark")) { cmark = '#ff7f0e' }
curvelines = cline(1, 0, word(ccolors, 1), int(word(cdashes, 1)), 'fold curve') . cline(1, 1, word(ccolors, 1), int(word(cdashes, 1)), '') . \
             cline(2, 0, word(ccolors, 2), int(word(cdashes, 2)), 'period-doubling curve') . cline(2, 1, word(ccolors, 2), int(word(cdashes, 2)), '') . \
             cline(3, 0, word(ccolors, 3), int(word(cdashes, 3)), 'Neimark-Sacker curve') . cline(3, 1, word(ccolors, 3), int(word(cdashes, 3)), '') . \
             cline(4, 0, word(ccolors, 4), int(word(cdashes, 4)), 'grazing curve') . cline(4, 1, word(ccolors, 4), int(word(cdashes, 4)), '')
# Codimension-two points: the smooth ones (found by smooth tools too) filled and named by the short
# names of MatCont and AUTO (LPPD fold-flip, CP cusp, GPD generalised period doubling, R1..R4 the
# strong resonances, LPNS and PDNS fold- and flip-Neimark-Sacker); the non-smooth ones, where a
# contact appears or disappears (a name with "grazing"), open and unnamed: codim2.csv names them.
# (gnuplot 5.4.4 crashes on labels from a file without data rows: the points are added only when
# there are some, `ncodim2` of them, and the labels only when some are smooth.)
short(s) = s eq 'fold-flip' ? 'LPPD' : s eq 'cusp' ? 'CP' : s eq 'generalised-period-doubling' ? 'GPD' : \
           s eq 'fold-neimark-sacker' ? 'LPNS' : s eq 'period-doubling-neimark-sacker' ? 'PDNS' : \
           strstrt(s, 'resonance-1:') == 1 ? 'R'.s[13:] : s
nonsmooth(s) = strstrt(s, 'grazing') > 0
set style textbox opaque noborder margins 1,1
if (!exists("ncodim2")) { ncodim2 = 0 }
if (ncodim2 > 0) { \
  stats codim2 using (valid(2) && !nonsmooth(strcol(1)) ? 1 : 0) nooutput; \
  nsmooth = STATS_sum; \
  curvelines = curvelines . \
    sprintf(", codim2 using (nonsmooth(strcol(1)) ? column(%d) : NaN):(column(%d)) with points pt 6 ps 1.2 lw 1.5 lc rgb '%s' title 'codimension two, non-smooth'", xcol - 1, ycol - 1, cmark); \
  if (nsmooth > 0) { \
    curvelines = curvelines . \
      sprintf(", codim2 using (nonsmooth(strcol(1)) ? NaN : column(%d)):(column(%d)) with points pt 7 ps 1.4 lc rgb '%s' title 'codimension two, smooth'", xcol - 1, ycol - 1, cmark) . \
      sprintf(", codim2 using (nonsmooth(strcol(1)) ? NaN : column(%d)):(column(%d)):(short(strcol(1))) with labels boxed left offset 0.7,0.5 font ',9' notitle", xcol - 1, ycol - 1) \
  } \
}
