# The paper's figure 7: phase portrait of mass 1 of the 1000-mass chain for t in [100, 200] s.
# Variables (gnuplot -e): data (CSV t,x1,v1), out (PNG), params (the chain), method.
set terminal pngcairo size 900,760 enhanced font 'DejaVu Sans,11'
set output out
set datafile separator ','
set key top right opaque box
set grid lc rgb '#dddddd'
set title sprintf("Figure 7: phase portrait of mass 1, t in [100, 200] s\n{/*0.8 %s}\n{/*0.8 %s}", method, params)
set xlabel 'x_1 (m)'
set ylabel "x'_1 (m/s)"
plot data using 2:3 every ::1 with lines lw 1 lc rgb '#4477aa' title method
