# Work-precision diagram: error against CPU time, log-log, one curve per method
# (pwl bench accuracy). Each curve is a CSV <data>/<stem>_<key>.csv with the columns
# parameter, cpu_seconds, error, steps, rhs_evaluations, events, step, min_cpu_seconds, repeats.
# Variables (gnuplot -e): data, stem, curves (space-separated keys), out, plot_title,
# ylabel_text. The colour and marker of a method are the same in every chart.
call 'terminal.gp' 1560 820 11
set datafile separator ','
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid xtics ytics mxtics mytics lc rgb '#e4e4e4', lc rgb '#f2f2f2'
set key outside right center box spacing 1.3 font ',10'
set title plot_title."\n{/*0.85 lower left is better. Along a curve: the step η shrinks (PIM) or the tolerance tightens (Runge-Kutta)}"
set xlabel 'CPU time per run [s] (process, median of repeated runs, construction included)'
set ylabel ylabel_text
colour(k) = k eq 'exact' ? '#000000' : \
            k eq 'pim' ? '#4477aa' : \
            k eq 'pim-switching' ? '#ee6677' : \
            k eq 'pim-switching-d4' ? '#aa3377' : \
            k eq 'dopri5' ? '#228833' : \
            k eq 'dopri5-kinks' ? '#66ccee' : \
            k eq 'rkf78' ? '#ccbb44' : \
            k eq 'rkf78-kinks' ? '#997700' : '#888888'
marker(k) = k eq 'exact' ? 3 : (k[1:3] eq 'pim' ? 7 : 9)
dashes(k) = (k eq 'dopri5' || k eq 'rkf78') ? 2 : 1
label(k) = k eq 'exact' ? 'exact event-driven (ground truth; error vs its exponential form)' : \
           k eq 'pim' ? 'PIM, the paper: linear force in the step (order 2)' : \
           k eq 'pim-switching' ? 'switching PIM, d = 2 + end slope (order 5)' : \
           k eq 'pim-switching-d4' ? 'switching PIM, d = 4 + end slope (order 7)' : \
           k eq 'dopri5' ? 'dopri5, plain (like MATLAB ode45)' : \
           k eq 'dopri5-kinks' ? 'dopri5, kink-located' : \
           k eq 'rkf78' ? 'rkf78, plain' : \
           k eq 'rkf78-kinks' ? 'rkf78, kink-located' : k
plot for [k in curves] sprintf('%s/%s_%s.csv', data, stem, k) every ::1 using 2:3 \
     with linespoints lw 2 pt marker(k) ps 1.4 dt dashes(k) lc rgb colour(k) title label(k)
