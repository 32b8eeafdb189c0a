"""Finds the periodic orbit of a structure given by its matrices, and follows it in a gap.

The structure is two masses on springs (M, C, K from NumPy) with a stop on the second mass and a
gap spring between the two, forced on the second mass: the two-mass stop of
apps/scenes/two_mass_stop.toml, built in Python. pwl.orbit finds its period-1 orbit by Newton
shooting on the exact piecewise-linear map, with its Floquet multipliers; pwl.continue_ follows
that orbit as the stop's gap grows, and names every bifurcation on the way (where a contact
appears or disappears: a grazing; where the orbit loses its stability). Values are Python
values: the matrices and the initial state NumPy arrays, the range a pair.

    PYTHONPATH=build/release/apps/python /usr/bin/python3 \
        apps/python/examples/periodic_orbit_of_a_structure.py --out orbit_in_gap.csv

Writes the branch (gap, largest |μ|, stable, amplitude of mass 2) as CSV.
"""

import argparse

import numpy as np

import pwl


def two_mass_stop():
    """M, C, K of two unit masses in a row, fixed at the left; a stop on mass 2 and a gap spring
    between the masses; a harmonic load on mass 2."""
    M = np.eye(2)
    C = 0.05 * np.array([[2.0, -1.0], [-1.0, 1.0]])
    K = np.array([[2.0, -1.0], [-1.0, 1.0]])
    springs = [{"mass": 2, "stiffness": 4.0, "gap": 0.2},
               {"mass": 1, "other_mass": 2, "direction": -1, "stiffness": 1.0, "gap": 0.1}]
    loads = [{"mass": 2, "amplitude": 1.0, "omega": 1.2}]
    return pwl.Structure(M, C, K, springs=springs, loads=loads)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="orbit_in_gap.csv", help="the CSV to write")
    parser.add_argument("--small", action="store_true", help="a short branch, for a quick check")
    args = parser.parse_args()

    structure = two_mass_stop()
    orbit = pwl.orbit(structure=structure, period=1, x0=np.zeros(2), v0=np.zeros(2))
    print(orbit)
    print("multipliers:", ", ".join("{:.4f}".format(m) for m in orbit.multipliers[:4]))

    gaps = (0.2, 0.35) if args.small else (0.2, 0.6)
    branch = pwl.continue_(structure=structure, parameter="spring1.gap", range=gaps)
    print(branch)
    found = branch.bifurcations
    for kind, gap, spring in zip(found["type"], found["parameter"], found["spring"]):
        where = " (spring {})".format(spring) if spring > 0 else ""
        print("  {} at gap = {:.8f}{}".format(kind, gap, where))
    table = np.column_stack([branch.parameter, branch.max_abs_multiplier, branch.stable,
                             branch.amplitude[:, 1]])
    np.savetxt(args.out, table, delimiter=",", header="gap,max_abs_multiplier,stable,amplitude_x2",
               comments="")
    print("wrote {}".format(args.out))


if __name__ == "__main__":
    main()
