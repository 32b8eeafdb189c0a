"""What the Python module's tests share: the pwl program, run in a temporary folder, and its CSV
files read back as columns, so that every test compares the module with the program's own output
for the same flags. ctest sets PWL_EXECUTABLE (the program), PYTHONPATH (the module in the build
tree) and PWL_SOURCE_DIR (the shipped scenes and examples)."""

import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("PWL_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
SCENES = SOURCE_DIR / "apps" / "scenes"


def pwl_executable():
    path = os.environ.get("PWL_EXECUTABLE")
    if not path:
        pytest.fail("PWL_EXECUTABLE is not set (ctest sets it to the built pwl program)")
    return path


class Cli:
    """Runs `pwl JOB ARGS...` in a temporary folder."""

    def __init__(self, folder):
        self.folder = folder

    def run(self, job, *args, code=0):
        """The program's exit code must be `code`; returns the completed process."""
        process = subprocess.run([pwl_executable(), job, *map(str, args)], cwd=self.folder,
                                 capture_output=True, text=True)
        assert process.returncode == code, (
            "pwl {} {} exited with {}:\n{}{}".format(job, " ".join(map(str, args)),
                                                    process.returncode, process.stdout,
                                                    process.stderr))
        return process

    def out(self, job, *args):
        """Runs the job with --out into a fresh folder and returns that folder."""
        out = self.folder / "{}_{}".format(job, len(list(self.folder.iterdir())))
        self.run(job, *args, "--out", out)
        return out

    def error(self, job, *args):
        """Runs the job on bad input (exit code 2) and returns its message on standard error."""
        return self.run(job, *args, code=2).stderr


@pytest.fixture
def cli(tmp_path):
    return Cli(tmp_path)


def read_csv(path):
    """A CSV file as {column: array}: float64 where every cell is a number (an empty cell is
    NaN), str otherwise."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    columns = {}
    for j, name in enumerate(header):
        cells = [row[j] for row in body]
        try:
            columns[name] = np.array([float(c) if c != "" else np.nan for c in cells])
        except ValueError:
            columns[name] = np.array(cells, dtype=str)
    return columns


def state_matrix(columns, names):
    """The columns `names` of read_csv's result side by side, (rows, len(names))."""
    return np.column_stack([columns[name] for name in names])


def largest_difference(a, b):
    """max |a - b| over arrays of one shape, NaN where both are NaN counting as equal."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, (a.shape, b.shape)
    both = np.isnan(a) & np.isnan(b)
    assert not (np.isnan(a) ^ np.isnan(b)).any(), "NaN in one array only"
    return float(np.max(np.abs(np.where(both, 0.0, a - b)), initial=0.0))
