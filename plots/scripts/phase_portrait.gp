# Phase portrait of one mass with its stroboscopic Poincaré points, for `pwl simulate --record`.
# Variables (gnuplot -e): trajectory, poincare, out, fmt, xcol, vcol, pxcol, pvcol, mass, label,
# title ('' for the default).
call 'terminal.gp' 900 700 11
set datafile separator ','
set key top right opaque
set grid lc rgb '#dddddd'
if (!exists("title") || title eq '') title = sprintf('Mass %d: phase portrait and Poincaré points', mass)
set title sprintf("%s\n{/*0.8 %s}", title, label)
set xlabel sprintf('x_%d (nondimensional)', mass)
set ylabel sprintf("x'_%d (nondimensional)", mass)
plot trajectory using xcol:vcol every ::1 with lines lw 1 lc rgb '#4477aa' title 'trajectory', \
     poincare using pxcol:pvcol every ::1 with points pt 7 ps 1.2 lc rgb '#cc3311' title 'Poincaré points (t = kT)'
