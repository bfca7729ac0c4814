"""Scenes: from a shipped name, a file, TOML text or a dict; changes by dotted key, by mapping
or by keyword section; the same scene whatever the route."""

import copy

import numpy as np

import pytest

import piezocontact as pc

from conftest import REPO


def test_every_route_gives_the_same_scene(tmp_path):
    shipped = pc.Scene.load("paper")
    path = REPO / "scenes" / "paper.toml"
    assert pc.Scene.from_toml(path).to_dict() == shipped.to_dict()
    assert pc.Scene.from_toml(str(path)).to_dict() == shipped.to_dict()
    assert pc.Scene.from_toml(path.read_text()).to_dict() == shipped.to_dict()
    assert pc.Scene.from_dict(shipped.to_dict()).to_dict() == shipped.to_dict()
    assert pc.Scene.from_toml(shipped.to_toml()).to_dict() == shipped.to_dict()
    assert shipped.name == "paper" and shipped.dim == 2 and shipped.source == "paper"
    assert "paper" in pc.Scene.shipped() and "paper-3d" in pc.Scene.shipped()


def test_changes_by_key_mapping_and_section():
    s = pc.Scene.load("paper", {"mesh.n": 32})
    assert s.get("mesh.n") == 32
    s.set("mesh.n", 16)
    s.set({"solver.tol": 1e-9, "load.p": -4})
    s.set(mesh={"n": 12}, contact={"friction": 0.3})
    assert (s.get("mesh.n"), s.get("solver.tol"), s.get("load.p"), s.get("contact.friction")) == (12, 1e-9, -4, 0.3)
    s.set(mesh__n=10, solver__tol=1e-8)
    assert (s.get("mesh.n"), s.get("solver.tol")) == (10, 1e-8)
    # keywords on the constructors too, the same as set()
    assert pc.Scene.load("paper", mesh__n=7).get("mesh.n") == 7
    assert pc.Scene.load("paper", {"mesh.n": 5}, solver={"tol": 1e-9}).to_dict() == pc.Scene.from_dict(
        pc.Scene.load("paper").to_dict(), mesh__n=5, solver__tol=1e-9
    ).to_dict()
    # the one [[material]] table is entered by its keys
    s.set("material.poling", [0.0, -1.0, 0.0])
    assert s.get("material.poling") == [0.0, -1.0, 0.0]
    assert s.get("nothing.here", "default") == "default"
    # numpy scalars are numbers
    np = pytest.importorskip("numpy")
    s.set("electrode", {"group": "top", "v": np.float64(0.1), "x_range": np.array([0.25, 1.75])})
    assert s.get("electrode.v") == 0.1 and s.get("electrode.x_range") == [0.25, 1.75]
    s.set({"mesh.n": np.int64(10), "solver.tol": np.array(1e-9), "load.p": np.float32(-2.0)})
    assert (s.get("mesh.n"), s.get("solver.tol"), s.get("load.p")) == (10, 1e-9, -2.0)
    assert type(s.get("mesh.n")) is int
    # a component of a list by its index, as --set takes it; past the end refused
    s.set({"load.direction.1": 0.5, "material.c.3": 100})
    assert s.get("load.direction") == [0.0, 0.5] and s.get("material.c")[3] == 100.0
    with pytest.raises(pc.InputError, match="beyond the 2 components of `load.direction`"):
        s.set("load.direction.2", 1.0)


def test_a_copy_is_independent():
    a = pc.Scene.load("paper", {"mesh.n": 8})
    for b in [a.copy(), copy.copy(a), copy.deepcopy(a)]:
        b.set("mesh.n", 4)
        assert a.get("mesh.n") == 8 and b.get("mesh.n") == 4


def test_a_change_changes_the_run():
    s = pc.Scene.load("paper", {"mesh.n": 8})
    f2 = pc.run(s).report["contact"]["normal_force"]
    s.set("load.p", -4.0)
    f4 = pc.run(s).report["contact"]["normal_force"]
    # the pressed block is linear in the load while every point sticks
    assert f4 == pytest.approx(2 * f2, rel=1e-9)


def test_a_crystal_by_name_and_by_datasheet():
    """`material.crystal` gives the library's constants (in the units it names), and
    `material.datasheet` a datasheet's converted to the stress-charge form: the paper's block
    with crystal PZT-5A is the paper's block, its datasheet's within the two sources' rounding,
    and the name's clash with given constants is refused by key."""
    gone = {"mesh.n": 8, "material.c": None, "material.e": None, "material.permittivity": None}
    named = pc.run(pc.Scene.load("paper", dict(gone, **{"material.crystal": "PZT-5A", "material.units": "GPa"})))
    given = pc.run(pc.Scene.load("paper", {"mesh.n": 8}))
    assert np.array_equal(named.u, given.u)
    sheet = {"d": [-171.0, 374.0, 584.0], "s_e": [16.4, -5.74, -7.22, 18.8, 47.5, 44.3],
             "relative_permittivity_t": [1730.0, 1700.0]}
    converted = pc.run(pc.Scene.load("paper", dict(gone, **{"material.datasheet": sheet, "material.units": "GPa"})))
    assert np.abs(converted.u - given.u).max() < 0.01 * np.abs(given.u).max()
    with pytest.raises(pc.InputError) as e:
        pc.Scene.load("paper", {"material.crystal": "PZT-4", "material.units": "GPa"})
    assert "material.c" in str(e.value)


def test_a_layered_body_from_a_dict():
    """`mesh.layer` from Python: the stack's layers and its internal electrodes (the groups
    the layers name) as the shipped scene has them, and a thickness that does not fill the
    body refused by key."""
    r = pc.run(pc.Scene.load("stack"))
    groups = [t["group"] for t in r.report["terminals"]]
    assert set(groups) == {"top", "bottom", "e1", "e2", "e3"}
    assert r.report["contact"]["normal_force"] > 0.9
    assert abs(sum(t["charge"] for t in r.report["terminals"])) < 1e-3
    data = pc.Scene.load("stack").to_dict()
    data["mesh"]["layer"][0]["thickness"] = 0.5
    with pytest.raises(pc.InputError) as e:
        pc.Scene.from_dict(data)
    assert e.value.key == "mesh.layer.thickness" and "sum to 1.25" in str(e.value)
