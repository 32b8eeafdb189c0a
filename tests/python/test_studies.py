"""pwl.sweep and pwl.map against `pwl sweep` and `pwl map`: the same Poincaré points and regime
tables as the program's poincare.csv, classification.csv and map.csv, and the same errors."""

import numpy as np
import pytest

import pwl
from conftest import largest_difference, read_csv


def assert_same_table(table, files):
    """Every column of a result table equals the file's column of that name."""
    assert list(table) == list(files)
    for name, column in table.items():
        if files[name].dtype.kind == "U":
            assert list(column) == list(files[name]), name
        elif np.asarray(column).dtype.kind == "U":
            # A text column whose every cell is empty (confirmed_by when nothing was confirmed)
            # reads from the file as NaN.
            assert all(cell == "" for cell in column), name
            assert np.all(np.isnan(files[name])), name
        else:
            assert largest_difference(column, files[name]) <= 1e-12, name


def test_sweep_equals_the_cli_files(cli):
    # A continuation up and down over theta, two components recorded, two threads.
    s = pwl.sweep(figure="5", parameter="theta", range="0.8:1.6", points=3, mode="continuation",
                  transient=40, periods=100, record=["x5", "v3"], threads=2)
    out = cli.out("sweep", "--figure", "5", "--parameter", "theta", "--range", "0.8:1.6",
                  "--points", "3", "--mode", "continuation", "--transient", "40", "--periods",
                  "100", "--record", "x5,v3", "--no-plot", "--quiet")
    assert list(s.components) == ["x5", "v3"]
    assert np.allclose(s.values, [0.8, 1.2, 1.6], rtol=0, atol=1e-15)
    points = read_csv(out / "poincare.csv")
    # 100 points a point, and those adaptive evidence recorded beyond them.
    extra = np.asarray(s.table["extra_periods"])
    assert s.poincare.shape == (int(np.sum(100 + extra)), 2)
    assert largest_difference(s.poincare[:, 0], points["x5"]) <= 1e-12
    assert largest_difference(s.poincare[:, 1], points["v3"]) <= 1e-12
    assert largest_difference(s.poincare_parameter, points["theta"]) <= 1e-12
    assert list(s.poincare_direction) == list(points["direction"])
    assert np.array_equal(s.poincare_index, points["index"])
    assert np.array_equal(s.poincare_period, points["period_index"])
    table = read_csv(out / "classification.csv")
    assert_same_table(s.table, table)
    assert list(s.regime) == list(table["regime"]) and s.lambda1.shape == (6,)
    down = s.points_of(2, "down")  # theta = 1.6 on the downward branch
    row = [i for i in range(6) if s.table["direction"][i] == "down" and s.table["index"][i] == 2]
    assert down.shape == (100 + extra[row[0]], 2)
    chosen = (points["direction"] == "down") & (points["index"] == 2)
    assert largest_difference(down[:, 0], points["x5"][chosen]) <= 1e-12


def test_map_equals_the_cli_file(cli):
    m = pwl.map(figure="5", x="theta", x_range="0.8:1.6", x_points=3, y="zeta", y_range="0.1:0.3",
                y_points=2, transient=40, periods=100)
    out = cli.out("map", "--figure", "5", "--x", "theta", "--x-range", "0.8:1.6", "--x-points",
                  "3", "--y", "zeta", "--y-range", "0.1:0.3", "--y-points", "2", "--transient",
                  "40", "--periods", "100", "--no-plot", "--quiet")
    files = read_csv(out / "map.csv")
    assert_same_table(m.table, files)
    assert m.regime.shape == (2, 3) and m.lambda1.shape == (2, 3)
    # Row j of the grids is y_values[j], column i is x_values[i].
    for i, j, regime, lambda1 in zip(files["i"], files["j"], files["regime"], files["lambda1"]):
        assert m.regime[int(j), int(i)] == regime
        assert m.lambda1[int(j), int(i)] == pytest.approx(lambda1, rel=0, abs=1e-12)
    assert np.allclose(m.y_values, [0.1, 0.3], rtol=0, atol=1e-15)


@pytest.mark.parametrize("job, flags, args", [
    ("sweep", dict(figure="5", parameter="spring1.gap"),
     ["--figure", "5", "--parameter", "spring1.gap"]),
    ("sweep", dict(range="3"), ["--range", "3"]),
    ("sweep", dict(record=["x9"]), ["--record", "x9"]),
    ("sweep", dict(mode="both"), ["--mode", "both"]),
    ("map", dict(y="omega"), ["--y", "omega"]),
    ("map", dict(section="v3=0,down"), ["--section", "v3=0,down"]),
])
def test_bad_values_raise_input_error_with_the_cli_message(cli, job, flags, args):
    with pytest.raises(pwl.InputError) as raised:
        getattr(pwl, job)(**flags)
    assert str(raised.value) in cli.error(job, *args, "--no-plot", "--quiet", "--out",
                                          cli.folder / "bad")


def test_file_keywords_are_refused():
    with pytest.raises(TypeError, match="does not take resume="):
        pwl.sweep(resume=True)
    with pytest.raises(TypeError, match="unexpected keyword argument 'x_point'"):
        pwl.map(x_point=3)
