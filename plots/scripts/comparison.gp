# Phase portrait of one mass by two methods on the same time grid, with their stroboscopic
# Poincaré points (pwl simulate --compare-with; the paper's figures 4a and 4b). The first method
# is drawn thin over the second, thick and grey, so that a gap between them shows.
# Variables (gnuplot -e): out, fmt, trajectory, reference_trajectory, poincare,
# reference_poincare, xcol, vcol (trajectory columns), pxcol, pvcol (Poincaré columns), mass,
# method, reference, title, subtitle.
call 'terminal.gp' 900 780 11
set datafile separator ','
set key below horizontal box
set grid lc rgb '#dddddd'
set title sprintf("%s\n{/*0.8 %s}", title, subtitle)
set xlabel sprintf('x_%d (nondimensional, k_1x/A)', mass)
set ylabel sprintf("x'_%d (nondimensional)", mass)
plot reference_trajectory using xcol:vcol every ::1 with lines lw 4 lc rgb '#bbbbbb' title reference, \
     trajectory using xcol:vcol every ::1 with lines lw 1 lc rgb '#4477aa' title method, \
     reference_poincare using pxcol:pvcol every ::1 with points pt 6 ps 2.2 lw 2 lc rgb '#222222' title 'Poincaré points, '.reference, \
     poincare using pxcol:pvcol every ::1 with points pt 7 ps 1.0 lc rgb '#cc3311' title 'Poincaré points, '.method
