# The bifurcations of a continuation (bifurcations.csv of pwl continue) as marks, one symbol and
# colour per kind, only the kinds found; loaded by the figures that draw them
# (frequency_response.gp, branch_over_diagram.gp), which append @marks to their plot command.
# Variables set before loading: bifurcations (the file), mcolumn (the column drawn against the
# parameter), msize (the marks' size), nfold, ndoubling, nns, ngrazing (how many of each kind: a
# kind not found stays out of the legend).
mark(kind, pt, color, name) = sprintf(", bifurcations using 2:(strcol(1) eq '%s' ? column(%d) : NaN) with points pt %d ps %g lw 2 lc rgb '%s' title '%s'", kind, mcolumn, pt, msize, color, name)
marks = (nfold > 0 ? mark('fold', 9, '#000000', 'fold') : '') . \
        (ndoubling > 0 ? mark('period-doubling', 5, '#d62728', 'period doubling') : '') . \
        (nns > 0 ? mark('neimark-sacker', 13, '#ff7f0e', 'Neimark-Sacker') : '') . \
        (ngrazing > 0 ? mark('grazing', 2, '#2ca02c', 'grazing') : '')
