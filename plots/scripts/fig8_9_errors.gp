# The paper's figures 8 and 9: error of x1 and x1' of one method against the reference, over the
# run of the 1000-mass chain. Two panels: (a) displacement, (b) velocity.
# Variables (gnuplot -e): data (CSV t,error_x1,error_v1), out (PNG), fig (8 or 9), method,
# params (the chain), reference, ex and ev (largest errors, as text).
call 'terminal.gp' 1000 900 11
set datafile separator ','
set grid lc rgb '#dddddd'
set key top left opaque box
set format y '%.1e'
set multiplot layout 2,1 title sprintf("Figure %d: error of mass 1, %s, against %s\n{/*0.8 %s}", fig, method, reference, params)
set title sprintf('(a) displacement: δ_x = x_1 - x_{1,ref} (largest |δ_x| %s m)', ex)
set xlabel 't (s)'
set ylabel 'δ_x (m)'
plot data using 1:2 every ::1 with lines lw 1 lc rgb '#4477aa' title 'δ_x'
set title sprintf("(b) velocity: δ_v = x'_1 - x'_{1,ref} (largest |δ_v| %s m/s)", ev)
set ylabel 'δ_v (m/s)'
plot data using 1:3 every ::1 with lines lw 1 lc rgb '#cc3311' title 'δ_v'
unset multiplot
