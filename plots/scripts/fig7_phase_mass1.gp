# The paper's figure 7: phase portrait of mass 1 of the section 4.2 chain over the second half of
# the run. Variables (gnuplot -e): data (CSV t,x1,v1), out, fmt, params (the chain), method,
# t_from, t_to.
call 'terminal.gp' 900 760 11
set datafile separator ','
set key top right opaque box
set grid lc rgb '#dddddd'
set title sprintf("Figure 7: phase portrait of mass 1, t in [%g, %g] s\n{/*0.8 %s}\n{/*0.8 %s}", t_from, t_to, method, params)
set xlabel 'x_1 (m)'
set ylabel "x'_1 (m/s)"
plot data using 2:3 every ::1 with lines lw 1 lc rgb '#4477aa' title method
