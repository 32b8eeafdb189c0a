# Basins of attraction (pwl basin): every initial state of the grid coloured by the attractor its
# motion ends on, the attractors' stroboscopic points marked on the same two state components.
# Variables (gnuplot -e): data (basin.csv), points (attractor_points.csv), out, xname, yname,
# xcol, ycol (the columns of the two components in attractor_points.csv), dx, dy (the grid
# spacing), attractors (how many), label1..labelN (legend text), subtitle.
if (!exists("data")) data = 'basin/basin.csv'
if (!exists("points")) points = 'basin/attractor_points.csv'
if (!exists("out")) out = 'basin/basin.png'
if (!exists("xname")) xname = 'x1'
if (!exists("yname")) yname = 'v1'
if (!exists("xcol")) xcol = 2
if (!exists("ycol")) ycol = 3
if (!exists("attractors")) attractors = 0
if (!exists("subtitle")) subtitle = ''
if (!exists("dx")) dx = 0.1
if (!exists("dy")) dy = 0.1
if (dx <= 0) dx = 1.0
if (dy <= 0) dy = 1.0
set datafile separator ','
call 'terminal.gp' 900 900 12
# Attractor 0 (the motion failed) grey; the others from a qualitative palette, repeating after 10.
hue(i) = i == 0 ? 0x1f77b4 : i == 1 ? 0xff7f0e : i == 2 ? 0x2ca02c : i == 3 ? 0xd62728 : \
         i == 4 ? 0x9467bd : i == 5 ? 0x8c564b : i == 6 ? 0xe377c2 : i == 7 ? 0xbcbd22 : \
         i == 8 ? 0x17becf : 0x7f7f7f
# A header row reads as NaN: grey, like a failed motion.
color(a) = (a != a || a < 1) ? 0xbbbbbb : hue((int(a) - 1) % 10)
label(a) = exists(sprintf('label%d', a)) ? value(sprintf('label%d', a)) : sprintf('%d', a)
set xlabel xname.' at t = 0'
set ylabel yname.' at t = 0'
set key below left Left reverse title 'attractor' maxrows 4
stats data using 3 nooutput
set xrange [STATS_min - dx/2.0 : STATS_max + dx/2.0]
stats data using 4 nooutput
set yrange [STATS_min - dy/2.0 : STATS_max + dy/2.0]
set title 'basins of attraction'.(subtitle eq '' ? '' : "\n{/*0.8 ".subtitle."}")
plot data using 3:4:(dx/2.0):(dy/2.0):(color($5)) with boxxyerror fs solid 1.0 noborder \
       lc rgb variable notitle, \
     for [a=1:attractors] NaN with boxes fs solid lc rgb color(a) title label(a), \
     points using (column(xcol)):(column(ycol)) with points pt 7 ps 1.2 lc rgb 'black' \
       title 'the attractors at t = 0 (within the grid)', \
     points using (column(xcol)):(column(ycol)):(sprintf('%d', int($1))) with labels \
       offset 1.2,0.8 tc rgb 'black' notitle
