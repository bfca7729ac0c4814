"""The examples run, and draw their figures."""

import pathlib
import subprocess
import sys

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def run_example(name, tmp_path, *args):
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / name), "--out", str(tmp_path), *args],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_paper_figures(tmp_path):
    out = run_example("paper_figures.py", tmp_path, "--n", "16")
    for name in ["fig2-deformed", "fig3-multipliers", "fig4-potential", "fig5-multipliers", "fig6-multipliers"]:
        png = tmp_path / f"{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    assert "load -6: normal force" in out


def test_the_actuator_sweep(tmp_path):
    out = run_example("actuator_sweep.py", tmp_path, "--n", "8", "--points", "5")
    assert (tmp_path / "actuator-sweep.png").read_bytes()[:4] == b"\x89PNG"
    rows = [line.split() for line in out.splitlines()[1:6]]
    voltages = [float(r[0]) for r in rows]
    forces = [float(r[1]) for r in rows]
    separated = [int(r[4]) for r in rows]
    assert voltages == [-0.1, 0.0, 0.1, 0.2, 0.3]
    # lifted off at -0.1 (every point separated), then pressed harder as the voltage rises
    assert forces[0] == 0.0 and separated[0] > 0 and separated[-1] == 0
    assert all(a < b for a, b in zip(forces[1:], forces[2:])), forces
