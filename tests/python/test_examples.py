"""Every example of apps/python/examples/ runs at a small size and writes what it says, and the
folder's README.md lists every example: none rots unseen. Each example takes --small (a quick
size) and ends by printing "wrote FILE" (its --out, relative to the folder it runs in)."""

import importlib.util
import os
import re
import shutil
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

FOLDER = SOURCE_DIR / "apps" / "python" / "examples"
EXAMPLES = sorted(FOLDER.glob("*.py"))
NO_PLOTTER = shutil.which("gnuplot") is None and importlib.util.find_spec("matplotlib") is None
DRAWING = ("bifurcation_diagram.py", "regime_map.py")


def run_small(example, folder):
    process = subprocess.run([sys.executable, str(example), "--small"], cwd=folder,
                             capture_output=True, text=True, env=dict(os.environ))
    assert process.returncode == 0, process.stdout + process.stderr
    wrote = re.findall(r"^wrote (.+)$", process.stdout, re.M)
    assert wrote, "{} printed no 'wrote FILE':\n{}".format(example.name, process.stdout)
    made = folder / wrote[-1]
    assert made.is_file() and made.stat().st_size > 0, made
    return process.stdout, made


def test_there_are_examples_and_the_index_lists_each():
    assert len(EXAMPLES) >= 3
    index = (FOLDER / "README.md").read_text()
    for example in EXAMPLES:
        assert "({})".format(example.name) in index, "README.md does not list " + example.name


def bifurcation_diagram(printed, made):
    assert "period-doubling at θ = " in printed
    data = made.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000


def regime_map(printed, made):
    rows = re.findall(r"^α = +[0-9.]+  (\S+)$", printed, re.M)
    assert len(rows) == 4 and all(len(r) == 6 for r in rows), printed
    assert made.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def periodic_orbit_of_a_structure(printed, made):
    assert printed.startswith("OrbitResult(period-1 orbit, ")
    assert "ContinuationResult(spring1.gap: " in printed
    lines = made.read_text().splitlines()
    assert lines[0] == "gap,max_abs_multiplier,stable,amplitude_x2"
    gaps = [float(line.split(",")[0]) for line in lines[1:]]
    assert len(gaps) > 5 and gaps[0] == pytest.approx(0.2) and max(gaps) >= 0.35


# What an example's output must show besides its file, by example (an example without an entry is
# only run).
CHECKS = {"bifurcation_diagram.py": bifurcation_diagram, "regime_map.py": regime_map,
          "periodic_orbit_of_a_structure.py": periodic_orbit_of_a_structure}


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda path: path.stem)
def test_every_example_runs_small(example, tmp_path):
    if NO_PLOTTER and example.name in DRAWING:
        pytest.skip("neither gnuplot nor matplotlib to draw with")
    printed, made = run_small(example, tmp_path)
    if example.name in CHECKS:
        CHECKS[example.name](printed, made)
