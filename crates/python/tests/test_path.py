"""Load paths from Python: the series as arrays, the same numbers as the command-line
program's path.csv, the contact values of every instant on request."""

import json
import subprocess

import numpy as np
from conftest import csv_rows

import piezocontact as pc


def test_the_series_are_the_programs_path_csv(binary, tmp_path):
    overrides = {"mesh.n": 8, "path.steps": 12}
    args = [str(binary), "run", "actuator-cycle", "--out", str(tmp_path)]
    for k, v in overrides.items():
        args += ["--set", f"{k}={v}"]
    subprocess.run(args, check=True, capture_output=True)
    rows = csv_rows(tmp_path / "path.csv")
    # each column's unit in its header is run.json's
    header = (tmp_path / "path.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
    units = json.loads((tmp_path / "run.json").read_text(encoding="utf-8"))["units"]["columns"]["path.csv"]
    for cell in header:
        name = cell.split(" [")[0]
        assert cell == (f"{name} [{units[name]}]" if units[name] else name), cell
    assert "normal_force [" in ",".join(header)
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
    potentials = np.array([[float(row[f"potential_{t}"]) for t in p["terminals"]] for row in rows])
    assert np.allclose(p["potentials"], potentials, rtol=1e-12, atol=1e-15)
    # the fields of the instants the library did not need are not computed: no equilibrium
    assert np.isnan(p["equilibrium"][:-1]).all() and p["equilibrium"][-1] < 1e-8
    assert "lambda_n" not in p


def test_every_instants_contact_values_on_request():
    scene = pc.Scene.load("cattaneo-mindlin-cycle", {"mesh.n": 24, "path.steps": 6})
    r = pc.run(scene, series=True)
    p = r.path
    n = len(r.contact.lambda_n)
    for key in ["lambda_n", "u_n", "status"]:
        assert p[key].shape == (7, n), key
    for key in ["lambda_t", "u_t"]:
        assert p[key].shape == (7, n, 1), key
    # the last instant's values are the result's own; the forces are the weighted sums
    assert np.allclose(p["lambda_n"][-1], r.contact.lambda_n, rtol=1e-12, atol=0)
    w = r.contact.weight
    assert np.allclose(p["lambda_n"] @ w, p["normal_force"], rtol=1e-12)
    # the tangent is x: the resultant's x component is the signed sum, its magnitude the norm
    assert np.allclose(p["lambda_t"][:, :, 0] @ w, p["tangential_force_x"], rtol=1e-12, atol=1e-14)
    assert np.allclose(np.abs(p["tangential_force_x"]), p["tangential_force"], rtol=1e-12, atol=1e-14)
    assert np.allclose(p["tangential_force_y"], 0.0, atol=1e-14)
    assert pc.run(pc.Scene.load("paper", {"mesh.n": 8})).path is None


def test_a_floating_electrode_pushed_onto_a_foundation_along_a_path():
    """The sensor disc pushed down by d at its top onto a frictionless rigid foundation (its
    grounded bottom in contact instead of on a support), its top electrode open: uniaxial strain
    eps = -d / h with D_z = 0 reads V = e33 eps h / eps33 at every instant of the ramp."""
    data = pc.Scene.load("sensor").to_dict()
    d = 1e-3
    for c in data["dirichlet"]:
        if c["group"] == "bottom":
            del c["uy"]
        if c["group"] == "top":
            c["uy"] = -d
    del data["load"]
    data["contact"] = {"group": "bottom", "law": "signorini", "normal": [0.0, -1.0]}
    data["path"] = {"t": [0.0, 1.0], "steps": 4, "displacement": [0.0, 1.0]}
    r = pc.run(pc.Scene.from_dict(data))
    p = r.path
    top = p["terminals"].index("top")
    e33, eps33 = 15.1, 5.62
    expected = e33 * (-d * p["t"]) / eps33
    assert np.allclose(p["potentials"][:, top], expected, rtol=1e-9, atol=1e-15)
    assert np.allclose(p["charges"][:, top], 0.0, atol=1e-12)
    assert [t["floating"] for t in r.report["terminals"] if t["group"] == "top"] == [True]


def test_a_force_depth_curve_under_force_control():
    """hertz-sphere's force ramped along a path: the depth found at each instant is Hertz's,
    d = (3 F / (4 E* sqrt(R)))^(2/3), within the mesh's 1 %."""
    scene = pc.Scene.load(
        "hertz-sphere",
        {
            "mesh.n": 96,
            "exact": None,
            "contact.indenter.force": 0.46,
            "path": {"t": [0.0, 1.0], "steps": 10, "load": [0.0, 1.0], "output_every": 0},
        },
    )
    p = pc.run(scene).path
    force = 0.46 * p["t"]
    assert np.allclose(p["normal_force"], force, rtol=1e-9, atol=1e-15)
    e_star = 100.0 / (1.0 - 0.3**2)
    hertz = (3.0 * force / (4.0 * e_star * np.sqrt(10.0))) ** (2.0 / 3.0)
    assert np.all(np.abs(p["depth"][1:] / hertz[1:] - 1.0) < 0.01)
    assert p["depth"][0] == 0.0


def test_each_contact_groups_forces_along_a_path():
    """Several [[contact]] groups: path.csv's per-group columns, in the path dict too; the
    groups' normal forces sum to the total at every instant."""
    scene = pc.Scene.load("corner", {"mesh.n": 4, "path": {"t": [0.0, 1.0], "gap": [0.0, 1.0], "steps": 4}})
    p = pc.run(scene).path
    total = p["normal_force_right"] + p["normal_force_top"]
    assert np.allclose(total, p["normal_force"], rtol=1e-12, atol=0)
    for g in ["right", "top"]:
        for key in [f"tangential_force_{g}", f"tangential_force_x_{g}", f"tangential_force_y_{g}"]:
            assert np.all(p[key] == 0.0), key


def test_a_conducting_foundation_follows_a_path():
    """paper-conducting, frictionless, its load, electrode voltage and foundation potential
    ramped from 0: without friction each instant is the static run at its own data (its force
    and the foundation's flux), and the series carries each point's flux."""
    base = {"mesh.n": 12, "contact.law": "signorini", "contact.friction": None,
            "contact.foundation_potential": 0.01}
    path = dict(base, path={"t": [0.0, 1.0], "steps": 2, "load": [0.0, 1.0], "voltage": [0.0, 1.0]})
    r = pc.run(pc.Scene.load("paper-conducting", path), series=True)
    p = r.path
    assert p["flux"].shape == p["lambda_n"].shape == (3, len(r.contact.lambda_n))
    w = r.contact.weight
    for k, t in enumerate(p["t"]):
        if t == 0.0:
            continue
        alone = pc.run(pc.Scene.load("paper-conducting", dict(
            base, **{"load.p": -2.0 * t, "electrode.v": 0.05 * t, "contact.foundation_potential": 0.01 * t})))
        assert np.isclose(p["normal_force"][k], alone.report["contact"]["normal_force"], rtol=1e-7)
        flux = np.nansum(w * p["flux"][k])
        assert np.isclose(flux, np.nansum(w * alone.contact.flux), rtol=1e-7)


def test_the_force_depth_charge_curve_of_a_conducting_tip():
    """pfm-curve from Python: the tip's charge and the half-space's closed form beside each
    instant, the force and the charge within 2.5 % of it at the smoke size."""
    r = pc.run(pc.Scene.load("pfm-curve", {"mesh.n": 48, "path.steps": 4}))
    p = r.path
    touching = p["t"] > 0
    for run, form in [("normal_force", "half_space_force"), ("tip_charge", "half_space_charge")]:
        assert np.allclose(p[run][touching], p[form][touching], rtol=0.025), run
    assert np.all(np.diff(p["half_space_force"][touching]) > 0)


def test_the_programs_steps_are_compressed_files_meshio_reads(binary, tmp_path):
    """A path's step-NNNN.vtu: zlib-compressed, read by meshio; u, phi and the contact's
    fields in every step, the cell fields where path.cell_fields asks; the last step's u is
    solution.vtu's. The key reaches the library's scenes too."""
    import meshio

    for cells in [False, True]:
        out = tmp_path / f"cells-{cells}"
        args = [str(binary), "run", "cattaneo-mindlin-cycle", "--out", str(out)]
        for k, v in {"mesh.n": 8, "path.steps": 4, "path.cell_fields": str(cells).lower()}.items():
            args += ["--set", f"{k}={v}"]
        subprocess.run(args, check=True, capture_output=True)
        last = meshio.read(out / "step-0004.vtu")
        assert b'compressor="vtkZLibDataCompressor"' in (out / "step-0004.vtu").read_bytes()[:600]
        for key in ["u", "phi", "contact_status", "contact_pressure", "contact_traction", "contact_gap"]:
            assert key in last.point_data, key
        assert ("stress" in last.cell_data) == cells
        solution = meshio.read(out / "solution.vtu")
        assert np.array_equal(last.point_data["u"], solution.point_data["u"])
        scene = pc.Scene.load("cattaneo-mindlin-cycle", {"mesh.n": 8, "path.steps": 4, "path.cell_fields": cells})
        assert pc.run(scene).path is not None
