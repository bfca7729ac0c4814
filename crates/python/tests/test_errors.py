"""Every error class raises its exception, with the Rust message; the bad-input corpus of the
command line raises the same messages from Python."""

import pathlib

import numpy as np
import pytest

import piezocontact as pc

BAD = pathlib.Path(__file__).resolve().parents[3] / "tests" / "bad-input"


def test_the_hierarchy():
    assert issubclass(pc.PiezocontactError, Exception)
    assert issubclass(pc.InputError, pc.PiezocontactError) and issubclass(pc.InputError, ValueError)
    assert issubclass(pc.MeshError, pc.InputError)
    assert issubclass(pc.SolverError, pc.PiezocontactError) and issubclass(pc.SolverError, ArithmeticError)
    assert issubclass(pc.ConvergenceError, pc.SolverError)
    assert issubclass(pc.OutputError, pc.PiezocontactError) and issubclass(pc.OutputError, OSError)
    assert pc.InputError.__module__ == "piezocontact"


def expected_class(path: pathlib.Path):
    name = path.stem
    if name.startswith("mesh-") and name != "mesh-n-with-gmsh" or name == "missing-group" or name == "missing-dirichlet-group":
        return pc.MeshError
    if name.startswith("overflowing-") and name != "overflowing-stiffness" or name == "too-large":
        return pc.SolverError
    return pc.InputError


@pytest.mark.parametrize("path", sorted(BAD.glob("*.toml")), ids=lambda p: p.stem)
def test_the_bad_input_corpus_raises_its_class_with_the_programs_message(path):
    expect = path.read_text().splitlines()[0].removeprefix("# expect:").strip()
    with pytest.raises(pc.PiezocontactError) as info:
        pc.run(pc.Scene.from_toml(path))
    assert expect in str(info.value)
    assert isinstance(info.value, expected_class(path)), type(info.value).__name__


def test_scene_errors_name_the_key_and_leave_the_scene_unchanged():
    s = pc.Scene.load("paper", {"mesh.n": 8})
    with pytest.raises(pc.InputError, match="solver.strategy `fast` is unknown"):
        s.set("solver.strategy", "fast")
    with pytest.raises(pc.InputError, match="unknown field `nn`"):
        s.set("mesh.nn", 3)
    # friction does not apply to Signorini's law: the two changes go together
    with pytest.raises(pc.InputError, match="contact.friction does not apply") as info:
        s.set("contact.law", "signorini")
    # the key is kept as data, not only in the message
    assert info.value.key == "contact.friction"
    assert s.get("contact.law") == "coulomb" and s.get("mesh.n") == 8
    s.set({"contact.law": "signorini", "contact.friction": None})
    assert s.get("contact.law") == "signorini" and s.get("contact.friction") is None
    with pytest.raises(pc.InputError, match="no `contact.nothing` to remove"):
        s.set("contact.nothing", None)
    with pytest.raises(pc.InputError, match="has no meaning in a scene"):
        s.set("mesh.n", object())
    with pytest.raises(pc.InputError, match="needs a value"):
        s.set("mesh.n")


def test_a_scene_for_the_petsc_backend_is_refused_not_solved_by_the_default_one():
    s = pc.Scene.load("paper", {"mesh.n": 4, "solver.backend": "petsc"})
    with pytest.raises(pc.InputError, match='solver.backend = "petsc" asks for the distributed backend') as info:
        pc.run(s)
    assert info.value.key == "solver.backend"


def test_an_error_that_is_no_scene_values_has_no_key():
    with pytest.raises(pc.InputError) as info:
        pc.Scene.load("papper")
    assert info.value.key is None


def test_scene_sources_name_what_is_wrong(tmp_path):
    with pytest.raises(pc.InputError, match="no shipped scene of that name"):
        pc.Scene.load("papper")
    with pytest.raises(pc.InputError, match="TOML parse error"):
        pc.Scene.from_toml("name = \n")
    with pytest.raises(pc.InputError, match="no such file"):
        pc.Scene.from_toml("scenes/papper.toml")
    with pytest.raises(pc.InputError, match="missing field `mesh`"):
        pc.Scene.from_dict({"name": "x", "description": ""})
    with pytest.raises(pc.InputError, match="is not a regular file"):
        pc.Scene.from_toml(tmp_path)


def test_a_mesh_of_bad_arrays_raises_a_mesh_error():
    s = pc.Scene.load("paper", {"mesh.n": 8})
    points = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    bottom = {"bottom": [[0, 1]]}
    with pytest.raises(pc.MeshError, match="cell 1 is inverted"):
        s.set_mesh(points, [[0, 1, 2], [0, 3, 2]], bottom)
    with pytest.raises(pc.MeshError, match="refers to node 9"):
        s.set_mesh(points, [[0, 1, 2], [0, 2, 9]], bottom)
    with pytest.raises(pc.MeshError, match="negative index"):
        s.set_mesh(points, [[0, 1, 2], [0, 2, -1]], bottom)
    with pytest.raises(pc.MeshError, match="must hold integer indices"):
        s.set_mesh(points, np.array([[0, 1, 2], [0, 2, 3]]) + 0.5, bottom)
    with pytest.raises(pc.MeshError, match="not an array of indices"):
        s.set_mesh(points, [[0, 1, 2], [0, 2]], bottom)
    with pytest.raises(pc.MeshError, match="non-finite coordinate"):
        s.set_mesh([[0.0, 0.0], [1.0, float("nan")], [1.0, 1.0], [0.0, 1.0]], [[0, 1, 2], [0, 2, 3]], bottom)
    with pytest.raises(pc.MeshError, match="the mesh has no cells"):
        s.set_mesh(points, np.zeros((0, 3), dtype=int), bottom)
    with pytest.raises(pc.MeshError, match="cells of 5 nodes"):
        s.set_mesh(points, [[0, 1, 2, 3, 0]], bottom)
    with pytest.raises(pc.MeshError, match="facets of 3 nodes"):
        s.set_mesh(points, [[0, 1, 2], [0, 2, 3]], {"bottom": [[0, 1, 2]]})
    # the scene is unchanged by the refusals
    assert s.get("mesh.kind") == "rectangle"
    # a good mesh without the scene's groups: named at the run
    s.set_mesh(points, [[0, 1, 2], [0, 2, 3]], bottom)
    # the first group the set-up looks for: the load's, or a condition's
    with pytest.raises(pc.MeshError, match="boundary group `(left|top)` is missing"):
        pc.run(s)


def test_a_contact_solve_that_does_not_converge_raises_a_convergence_error():
    # docs/stability.md: under strong coupling the friction fixed point of the first-order
    # strategies stops improving, and is stopped (a fraction of a second on the condensed problem)
    s = pc.Scene.load("paper", {"mesh.n": 32, "material.coupling_scale": 100, "solver.strategy": "uzawa-condensed"})
    with pytest.raises(pc.ConvergenceError, match="the friction fixed point did not converge .* it stopped improving") as info:
        pc.run(s)
    assert "try solver.strategy=newton-condensed" in str(info.value)
    # and the hint is right
    s.set("solver.strategy", "newton-condensed")
    assert pc.run(s).report["residuals"]["converged_to_tolerance"]


def test_a_run_out_of_time_raises_a_convergence_error():
    s = pc.Scene.load("paper", {"mesh.n": 16, "solver.strategy": "uzawa-direct"})
    with pytest.raises(pc.ConvergenceError, match="the deadline passed"):
        pc.run(s, timeout=0.0)
    with pytest.raises(pc.InputError, match="timeout"):
        pc.run(s, timeout=-1.0)


def test_an_output_that_cannot_be_written_raises_an_output_error(tmp_path):
    r = pc.run(pc.Scene.load("paper", {"mesh.n": 4}))
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    with pytest.raises(pc.OutputError):
        r.write(blocker / "out")
    assert blocker.read_text() == "not a directory"
