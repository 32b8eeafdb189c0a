# Stability and failure chart (pwl bench stability): for each method, what happens at each
# contact stiffness ratio α = k2/k1 and step (or tolerance), and the CPU time it needs to reach
# the target error. Files: <data>/stability_<method>.csv with the columns alpha, parameter,
# status (0 ok, 1 blows up, 2 refused, 3 misses contacts, 4 wrong regime), error, cpu_seconds,
# events_seen, events_exact, period_seen, period_exact, run_error (-1: not measured);
# <data>/stability_cost.csv with alpha and
# one column per method. Variables (gnuplot -e): data, out, target (a number), periods,
# accuracy_periods, plot_title.
call 'terminal.gp' 1500 950 10
set datafile separator ','
status_colour(s) = s == 0 ? 0x228833 : s == 1 ? 0xcc3311 : s == 2 ? 0x999999 : s == 3 ? 0xee7733 : 0xaa3377
# filled square: ok and within the target; open square: ok but less accurate; triangle: a
# failure; open circle: refused
status_marker(s, e) = s == 0 ? (e >= 0 && e <= target ? 5 : 4) : (s == 2 ? 6 : 9)
set multiplot layout 2,3 title plot_title font ',13'
set logscale x
set format x '10^{%L}'
set xrange [0.3:3e6]
set xlabel 'contact stiffness ratio α = k_2/k_1'
set grid lc rgb '#e4e4e4'
set key top left horizontal maxrows 3 box opaque font ',8' width -2

set logscale y 2
set yrange [15:120000]
set ytics (16, 64, 256, 1024, 4096)
set ylabel 'steps per forcing period T/η'
set title 'PIM (the paper): linear force in the step'
plot sprintf('%s/stability_pim.csv', data) every ::1 using 1:2:(status_marker($3,$4)):(status_colour($3)) \
       with points pt variable lc rgb variable ps 2.2 notitle, \
     NaN with points pt 5 ps 1.5 lc rgb '#228833' title sprintf('ok, error ≤ %g', target), \
     NaN with points pt 4 ps 1.5 lc rgb '#228833' title 'ok, less accurate', \
     NaN with points pt 9 ps 1.5 lc rgb '#cc3311' title 'blows up', \
     NaN with points pt 9 ps 1.5 lc rgb '#ee7733' title 'misses contacts', \
     NaN with points pt 9 ps 1.5 lc rgb '#aa3377' title 'wrong regime (period)', \
     NaN with points pt 6 ps 1.5 lc rgb '#999999' title 'refused (step too large)'
unset key
set title 'switching PIM, d = 2 (refuses η ω_{max} > 2)'
plot sprintf('%s/stability_pim-switching.csv', data) every ::1 using 1:2:(status_marker($3,$4)):(status_colour($3)) \
       with points pt variable lc rgb variable ps 2.2 notitle

unset logscale y
set logscale y
set ytics autofreq
set yrange [3e-13:3e-3]
set format y '10^{%L}'
set ylabel 'tolerance (relative = absolute)'
set title 'dopri5, plain (like MATLAB ode45)'
plot sprintf('%s/stability_dopri5.csv', data) every ::1 using 1:2:(status_marker($3,$4)):(status_colour($3)) \
       with points pt variable lc rgb variable ps 2.2 notitle
set title 'dopri5, kink-located'
plot sprintf('%s/stability_dopri5-kinks.csv', data) every ::1 using 1:2:(status_marker($3,$4)):(status_colour($3)) \
       with points pt variable lc rgb variable ps 2.2 notitle
set title 'rkf78, kink-located'
plot sprintf('%s/stability_rkf78-kinks.csv', data) every ::1 using 1:2:(status_marker($3,$4)):(status_colour($3)) \
       with points pt variable lc rgb variable ps 2.2 notitle

set yrange [*:*]
set ylabel sprintf('CPU time to reach error ≤ %g [s]', target)
set title sprintf('cost of an error ≤ %g over the first %d periods (cheapest setting)', target, accuracy_periods)
set key top left box opaque font ',9'
set key
plot sprintf('%s/stability_cost.csv', data) every ::1 using 1:2 with linespoints lw 2 pt 3 lc rgb '#000000' title 'exact event-driven', \
     '' every ::1 using 1:3 with linespoints lw 2 pt 7 lc rgb '#4477aa' title 'PIM (paper)', \
     '' every ::1 using 1:4 with linespoints lw 2 pt 7 lc rgb '#ee6677' title 'switching PIM d = 2', \
     '' every ::1 using 1:5 with linespoints lw 2 pt 9 dt 2 lc rgb '#228833' title 'dopri5 plain', \
     '' every ::1 using 1:6 with linespoints lw 2 pt 9 lc rgb '#66ccee' title 'dopri5 kink-located', \
     '' every ::1 using 1:7 with linespoints lw 2 pt 9 lc rgb '#997700' title 'rkf78 kink-located'
unset multiplot
