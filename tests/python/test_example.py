"""The README's example, apps/python/examples/bifurcation_diagram.py, runs and draws its figure."""

import importlib.util
import os
import shutil
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLE = SOURCE_DIR / "apps" / "python" / "examples" / "bifurcation_diagram.py"


NO_PLOTTER = shutil.which("gnuplot") is None and importlib.util.find_spec("matplotlib") is None


@pytest.mark.skipif(NO_PLOTTER, reason="neither gnuplot nor matplotlib to draw with")
def test_the_example_draws_its_figure(tmp_path):
    out = tmp_path / "theta.png"
    process = subprocess.run([sys.executable, str(EXAMPLE), "--out", str(out), "--points", "40"],
                             cwd=tmp_path, capture_output=True, text=True, env=dict(os.environ))
    assert process.returncode == 0, process.stdout + process.stderr
    assert "period-doubling at θ = " in process.stdout
    assert "wrote {}".format(out) in process.stdout
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000
