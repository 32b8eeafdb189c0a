# Two panels like the paper's figures 4-6: the phase portrait of one mass (left) and its
# stroboscopic Poincaré map (right), for `pwl analyze`.
# Variables (gnuplot -e): trajectory, poincare, out, pxcol, pvcol, mass, label; optional ptitle,
# the right panel's title (default: the stroboscopic section at t = kT).
call 'terminal.gp' 1400 620 11
set datafile separator ','
set multiplot layout 1,2 title label font ',13'
set grid lc rgb '#dddddd'
set xlabel sprintf('x_%d (nondimensional)', mass)
set ylabel sprintf("x'_%d (nondimensional)", mass)
set title 'Phase portrait (last 20 periods)'
plot trajectory using 2:3 every ::1 with lines lw 1 lc rgb '#4477aa' notitle
if (!exists('ptitle')) ptitle = 'Poincaré map (t = kT, every recorded period)'
set title ptitle
plot poincare using pxcol:pvcol every ::1 with points pt 7 ps 0.5 lc rgb '#cc3311' notitle
unset multiplot
