"""Draws a regime map of the paper's 5-DOF chain over the forcing frequency and the contact stiffness.

Every cell of a (θ, α) grid is integrated past its transient and its motion classified from its
Poincaré points (pwl.map): period-k, quasi-periodic, chaotic, ... The map is printed as text, one
character a cell, and drawn with matplotlib when it is installed, else with gnuplot. The same
study from the command line is `pwl map --figure 5 --x theta --y alpha ...` (apps/README.md).

    PYTHONPATH=build/release/apps/python /usr/bin/python3 \
        apps/python/examples/regime_map.py --out regimes.png
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


def letter(regime):
    """One character per regime: the period's digit (up to 9), '+' for a longer one, 'q', 'c'."""
    if regime.startswith("period-"):
        k = int(regime.split("-")[1])
        return str(k) if k < 10 else "+"
    return {"quasi-periodic": "q", "chaotic": "c", "unbounded": "u"}.get(regime, "?")


def draw(m, out):
    codes = m.code.astype(float)
    if importlib.util.find_spec("matplotlib") is not None:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(8, 5))
        mesh = ax.pcolormesh(m.x_values, m.y_values, codes, shading="nearest", cmap="tab20")
        fig.colorbar(mesh, label="regime code (pwl.map's code column)")
        ax.set_xlabel("θ = ω/ω₀")
        ax.set_ylabel("α = k₂/k₁")
        fig.savefig(out, dpi=100)
        return
    if shutil.which("gnuplot") is None:
        sys.exit("regime_map.py: no matplotlib and no gnuplot to draw with")
    with tempfile.TemporaryDirectory() as folder:
        data = os.path.join(folder, "cells.dat")
        with open(data, "w") as f:
            for j, y in enumerate(m.y_values):
                for i, x in enumerate(m.x_values):
                    f.write("{!r} {!r} {}\n".format(x, y, codes[j, i]))
                f.write("\n")
        script = "\n".join([
            "set terminal pngcairo size 800,500 enhanced font 'DejaVu Sans,11'",
            "set output '{}'".format(out),
            "set xlabel 'θ = ω/ω_0'",
            "set ylabel 'α = k_2/k_1'",
            "set cblabel 'regime code'",
            "set view map",
            "plot '{}' using 1:2:3 with image notitle".format(data),
        ])
        subprocess.run(["gnuplot"], input=script, text=True, check=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="regimes.png", help="the PNG to write")
    parser.add_argument("--small", action="store_true", help="a coarse grid, for a quick check")
    args = parser.parse_args()
    points = (6, 4) if args.small else (40, 29)
    periods = (100, 100) if args.small else (500, 500)
    m = pwl.map(figure="5", x="theta", x_range=(0.5, 3), x_points=points[0], y="alpha",
                y_range=(1, 15), y_points=points[1], transient=periods[0], periods=periods[1])
    print(m)
    for j in reversed(range(len(m.y_values))):
        print("α = {:5.2f}  {}".format(m.y_values[j], "".join(letter(r) for r in m.regime[j])))
    draw(m, args.out)
    print("wrote {}".format(args.out))


if __name__ == "__main__":
    main()
