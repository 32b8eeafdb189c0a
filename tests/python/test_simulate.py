"""pwl.simulate against `pwl simulate`: the same Poincaré points and trajectory, the same errors,
arrays that own their data, and the GIL released while it integrates (Ctrl-C still heard)."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import pwl
from conftest import largest_difference, read_csv, state_matrix

STATE = ["x1", "x2", "x3", "x4", "x5", "v1", "v2", "v3", "v4", "v5"]


def test_poincare_equals_the_cli_file(cli):
    result = pwl.simulate(figure="4a", periods=20)
    files = read_csv(cli.out("simulate", "--figure", "4a", "--periods", "20", "--quiet") /
                     "poincare.csv")
    assert result.poincare.shape == (21, 10)
    assert result.columns == STATE
    assert largest_difference(result.poincare, state_matrix(files, STATE)) <= 1e-12
    assert largest_difference(result.t, files["t"]) <= 1e-12
    assert result.t[0] == 0.0 and result.t[-1] == pytest.approx(20 * result.forcing_period)


def test_trajectory_and_another_method_equal_the_cli_files(cli):
    flags = dict(figure="4b", periods=6, skip_periods=3, record=[5, 2], method="exact")
    result = pwl.simulate(**flags)
    out = cli.out("simulate", "--figure", "4b", "--periods", "6", "--skip-periods", "3",
                  "--record", "5,2", "--method", "exact", "--quiet")
    files = read_csv(out / "poincare.csv")
    assert result.poincare.shape == (3, 10)  # periods 4, 5 and 6
    assert largest_difference(result.poincare, state_matrix(files, STATE)) <= 1e-12
    trajectory = read_csv(out / "trajectory.csv")
    assert result.trajectory_columns == ["x5", "x2", "v5", "v2"]
    assert result.trajectory.shape[0] == len(trajectory["t"]) > 0
    assert largest_difference(result.trajectory,
                              state_matrix(trajectory, result.trajectory_columns)) <= 1e-12
    assert largest_difference(result.trajectory_t, trajectory["t"]) <= 1e-12
    assert result.method == "exact" and result.stats["steps"] > 0


def test_a_hyperplane_section_from_an_initial_state_equals_the_cli_file(cli):
    result = pwl.simulate(figure="4a", periods=10, section="v5=0,down", x0=0.1, v0=[0, 0, 0, 0, 1])
    files = read_csv(cli.out("simulate", "--figure", "4a", "--periods", "10", "--section",
                             "v5=0,down", "--x0", "0.1", "--v0", "0,0,0,0,1", "--quiet") /
                     "poincare.csv")
    assert result.poincare.shape[0] == len(files["t"]) > 5
    assert largest_difference(result.poincare, state_matrix(files, STATE)) <= 1e-12
    assert largest_difference(result.t, files["t"]) <= 1e-12
    assert np.abs(result.poincare[:, 9]).max() < 1e-6  # v5 = 0 at every crossing


def test_arrays_are_owned_float64_and_c_contiguous():
    result = pwl.simulate(figure="4a", periods=3, record=[1])
    for array in (result.poincare, result.t, result.trajectory, result.trajectory_t):
        assert array.dtype == np.float64
        assert array.flags["C_CONTIGUOUS"] and array.flags["OWNDATA"]
    copy = result.poincare.copy()
    del result  # the arrays outlive the result object and the C++ run
    assert np.isfinite(copy).all()


@pytest.mark.parametrize("flags, args", [
    (dict(n=0), ["--n", "0"]),                         # CLI11's check
    (dict(theta=-1), ["--theta", "-1"]),               # the library's check
    (dict(record=[7]), ["--record", "7"]),             # simulate's own check
    (dict(figure="9"), ["--figure", "9"]),
    (dict(dt=0.3), ["--dt", "0.3"]),
    (dict(skip_periods=5, periods=5), ["--skip-periods", "5", "--periods", "5"]),
])
def test_bad_values_raise_input_error_with_the_cli_message(cli, flags, args):
    with pytest.raises(pwl.InputError) as raised:
        pwl.simulate(**flags)
    assert isinstance(raised.value, ValueError)
    message = str(raised.value)
    assert message and message in cli.error("simulate", *args, "--quiet")


def test_unknown_and_file_keywords_raise_type_error():
    with pytest.raises(TypeError, match="unexpected keyword argument 'peroids'"):
        pwl.simulate(figure="4a", peroids=20)
    with pytest.raises(TypeError, match="does not take out="):
        pwl.simulate(figure="4a", out="folder")
    with pytest.raises(TypeError, match="locate_kinks is a flag"):
        pwl.simulate(figure="4a", locate_kinks="yes")


def test_the_gil_is_released_while_it_integrates():
    # The main thread keeps running Python while another thread integrates. Were the GIL held
    # during the integration, the main thread would stand still for the whole run: one gap
    # between its ticks as long as the run.
    run = {}

    def work():
        start = time.perf_counter()
        run["points"] = pwl.simulate(figure="4a", periods=150000).poincare.shape[0]
        run["seconds"] = time.perf_counter() - start

    worker = threading.Thread(target=work)
    ticks = [time.perf_counter()]
    worker.start()
    while worker.is_alive():
        sum(range(1000))
        ticks.append(time.perf_counter())
    worker.join()
    assert run["points"] == 150001
    assert run["seconds"] > 0.3, "the run is too short for the check to mean anything"
    longest = max(np.diff(ticks))
    print("run {:.2f} s, {} ticks of the main thread, longest gap {:.4f} s".format(
        run["seconds"], len(ticks), longest))
    assert longest < 0.25 * run["seconds"]


def test_ctrl_c_stops_a_long_run():
    flags = dict(n=100, periods=1000)
    start = time.perf_counter()
    pwl.simulate(**flags)
    expected = 20 * (time.perf_counter() - start)  # the run below is 20 times as long
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        pwl.simulate(n=100, periods=20000)
    stopped = time.perf_counter() - start
    timer.join()
    print("stopped after {:.2f} s of an expected {:.1f} s".format(stopped, expected))
    assert stopped < 0.3 * expected
