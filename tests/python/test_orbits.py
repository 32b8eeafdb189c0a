"""pwl.orbit and pwl.continue_ against `pwl orbit` and `pwl continue`: the same orbit and
multipliers as orbit.csv and floquet.csv, the same branch and bifurcations as branch.csv and
bifurcations.csv, and the same errors."""

import numpy as np
import pytest

import pwl
from conftest import largest_difference, read_csv, state_matrix

STATE = ["x1", "x2", "x3", "x4", "x5", "v1", "v2", "v3", "v4", "v5"]


def test_orbit_equals_the_cli_files(cli):
    # The unstable period-1 orbit inside figure 4a's period-2 motion.
    o = pwl.orbit(figure="4a", period=1)
    out = cli.out("orbit", "--figure", "4a", "--period", "1", "--no-path")
    assert largest_difference(o.state, state_matrix(read_csv(out / "orbit.csv"), STATE)[0]) <= 1e-12
    floquet = read_csv(out / "floquet.csv")
    assert o.multipliers.dtype == np.complex128 and o.multipliers.shape == (10,)
    assert largest_difference(o.multipliers.real, floquet["re"]) <= 1e-12
    assert largest_difference(o.multipliers.imag, floquet["im"]) <= 1e-12
    assert np.all(np.diff(np.abs(o.multipliers)) <= 1e-12)  # largest modulus first
    assert o.verdict == "unstable" and not o.stable and o.unstable_count == 1
    assert o.residual <= 1e-10 * max(1.0, np.abs(o.state).max())
    assert o.method == "exact event-driven" and o.method_default
    assert o.monodromy.shape == (10, 10)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(o.monodromy)),
                       np.sort_complex(o.multipliers), atol=1e-10)


def test_minimal_period_of_a_slow_spiral():
    # Figure 5's chain at alpha = 4.7, theta = 1.83: a stable period-1 orbit whose complex pair
    # (|mu| = 0.987) turns about 2/7 of a circle a period. Newton at period 7 lands on it: the
    # orbit is the period-1 orbit taken 7 times, its multipliers at period 1 the 7th roots of
    # those at period 7 in modulus.
    seven = pwl.orbit(figure="5", alpha=4.7, theta=1.83, period=7)
    assert seven.period == 7 and seven.minimal_period == 1
    one = pwl.orbit(figure="5", alpha=4.7, theta=1.83, period=1)
    assert one.minimal_period == 1
    assert abs(seven.minimal_largest_modulus - one.largest_modulus) <= 1e-10
    assert abs(seven.largest_modulus - one.largest_modulus ** 7) <= 1e-10
    assert "(minimal period 1)" in repr(seven) and "minimal" not in repr(one)


def test_continuation_equals_the_cli_files(cli):
    c = pwl.continue_(figure="4a", parameter="theta", range="0.9:1.1")
    out = cli.out("continue", "--figure", "4a", "--parameter", "theta", "--range", "0.9:1.1",
                  "--no-plot", "--quiet")
    branch = read_csv(out / "branch.csv")
    count = len(branch["parameter"])
    assert count > 10 and c.parameter.shape == (count,)
    for name in ("branch", "parameter", "period", "max_abs_multiplier", "unstable_multipliers"):
        assert largest_difference(getattr(c, name), branch[name]) <= 1e-12, name
    assert np.array_equal(c.stable, branch["stable"] == 1)
    amplitude = state_matrix(branch, ["amplitude_x{}".format(i) for i in range(1, 6)])
    assert largest_difference(c.amplitude, amplitude) <= 1e-12
    assert largest_difference(c.state[:, :5], state_matrix(branch, STATE[:5])) <= 1e-12
    found = read_csv(out / "bifurcations.csv")
    b = c.bifurcations
    assert len(b["type"]) == len(found["type"]) > 0
    assert list(b["type"]) == list(found["type"])
    assert "period-doubling" in list(b["type"])
    assert largest_difference(b["parameter"], found["parameter"]) <= 1e-12
    assert np.array_equal(b["branch"], found["branch"])
    assert largest_difference(np.where(b["spring"] > 0, b["spring"], np.nan), found["spring"]) == 0
    assert largest_difference(b["multiplier"].real, found["multiplier_re"]) <= 1e-12
    assert largest_difference(b["multiplier"].imag, found["multiplier_im"]) <= 1e-12
    assert [d for d in b["detail"]] == [d for d in np.char.strip(found["detail"].astype(str))]
    assert c.notes and c.parameter_name == "theta"
    assert pwl.continuation is pwl.continue_
    # Dense: every multiplier known, so the band round the circle is checked as asked.
    w = c.work
    assert not w["matrix_free"] and w["monodromies"] > 0 and w["krylov_products"] == 0
    assert w["narrowest_band"] == 0.05 and w["band"] == 0.05
    assert w["multiplier_products"] == 0 and w["uncovered_bands"] == 0
    assert w["davidson_points"] == 0 and w["arnoldi_points"] == 0
    assert c.curve_work is None
    blind = pwl.continue_(figure="4a", parameter="theta", range="0.9:0.95", band=0)
    assert np.isinf(blind.work["narrowest_band"]) and blind.work["band_cuts"] == 0


def test_curves_equal_the_cli_files(cli):
    # Figure 5's period doubling at theta = 1.0098 followed in (theta, alpha).
    c = pwl.continue_(figure="5", parameter="theta", range=(1.0, 1.02), curves=("alpha", (4.5, 5.5)),
                      curve_types=["period-doubling"])
    out = cli.out("continue", "--figure", "5", "--parameter", "theta", "--range", "1.0:1.02",
                  "--curves", "alpha=4.5:5.5", "--curve-types", "period-doubling", "--no-plot",
                  "--quiet")
    rows = read_csv(out / "curves.csv")
    count = len(rows["curve"])
    assert count > 10 and c.curves["curve"].shape == (count,)
    for name in ("curve", "theta", "alpha", "period", "kappa"):
        assert largest_difference(c.curves[name], rows[name]) <= 1e-12, name
    assert list(c.curves["type"]) == ["period-doubling"] * count
    assert largest_difference(c.curves["multiplier"].real, rows["multiplier_re"]) <= 1e-12
    assert largest_difference(c.curves["state"], state_matrix(rows, STATE)) <= 1e-12
    found = read_csv(out / "codim2.csv")
    assert len(c.codim2["type"]) == len(np.atleast_1d(found["type"]))
    assert len(c.curve_ends) == 1 and all(c.curve_ends[0])
    # Dense curves: the monodromy at every point, no Krylov product and no leading-multiplier solve.
    cw = c.curve_work
    assert cw["monodromies"] > 0 and cw["krylov_products"] == 0
    assert cw["multiplier_products"] == 0 and cw["davidson_points"] == 0 == cw["arnoldi_points"]
    assert "1 curve(s)" in repr(c)


@pytest.mark.parametrize("job, flags, args", [
    ("orbit", dict(period=0), ["--period", "0"]),
    ("orbit", dict(shots=3, period=2), ["--shots", "3", "--period", "2"]),
    ("continue", dict(figure="4a"), ["--figure", "4a"]),  # --parameter is required
    ("continue", dict(parameter="theta", range="1:1"), ["--parameter", "theta", "--range", "1:1"]),
    ("continue", dict(parameter="alpha", range="-1:2"),
     ["--parameter", "alpha", "--range", "-1:2"]),
    ("continue", dict(parameter="theta", range=(0.9, 1), curves=("theta", (1, 2))),
     ["--parameter", "theta", "--range", "0.9:1", "--curves", "theta=1:2"]),
    ("continue", dict(parameter="theta", range=(0.9, 1), curves=("alpha", (6, 8))),
     ["--parameter", "theta", "--range", "0.9:1", "--curves", "alpha=6:8"]),
])
def test_bad_values_raise_input_error_with_the_cli_message(cli, job, flags, args):
    function = pwl.continue_ if job == "continue" else pwl.orbit
    with pytest.raises(pwl.InputError) as raised:
        function(**flags)
    assert str(raised.value) in cli.error(job, *args, "--out", cli.folder / "bad")


def test_a_failed_newton_raises_run_error(cli):
    with pytest.raises(pwl.RunError) as raised:
        pwl.orbit(figure="4a", max_iterations=1, transient=0)
    assert isinstance(raised.value, RuntimeError)
    stderr = cli.run("orbit", "--figure", "4a", "--max-iterations", "1", "--transient", "0",
                     "--out", cli.folder / "failed", code=1).stderr
    assert str(raised.value) in stderr


def test_file_keywords_are_refused():
    with pytest.raises(TypeError, match="does not take over_sweep="):
        pwl.continue_(parameter="theta", range="0.9:1.1", over_sweep=50)
    with pytest.raises(TypeError, match="unexpected keyword argument 'guess'"):
        pwl.orbit(guess=[0.0] * 10)
