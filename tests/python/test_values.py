"""Python values where the command line has strings: ranges as pairs, lists and NumPy arrays for
loads and initial states, a Structure wherever a structure goes; the strings keep working and give
the same results. help() lists every keyword with its default and meaning, results print as one
line, and the relations between two keywords are refused as the program refuses its flags."""

import numpy as np
import pytest

import pwl


def test_a_range_as_a_pair_equals_the_string():
    as_text = pwl.sweep(figure="4a", parameter="theta", range="0.9:1.1", points=3, transient=20,
                        periods=10)
    as_pair = pwl.sweep(figure="4a", parameter="theta", range=(0.9, 1.1), points=3, transient=20,
                        periods=10)
    as_array = pwl.sweep(figure="4a", parameter="theta", range=np.array([0.9, 1.1]), points=3,
                         transient=20, periods=10)
    for other in (as_pair, as_array):
        np.testing.assert_array_equal(other.values, as_text.values)
        np.testing.assert_array_equal(other.poincare, as_text.poincare)


def test_map_ranges_as_pairs():
    m = pwl.map(figure="4a", x="theta", x_range=(0.9, 1.1), x_points=2, y="alpha",
                y_range=(1.5, 2.5), y_points=2, transient=20, periods=10)
    np.testing.assert_array_equal(m.x_values, [0.9, 1.1])
    np.testing.assert_array_equal(m.y_values, [1.5, 2.5])


def test_a_range_of_one_or_three_numbers_is_refused():
    for bad in ((0.5,), (0.5, 1, 2)):
        with pytest.raises(TypeError, match=r"a range is two numbers, \(FROM, TO\)"):
            pwl.sweep(figure="4a", parameter="theta", range=bad, points=3)


def test_loads_and_initial_states_as_lists_or_arrays():
    text = pwl.simulate(n=3, loads="1,0,-1", x0="0.1,0,0", v0="0,0.2,0", periods=3)
    listed = pwl.simulate(n=3, loads=[1, 0, -1], x0=[0.1, 0, 0], v0=(0, 0.2, 0), periods=3)
    arrays = pwl.simulate(n=3, loads=np.array([1.0, 0.0, -1.0]), x0=np.array([0.1, 0.0, 0.0]),
                          v0=np.array([0.0, 0.2, 0.0]), periods=3)
    for other in (listed, arrays):
        np.testing.assert_array_equal(other.poincare, text.poincare)
    assert text.poincare[0, 0] == 0.1 and text.poincare[0, 4] == 0.2


def two_mass_stop():
    return pwl.Structure(np.eye(2), 0.05 * np.array([[2.0, -1.0], [-1.0, 1.0]]),
                         np.array([[2.0, -1.0], [-1.0, 1.0]]),
                         springs=[{"mass": 2, "stiffness": 4.0, "gap": 0.2}],
                         loads=[{"mass": 2, "amplitude": 1.0, "omega": 1.2}])


def test_a_structure_where_a_scene_file_goes():
    S = two_mass_stop()
    a = pwl.analyze(structure=S, periods=300, transient=100)
    b = pwl.analyze(structure_scene=S, periods=300, transient=100)
    assert a.regime == b.regime and a.lambda1 == b.lambda1
    np.testing.assert_array_equal(a.poincare, b.poincare)
    with pytest.raises(pwl.InputError, match="not both"):
        pwl.analyze(structure=S, structure_scene=S)


def test_help_lists_every_keyword_with_its_default_and_meaning():
    doc = pwl.simulate.__doc__
    assert "structure : Structure, default None" in doc
    assert "periods : value, default 1000" in doc
    assert "locate_kinks : bool, default False" in doc
    assert "theta : value" in doc
    sweep_doc = pwl.sweep.__doc__
    assert "range : value, default 0.5:3" in sweep_doc
    for left_out in ("\nout :", "\nquiet :", "\nresume :"):
        assert left_out not in sweep_doc
    # Every keyword the function takes is documented, every documented keyword is taken.
    for function, job in ((pwl.orbit, "orbit"), (pwl.continue_, "continue_"), (pwl.map, "map")):
        keywords = [k for k, _, _, _ in pwl._pwl.keywords(job)]
        assert len(keywords) > 10
        for k in keywords:
            assert "\n{} : ".format(k) in function.__doc__, (job, k)


def test_results_print_as_one_line():
    o = pwl.orbit(figure="4a", period=1)
    text = repr(o)
    assert "\n" not in text and text.startswith("OrbitResult(period-1 orbit, unstable, ")
    s = pwl.sweep(figure="4a", parameter="theta", range=(0.9, 1.1), points=3, transient=20,
                  periods=10)
    assert "\n" not in repr(s) and repr(s).startswith("SweepResult(theta from 0.9 to 1.1, 3 values")
    assert str(s) == repr(s)
    assert "values = array(shape=(3,)" in s.fields()


def test_relations_between_keywords_are_refused_like_flags():
    with pytest.raises(pwl.InputError, match=r"--min-step = 0.5 must be at most --max-step = 0.1"):
        pwl.continue_(figure="4a", parameter="theta", range=(0.9, 1), min_step=0.5, max_step=0.1)
    with pytest.raises(pwl.InputError, match=r"--y = theta must differ from --x = theta"):
        pwl.map(figure="4a", x="theta", y="theta")
