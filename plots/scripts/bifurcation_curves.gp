# Bifurcation curves in two parameters (pwl continue --curves): every curve in the plane (P, Q),
# each type in its own style, and the codimension-two points marked and named (curve_lines.gp).
# Variables (gnuplot -e): curves (curves.csv: curve,type,P,Q,...), codim2 (codim2.csv:
# type,P,Q,curves,detail), ncodim2 (its rows), out, fmt, xname, yname, title, and optionally
# xlo, xhi, ylo, yhi (the rectangle the curves were followed in: the figure's frame).
if (!exists("curves")) curves = 'continuation/curves.csv'
if (!exists("codim2")) codim2 = 'continuation/codim2.csv'
if (!exists("out")) out = 'continuation/bifurcation_curves.png'
if (!exists("xname")) xname = 'P'
if (!exists("yname")) yname = 'Q'
if (!exists("title")) title = ''
set datafile separator ','
xcol = 3
ycol = 4
load 'curve_lines.gp'
call 'terminal.gp' 1100 800 12
set title title font 'DejaVu Sans,11'
set xlabel xname
set ylabel yname
set key outside right top
set grid
if (exists("xlo") && exists("xhi")) { set xrange [xlo:xhi] }
if (exists("ylo") && exists("yhi")) { set yrange [ylo:yhi] }
plot NaN notitle @curvelines
