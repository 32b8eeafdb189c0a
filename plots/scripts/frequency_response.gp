# Frequency response of a periodic-orbit continuation (pwl continue): the amplitude of one mass
# along each branch against the parameter, stable stretches solid and unstable ones dashed, one
# colour per branch, and the bifurcations found on the way marked by kind.
# Variables (gnuplot -e): branch (branch.csv of pwl continue: branch,parameter,period,stable,...),
# bifurcations (bifurcations.csv: type,parameter,...), out, fmt, ycolumn (the amplitude column
# drawn in branch.csv), bcolumn (the same mass's amplitude column in bifurcations.csv), branches
# (how many: 0 .. branches-1), bp0, bp1, ... (each branch's period), nfold, ndoubling, nns,
# ngrazing (how many of each kind were found: a kind not found stays out of the legend), xname,
# yname, title.
if (!exists("branch")) branch = 'continuation/branch.csv'
if (!exists("bifurcations")) bifurcations = 'continuation/bifurcations.csv'
if (!exists("out")) out = 'continuation/frequency_response.png'
if (!exists("ycolumn")) ycolumn = 10
if (!exists("bcolumn")) bcolumn = 14
if (!exists("branches")) branches = 1
if (!exists("bp0")) bp0 = 1
if (!exists("nfold")) nfold = 0
if (!exists("ndoubling")) ndoubling = 0
if (!exists("nns")) nns = 0
if (!exists("ngrazing")) ngrazing = 0
if (!exists("xname")) xname = 'parameter'
if (!exists("yname")) yname = 'amplitude'
if (!exists("title")) title = ''
set datafile separator ','
call 'terminal.gp' 1400 900 12
set title title font 'DejaVu Sans,11'
set xlabel xname
set ylabel yname
set autoscale xfix
set key outside right top
set grid
# A resonance peak far above the rest of the curve: a logarithmic amplitude axis keeps both legible.
stats branch using (column(ycolumn)) nooutput
if (STATS_min > 0 && STATS_max > 20 * STATS_min) { set logscale y }
colors = '#1f3fbf #d9531e #2ca02c #9467bd #8c564b #17becf'
bcolor(b) = word(colors, b % 6 + 1)
period_of(b) = exists(sprintf('bp%d', b)) ? value(sprintf('bp%d', b)) : 0
# A row belongs to the curve of stability `want` when it has that stability or the row before it
# on the same branch has: every segment between two points is drawn once, in the style of its
# first point, and a curve breaks (NaN) where the stability or the branch changes. pb, ps: the
# branch and stability of the row before (reset at each curve's first row, $0 == 0).
keep(b, s, want) = (r = (s == want || (b == pb && ps == want)), pb = b, ps = s, r)
restart(row) = row == 0 ? (pb = -1, ps = -1) : 0
pb = -1
ps = -1
# The bifurcations, each kind with its own mark, only the kinds found.
mcolumn = bcolumn
msize = 2
load 'bifurcation_marks.gp'
plot for [b=0:branches-1] branch using 2:(restart($0), keep($1, $4, 1) && $1 == b ? column(ycolumn) : NaN) \
       with lines lw 2 dt 1 lc rgb bcolor(b) \
       title sprintf('branch %d (period %d), stable', b, period_of(b)), \
     for [b=0:branches-1] branch using 2:(restart($0), keep($1, $4, 0) && $1 == b ? column(ycolumn) : NaN) \
       with lines lw 2 dt (8, 6) lc rgb bcolor(b) \
       title sprintf('branch %d, unstable', b) @marks
