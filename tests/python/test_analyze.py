"""pwl.analyze against `pwl analyze`: the same verdict, evidence and Poincaré points as the
program's classification.csv, poincare.csv and printout, and the same errors."""

import re

import numpy as np
import pytest

import pwl
from conftest import largest_difference, read_csv, state_matrix

STATE = ["x1", "x2", "x3", "x4", "x5", "v1", "v2", "v3", "v4", "v5"]


@pytest.mark.parametrize("flags, args", [
    (dict(figure="4a", periods=300, transient=100),
     ["--figure", "4a", "--periods", "300", "--transient", "100"]),
    (dict(figure="5", theta=2.5, periods=400, transient=200, method="exact"),
     ["--figure", "5", "--theta", "2.5", "--periods", "400", "--transient", "200", "--method",
      "exact"]),
])
def test_verdict_and_evidence_equal_the_cli(cli, flags, args):
    a = pwl.analyze(**flags)
    out = cli.folder / "analyze"
    printout = cli.run("analyze", *args, "--out", out).stdout
    table = read_csv(out / "classification.csv")
    assert a.regime == table["regime"][0]
    assert a.period == table["period"][0]
    # classification.csv has lambda1 to 10 significant digits, its error to 3 and K to 6.
    assert a.lambda1 == pytest.approx(table["lambda1_per_period"][0], rel=1e-9)
    assert a.lambda1_error == pytest.approx(table["lambda1_error"][0], rel=1e-2)
    assert a.K == pytest.approx(table["K"][0], rel=1e-5, abs=1e-6)
    assert "  rule: {}\n".format(a.reason) in printout
    search = re.search(r"period search: .*\(best k = (\d+), mismatch \S+, (\d+) distinct points\)",
                       printout)
    assert (a.period_search["best_k"], a.period_search["distinct_points"]) == (
        int(search.group(1)), int(search.group(2)))
    points = read_csv(out / "poincare.csv")
    # The record, and the periods adaptive evidence added to it.
    recorded = a.recorded + a.extra_periods
    assert a.poincare.shape == (recorded, 10)
    assert largest_difference(a.poincare, state_matrix(points, STATE)) <= 1e-12
    assert largest_difference(a.t, points["t"]) <= 1e-12
    assert np.array_equal(a.period_index, np.arange(a.transient + 1, a.transient + recorded + 1))
    # The evidence ladder's columns of classification.csv.
    assert a.minimal_period == table["minimal_period"][0]
    assert a.observed_periods == table["observed_periods"][0]
    assert a.decided_by == table["decided_by"][0]


def test_bad_values_raise_input_error_with_the_cli_message(cli):
    for flags, args in [(dict(figure="4a", mass=9), ["--figure", "4a", "--mass", "9"]),
                        (dict(periods=150), ["--periods", "150"]),
                        (dict(method="dopri5", lyapunov="tangent-frame"),
                         ["--method", "dopri5", "--lyapunov", "tangent-frame"])]:
        with pytest.raises(pwl.InputError) as raised:
            pwl.analyze(**flags)
        assert str(raised.value) in cli.error("analyze", *args, "--out", cli.folder / "bad")
    with pytest.raises(TypeError, match="unexpected keyword argument 'masses'"):
        pwl.analyze(masses=3)


def test_the_ladder_gives_the_minimal_period_and_the_method_it_rests_on():
    # Seven turns of a slow spiral onto the period-1 orbit, which the record's search takes for a
    # period-7 cycle: Newton says period 1, the exact solver's Newton confirms it (pwl orbit
    # --figure 5 --alpha 4.7 --theta 1.83 --period 1 --method exact: |mu| = 0.9866872283).
    a = pwl.analyze(figure="5", alpha=4.7, theta=1.83)
    assert (a.regime, a.period, a.minimal_period, a.record_period) == ("period-1", 1, 1, 7)
    assert (a.decided_by, a.confirmed_by, a.confirmation) == ("exact", "exact", "newton")
    assert a.multiplier == pytest.approx(0.9866872283, rel=1e-8)
    assert a.observed_periods == a.recorded + a.extra_periods
    assert a.seconds > 0
    assert "decided by exact" in repr(a)
    # The plain record: the spiral is still drifting after 500 periods, and nothing checks it.
    q = pwl.analyze(figure="5", alpha=4.7, theta=1.83, quick=True)
    assert q.regime == "uncertain" and q.minimal_period == 0 and q.decided_by == "pim"
    assert q.extra_periods == 0 and q.confirmed_by == ""
