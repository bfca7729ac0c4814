"""Issue 42, class 1 and the keys of one call: a Python call that replaces part of a scene
keeps what it does not replace (`set_mesh` keeps `mesh.axisymmetric`), and a call that names
one key twice (a dict and a keyword, or a table and one of its keys) is refused by key instead
of keeping one of them silently."""

import numpy as np
import pytest

import piezocontact as pc

from test_mesh_arrays import rectangle_groups


def test_a_mesh_given_as_arrays_keeps_the_body_of_revolution():
    # (Hertz's exact solution is checked on the generated rectangle only)
    generated = pc.run(pc.Scene.load("hertz-sphere", {"mesh.n": 16, "exact": None}))
    points, cells = np.array(generated.points), np.array(generated.cells)
    groups = rectangle_groups(points, cells)
    groups["axis"] = groups["left"]
    scene = pc.Scene.load("hertz-sphere", {"exact": None})
    assert scene.get("mesh.axisymmetric") is True
    scene.set_mesh(points, cells, groups)
    # what the [mesh] table says of the body stays; how the mesh was made goes
    assert scene.get("mesh.axisymmetric") is True
    assert scene.get("mesh.kind") == "given"
    assert scene.get("mesh.n") is None and scene.get("mesh.hi") is None
    given = pc.run(scene)
    force = generated.report["contact"]["normal_force"]
    # the body of revolution's force, not the plane-strain block's (16.9 against 1.16 before)
    assert np.isclose(given.report["contact"]["normal_force"], force, rtol=1e-10)


@pytest.mark.parametrize(
    "call",
    [
        lambda s: s.set({"mesh.n": 8}, mesh__n=16),
        lambda s: s.set({"mesh.n": 8}, mesh={"n": 16}),
        lambda s: s.set({"mesh": {"kind": "rectangle", "lo": [0, 0], "hi": [2, 1], "n": 4}, "mesh.n": 8}),
        lambda s: s.set(contact={"friction": 0.3}, contact__friction=0.2),
        lambda s: s.set({"mesh.n": 8}, mesh__h=0.125),
        lambda s: s.set({"dirichlet[0].phi": 0.0, "dirichlet.0.phi": 0.1}),
        # the one table of an array (or of a section written as one table) by index or without
        lambda s: s.set({"material.0.poling": [0.0, 1.0, 0.0]}, material__poling=[1.0, 0.0, 0.0]),
        lambda s: s.set({"contact.0.friction": 0.3}, contact__friction=0.2),
    ],
)
def test_one_key_twice_in_one_call_is_refused(call):
    s = pc.Scene.load("paper", {"mesh.n": 4})
    with pytest.raises(pc.InputError, match="in one call"):
        call(s)
    # nothing changed
    assert s.get("mesh.n") == 4 and s.get("contact.friction") == 0.6


def test_distinct_keys_in_one_call_are_all_set():
    s = pc.Scene.load("paper", {"mesh.n": 4})
    s.set({"mesh.n": 8}, contact__friction=0.3, solver={"tol": 1e-9})
    assert (s.get("mesh.n"), s.get("contact.friction"), s.get("solver.tol")) == (8, 0.3, 1e-9)


def test_a_key_is_read_as_it_is_set():
    # by index in an array of tables (it read None: the value there looked unset)
    corner = pc.Scene.load("corner")
    assert corner.get("contact.1.group") == "top" and corner.get("contact[0].group") == "right"
    assert corner.get("material.0.model") == corner.get("material.model") == "crystal-6mm"
    assert corner.get("contact.2.group") is None and corner.get("contact.2.group", 7) == 7
    with pytest.raises(pc.InputError, match="holds 2 tables"):
        corner.get("contact.group")
    # a section written as one table, by index 0 too, before and after a change by index
    paper = pc.Scene.load("paper")
    assert paper.get("contact.0.friction") == paper.get("contact.friction") == 0.6
    paper.set({"contact.0.friction": 0.3})
    assert paper.get("contact.0.friction") == paper.get("contact.friction") == 0.3
