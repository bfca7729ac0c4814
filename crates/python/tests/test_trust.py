"""Issue 20 from Python: a run nested in another's progress callback has its own cancel flag,
complex arrays are refused, time limits read as the command line reads them, a relative
mesh.file resolves where it was typed, and every form of MSH 4.1 that the installed gmsh
writes reads as the same mesh (when gmsh is installed)."""

import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import piezocontact as pc

FORMS = pathlib.Path(__file__).resolve().parents[2] / "mesh" / "tests" / "fixtures"


def test_a_nested_run_has_its_own_cancel_flag():
    inner = []

    def progress(line):
        # a run started from the outer run's callback, once: it must not reset or take the
        # outer run's flag
        if not inner and line.strip().startswith("newton"):
            inner.append(pc.run(pc.Scene.load("paper", {"mesh.n": 4})))
            raise KeyboardInterrupt  # stops the outer run through its own flag

    with pytest.raises(KeyboardInterrupt):
        pc.run(pc.Scene.load("paper", {"mesh.n": 16}), progress=progress)
    assert inner and inner[0].report["residuals"]["converged_to_tolerance"]
    # the flags are given back: a run after both is not cancelled
    assert pc.run(pc.Scene.load("paper", {"mesh.n": 4})).report["residuals"]["converged_to_tolerance"]


def test_complex_points_are_refused():
    s = pc.Scene.load("paper", {"mesh.n": 4})
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=complex)
    with pytest.raises(pc.MeshError, match="real numbers"):
        s.set_mesh(pts, np.array([[0, 1, 2], [0, 2, 3]]), {"bottom": np.array([[0, 1]])})


@pytest.mark.parametrize("timeout", [math.inf, 1e19, 1e300])
def test_a_timeout_beyond_the_clock_is_no_limit(timeout):
    r = pc.run(pc.Scene.load("paper", {"mesh.n": 4}), timeout=timeout)
    assert r.report["residuals"]["converged_to_tolerance"]


@pytest.mark.parametrize("timeout", [math.nan, -1.0, -math.inf])
def test_a_timeout_that_is_no_number_of_seconds_is_refused(timeout):
    with pytest.raises(pc.InputError, match="not a positive number of seconds"):
        pc.run(pc.Scene.load("paper", {"mesh.n": 4}), timeout=timeout)


def test_a_relative_mesh_file_resolves_where_it_was_typed(tmp_path, monkeypatch):
    monkeypatch.chdir(FORMS / "forms")
    s = pc.Scene.from_dict(stack("x.msh"))
    s.set("mesh.file", "2d-ascii.msh")
    check_stack(pc.run(s))


def stack(file):
    """Two dielectric layers and an internal electrode on their interface (the closed form:
    phi = y / 0.8 below it, (1 - y) / 0.2 above)."""
    return {
        "name": "stack",
        "description": "an internal electrode between two dielectric layers",
        "mesh": {"kind": "gmsh", "file": str(file)},
        "material": [
            {"region": "substrate", "model": "isotropic", "young": 100.0, "poisson": 0.3, "permittivity": [2.0]},
            {"region": "pzt", "model": "isotropic", "young": 50.0, "poisson": 0.25, "permittivity": [5.0]},
        ],
        "dirichlet": [{"group": "bottom", "u": [0.0, 0.0], "phi": 0.0}, {"group": "top", "phi": 0.0}],
        "electrode": {"group": "interface", "v": 1.0},
    }


def check_stack(r):
    y = r.points[:, 1]
    exact = np.where(y <= 0.8, y / 0.8, (1 - y) / 0.2)
    used = np.zeros(len(y), dtype=bool)
    used[np.asarray(r.cells).ravel()] = True
    assert np.max(np.abs(r.phi[used] - exact[used])) < 1e-12


def test_every_form_the_installed_gmsh_writes_reads_as_the_same_mesh(tmp_path):
    try:
        import gmsh  # type: ignore[import-untyped]  # noqa: F401 (its library may be missing: OSError)
    except (ImportError, OSError) as e:
        pytest.skip(f"gmsh is not usable here: {e}")
    subprocess.run([sys.executable, str(FORMS / "write_forms.py"), str(tmp_path)], check=True)
    files = sorted(f for f in tmp_path.glob("2d-*.msh") if "-split_" not in f.name)
    assert len(files) >= 11
    for f in files:
        check_stack(pc.run(pc.Scene.from_dict(stack(f))))
    # a part of a mesh Gmsh split into files is a piece of the body: refused, naming its parts
    part = tmp_path / "2d-ascii-split_2.msh"
    with pytest.raises(pc.MeshError, match=r"part 2 of a mesh that Gmsh split into 3 files"):
        pc.run(pc.Scene.from_dict(stack(part)))
    # the second-order file: six-node triangles, its edge nodes exact too
    r = pc.run(pc.Scene.from_dict(stack(tmp_path / "2d-ascii-order2.msh")))
    assert r.cell_type == "triangle6" and np.asarray(r.cells).shape[1] == 6


def test_a_body_only_its_bed_holds_runs_and_what_it_leaves_free_is_named():
    # the paper's block on its compliant bed, its sides on rollers: only the bed holds it
    s = pc.Scene.load("paper-compliance", {"mesh.n": 8})
    s.set({"dirichlet.0.u": None, "dirichlet.1.u": None})
    s.set({"dirichlet.0.ux": 0.0, "dirichlet.1.ux": 0.0})
    r = pc.run(s)
    assert r.report["residuals"]["converged_to_tolerance"]
    assert r.report["iterations"]["bed"] > 0
    # the bed carries the whole load: 2 (pressure) x 2 (width)
    assert abs(r.report["contact"]["normal_force"] - 4.0) < 1e-9
    # nothing on the sides: the bed does not hold the slide
    s.set({"dirichlet.0.ux": None, "dirichlet.1.ux": None})
    with pytest.raises(pc.InputError, match=r"compliant bed leave 1 rigid motion of the body free \(a translation along \[1.000, 0.000\]\)"):
        pc.run(s)
