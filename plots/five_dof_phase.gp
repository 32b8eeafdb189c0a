# The paper's figures 4-6: phase portrait of mass 5 with its stroboscopic Poincaré points,
# the PIM (η = T/200) drawn over the kink-located dopri5 reference (tolerance 1e-10).
# Variables (gnuplot -e): data, fig, out, fmt (png|svg), params, points, diff.
if (fmt eq 'svg') { set terminal svg size 900,760 dynamic enhanced font 'DejaVu Sans,13' } \
else { set terminal pngcairo size 900,760 enhanced font 'DejaVu Sans,11' }
set output out
set datafile separator ','
set key below horizontal box
set grid lc rgb '#dddddd'
set title sprintf("Figure %s: mass 5, %s\n{/*0.85 trajectory of the last 20 periods; %d distinct Poincaré points; largest PIM - reference difference %s}", fig, params, points, diff)
set xlabel 'x_5 (nondimensional, k_1x/A)'
set ylabel "x'_5 (nondimensional)"
plot sprintf('%s/fig%s_reference.csv', data, fig) using 2:3 every ::1 with lines lw 4 lc rgb '#bbbbbb' title 'dopri5, kink-located, tol 1e-10', \
     sprintf('%s/fig%s_pim.csv', data, fig) using 2:3 every ::1 with lines lw 1 lc rgb '#4477aa' title 'PIM, η = T/200', \
     sprintf('%s/fig%s_poincare.csv', data, fig) using 4:5 every ::1 with points pt 6 ps 2.2 lw 2 lc rgb '#222222' title 'Poincaré, reference', \
     sprintf('%s/fig%s_poincare.csv', data, fig) using 2:3 every ::1 with points pt 7 ps 1.0 lc rgb '#cc3311' title 'Poincaré, PIM'
