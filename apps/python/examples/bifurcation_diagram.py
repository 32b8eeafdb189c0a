"""Draws the θ bifurcation diagram of the paper's 5-DOF chain from Python.

The case is figure 5's (α = 5, ζ = 0.2, Δ̃ = 0). The Poincaré points come from a brute-force
sweep by continuation, up and down (pwl.sweep); over them goes the period-1 orbit followed by
pseudo-arclength continuation (pwl.continue_), solid where its Floquet multipliers are inside the
unit circle (stable) and dashed where they are not.

    PYTHONPATH=build/release/apps/python /usr/bin/python3 \
        apps/python/examples/bifurcation_diagram.py --out theta.png

Draws with matplotlib when it is installed, else with gnuplot (Debian's gnuplot-nox, which pwl
uses for its own figures).
"""

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

import pwl


def compute(points):
    sweep = pwl.sweep(figure="5", parameter="theta", range=(0.6, 3), points=points,
                      mode="continuation", transient=200, periods=60, record=["x5"])
    branch = pwl.continue_(figure="5", parameter="theta", range=(0.6, 3))
    first = branch.branch == 0  # the period-1 branch the continuation started on
    return {
        "theta": sweep.poincare_parameter,
        "x5": sweep.poincare[:, 0],
        "branch_theta": branch.parameter[first],
        "branch_x5": branch.state[first, 4],  # x5 at t = 0 mod T: the orbit's Poincaré point
        "stable": branch.stable[first],
        "bifurcations": branch.bifurcations,
    }


def segments(stable, want):
    """(start, stop) index ranges of the branch where stable == want."""
    runs, start = [], None
    for i, s in enumerate(list(stable) + [not want]):
        if s == want and start is None:
            start = i
        elif s != want and start is not None:
            runs.append((start, i))
            start = None
    return runs


def draw_with_matplotlib(data, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(10, 6.5))
    ax.plot(data["theta"], data["x5"], ",", color="0.35", label="pwl.sweep (up and down)")
    for want, style, label in ((True, "-", "period-1 orbit, stable"),
                               (False, "--", "period-1 orbit, unstable")):
        for k, (a, b) in enumerate(segments(data["stable"], want)):
            ax.plot(data["branch_theta"][a:b], data["branch_x5"][a:b], style,
                    color="C0" if want else "C3", label=label if k == 0 else None)
    ax.set_xlim(0.6, 3.0)
    ax.set_xlabel("θ = ω/ω₀")
    ax.set_ylabel("x₅ at t = kT")
    ax.legend()
    fig.savefig(out, dpi=100)


def draw_with_gnuplot(data, out):
    with tempfile.TemporaryDirectory() as folder:
        points = os.path.join(folder, "points.dat")
        np.savetxt(points, np.column_stack([data["theta"], data["x5"]]))
        plots = ["'{}' with points pt 7 ps 0.15 lc rgb '#555555' "
                 "title 'pwl.sweep (up and down)'".format(points)]
        for want, colour, dash, label in ((True, "#1f77b4", 1, "stable"),
                                          (False, "#d62728", 2, "unstable")):
            path = os.path.join(folder, "{}.dat".format(label))
            with open(path, "w") as f:
                for a, b in segments(data["stable"], want):
                    for t, x in zip(data["branch_theta"][a:b], data["branch_x5"][a:b]):
                        f.write("{!r} {!r}\n".format(t, x))
                    f.write("\n")  # a blank line: gnuplot does not join the segments
            plots.append("'{}' with lines lw 2 dt {} lc rgb '{}' title 'period-1 orbit, {}'"
                         .format(path, dash, colour, label))
        script = "\n".join([
            "set terminal pngcairo size 1000,650 enhanced font 'DejaVu Sans,11'",
            "set output '{}'".format(out),
            "set xlabel 'θ = ω/ω_0'",
            "set ylabel 'x_5 at t = kT'",
            "set xrange [0.6:3]",
            "set key top left",
            "plot " + ", ".join(plots),
        ])
        subprocess.run(["gnuplot"], input=script, text=True, check=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="bifurcation_theta.png", help="the PNG to write")
    parser.add_argument("--points", type=int, default=120, help="values of θ in the sweep")
    parser.add_argument("--small", action="store_true", help="40 values of θ, for a quick check")
    args = parser.parse_args()
    data = compute(40 if args.small else args.points)
    found = data["bifurcations"]
    print("period-1 branch: {} points, {} stable; bifurcations: {}".format(
        len(data["stable"]), int(np.sum(data["stable"])),
        ", ".join("{} at θ = {:.4f}".format(t, p)
                  for t, p, b in zip(found["type"], found["parameter"], found["branch"])
                  if b == 0 and t != "grazing")))
    if importlib.util.find_spec("matplotlib") is not None:
        draw_with_matplotlib(data, args.out)
    elif shutil.which("gnuplot") is not None:
        draw_with_gnuplot(data, args.out)
    else:
        sys.exit("bifurcation_diagram.py: no matplotlib and no gnuplot to draw with")
    print("wrote {}".format(args.out))


if __name__ == "__main__":
    main()
