"""Load paths from Python: the series as arrays, the same numbers as the command-line
program's path.csv, the contact values of every instant on request."""

import csv
import subprocess

import numpy as np

import piezocontact as pc


def test_the_series_are_the_programs_path_csv(binary, tmp_path):
    overrides = {"mesh.n": 8, "path.steps": 12}
    args = [str(binary), "run", "actuator-cycle", "--out", str(tmp_path)]
    for k, v in overrides.items():
        args += ["--set", f"{k}={v}"]
    subprocess.run(args, check=True, capture_output=True)
    with open(tmp_path / "path.csv") as f:
        rows = list(csv.DictReader(f))
    r = pc.run(pc.Scene.load("actuator-cycle", overrides))
    p = r.path
    assert p is not None
    assert len(p["t"]) == len(rows) == 13
    for column in ["t", "voltage", "normal_force", "tangential_force", "max_slip", "n_stick"]:
        expected = np.array([float(row[column]) for row in rows])
        assert np.allclose(p[column], expected, rtol=1e-12, atol=1e-15), column
    assert p["terminals"] == ["left", "right", "electrode"]
    assert p["charges"].shape == (13, 3)
    charges = np.array([[float(row[f"charge_{t}"]) for t in p["terminals"]] for row in rows])
    assert np.allclose(p["charges"], charges, rtol=1e-12, atol=1e-15)
    # the fields of the instants the library did not need are not computed: no equilibrium
    assert np.isnan(p["equilibrium"][:-1]).all() and p["equilibrium"][-1] < 1e-8
    assert "lambda_n" not in p


def test_every_instants_contact_values_on_request():
    scene = pc.Scene.load("cattaneo-mindlin-cycle", {"mesh.n": 24, "path.steps": 6})
    r = pc.run(scene, series=True)
    p = r.path
    n = len(r.contact.lambda_n)
    for key in ["lambda_n", "lambda_t", "u_n", "u_t", "status"]:
        assert p[key].shape == (7, n), key
    # the last instant's values are the result's own; the forces are the weighted sums
    assert np.allclose(p["lambda_n"][-1], r.contact.lambda_n, rtol=1e-12, atol=0)
    w = r.contact.weight
    assert np.allclose(p["lambda_n"] @ w, p["normal_force"], rtol=1e-12)
    assert np.allclose(p["lambda_t"] @ w, p["tangential_force"], rtol=1e-12, atol=1e-14)
    assert pc.run(pc.Scene.load("paper", {"mesh.n": 8})).path is None
