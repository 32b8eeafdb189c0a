# Phase portrait of one mass with its stroboscopic Poincaré points, for `pwl simulate --record`.
# Variables (gnuplot -e): trajectory, poincare, out, xcol, vcol, pxcol, pvcol, mass, label.
set terminal pngcairo size 900,700 enhanced font 'DejaVu Sans,11'
set output out
set datafile separator ','
set key top right opaque
set grid lc rgb '#dddddd'
set title sprintf("Mass %d: phase portrait and Poincaré points\n{/*0.8 %s}", mass, label)
set xlabel sprintf('x_%d (nondimensional)', mass)
set ylabel sprintf("x'_%d (nondimensional)", mass)
plot trajectory using xcol:vcol every ::1 with lines lw 1 lc rgb '#4477aa' title 'trajectory', \
     poincare using pxcol:pvcol every ::1 with points pt 7 ps 1.2 lc rgb '#cc3311' title 'Poincaré points (t = kT)'
