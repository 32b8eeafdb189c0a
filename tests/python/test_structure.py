"""pwl.Structure: a structure from NumPy is the same structure as the scene file that writes the
same numbers, and every job given one (structure=S) answers as with --structure-scene, in the
module and in the program; its errors name the field."""

import numpy as np
import pytest

import pwl
from conftest import SCENES, largest_difference, read_csv, state_matrix

SCENE = SCENES / "two_mass_stop.toml"
STATE = ["x1", "x2", "v1", "v2"]


def two_mass_stop():
    """apps/scenes/two_mass_stop.toml's [structure], from NumPy."""
    return pwl.Structure(
        mass=np.eye(2),
        damping=0.1 * np.eye(2),
        stiffness=np.array([[2.0, -1.0], [-1.0, 1.0]]),
        springs=[{"mass": 2, "stiffness": 4.0, "gap": 0.2},
                 {"mass": 1, "other_mass": 2, "direction": -1, "stiffness": 1.0, "gap": 0.1}],
        loads=[{"mass": 2, "amplitude": 1.0, "omega": 1.2}])


def test_numpy_structure_equals_the_scene_file():
    given, scene = two_mass_stop(), pwl.Structure.from_scene(str(SCENE))
    for name in ("mass", "damping", "stiffness"):
        assert np.array_equal(getattr(given, name), getattr(scene, name)), name
    assert given.springs == scene.springs and given.loads == scene.loads
    assert given.dofs == 2 and given.period == pytest.approx(2 * np.pi / 1.2, rel=1e-15)


def test_jobs_given_the_structure_answer_as_with_the_scene_file(cli):
    s = two_mass_stop()
    a = pwl.analyze(structure=s, periods=400, transient=200)
    b = pwl.analyze(structure_scene=str(SCENE), periods=400, transient=200)
    assert np.array_equal(a.poincare, b.poincare)
    assert (a.regime, a.period, a.lambda1, a.K) == (b.regime, b.period, b.lambda1, b.K)
    out = cli.out("analyze", "--structure-scene", SCENE, "--periods", "400", "--transient", "200")
    assert largest_difference(a.poincare,
                              state_matrix(read_csv(out / "poincare.csv"), STATE)) <= 1e-12
    assert a.regime == read_csv(out / "classification.csv")["regime"][0]

    sim = pwl.simulate(structure=s, periods=30, record=[2])
    out = cli.out("simulate", "--structure-scene", SCENE, "--periods", "30", "--record", "2",
                  "--quiet")
    assert largest_difference(sim.poincare,
                              state_matrix(read_csv(out / "poincare.csv"), STATE)) <= 1e-12

    o = pwl.orbit(structure=s)
    out = cli.out("orbit", "--structure-scene", SCENE, "--no-path")
    assert largest_difference(o.state, state_matrix(read_csv(out / "orbit.csv"), STATE)[0]) <= 1e-12

    sw = pwl.sweep(structure=s, parameter="spring1.gap", range="0.05:0.5", points=3,
                   transient=50, periods=100)
    out = cli.out("sweep", "--structure-scene", SCENE, "--parameter", "spring1.gap", "--range",
                  "0.05:0.5", "--points", "3", "--transient", "50", "--periods", "100",
                  "--no-plot", "--quiet")
    points = read_csv(out / "poincare.csv")
    assert largest_difference(sw.poincare, state_matrix(points, ["x2", "v2"])) <= 1e-12
    assert list(sw.regime) == list(read_csv(out / "classification.csv")["regime"])


def test_the_library_checks_the_structure_as_it_checks_a_scene(cli, tmp_path):
    # A negative spring stiffness: GapStructure's own message, which the program also gives for
    # the same structure in a scene file.
    with pytest.raises(pwl.InputError) as raised:
        pwl.Structure(np.eye(2), stiffness=[[2.0, -1.0], [-1.0, 1.0]],
                      springs=[{"mass": 2, "stiffness": -4.0, "gap": 0.2}],
                      loads=[{"mass": 2, "amplitude": 1.0, "omega": 1.2}])
    assert "springs[0].stiffness = -4" in str(raised.value)
    scene = tmp_path / "negative.toml"
    scene.write_text("[structure]\nmass = [[1.0, 0.0], [0.0, 1.0]]\n"
                     "stiffness = [[2.0, -1.0], [-1.0, 1.0]]\n"
                     "spring = [{ mass = 2, stiffness = -4.0, gap = 0.2 }]\n"
                     "load = [{ mass = 2, amplitude = 1.0, omega = 1.2 }]\n")
    assert str(raised.value) in cli.error("analyze", "--structure-scene", scene, "--out",
                                          tmp_path / "bad")


@pytest.mark.parametrize("arguments, message", [
    (dict(mass=[[1.0, 2.0]]), "mass: expected a square matrix (n x n, n >= 1), got shape (1 x 2)"),
    (dict(mass=[[float("nan")]]), "mass[0,0] = nan: expected a finite number"),
    (dict(mass=np.eye(1), damping=np.eye(2)), "damping is 2x2; the mass matrix is 1x1"),
    (dict(mass=np.eye(1), springs=[{"mass": 2, "stiffness": 1.0}]),
     "springs[0].mass = 2: masses are numbered 1..1"),
    (dict(mass=np.eye(1), springs=[{"mas": 1, "stiffness": 1.0}]),
     "springs[0].mas: unknown; expected one of mass, other_mass, direction, stiffness, gap"),
    (dict(mass=np.eye(1), loads=[{"mass": 1, "amplitude": 1.0}]), "loads[0]: 'omega' is required"),
])
def test_bad_structures_name_the_field(arguments, message):
    with pytest.raises(pwl.InputError) as raised:
        pwl.Structure(**arguments)
    assert str(raised.value) == message


def test_a_structure_replaces_the_chain_keywords():
    with pytest.raises(pwl.InputError, match="do not apply to an explicit structure; got theta"):
        pwl.simulate(structure=two_mass_stop(), theta=1.5)
    with pytest.raises(pwl.InputError, match="not both"):
        pwl.orbit(structure=two_mass_stop(), structure_scene=str(SCENE))
    with pytest.raises(TypeError, match="expected a pwl.Structure"):
        pwl.simulate(structure=np.eye(2))
