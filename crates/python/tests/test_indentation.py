"""Indentation and terminals from Python: a body of revolution under a rigid sphere (the shipped
hertz-sphere scene) with its indenter's figures in the report, its four stress components per
cell ([rr, zz, rz, θθ]), another shape set from Python, and the capacitance matrix."""

import math

import piezocontact as pc


def test_hertz_sphere_from_python():
    r = pc.run(pc.Scene.load("hertz-sphere"))
    report = r.report
    assert report["exact"]["force_error"] < 0.01
    ind = report["indenter"]
    assert ind["shape"] == "paraboloid" and ind["depth"] == 0.01
    assert abs(ind["force"] - report["exact"]["load_p"]) == 0.0
    assert r.stress.shape[1] == 4


def test_a_cone_set_from_python_follows_sneddon():
    scene = pc.Scene.load("hertz-sphere")
    scene.set("exact", None)
    scene.set("contact.indenter", {"shape": "cone", "half_angle": 70.0, "depth": 0.01})
    r = pc.run(scene)
    e_star = 100.0 / (1.0 - 0.3**2)
    closed = 2.0 / math.pi * e_star * 0.01**2 * math.tan(math.radians(70.0))
    # measured +1.2 % at the scene's mesh
    assert abs(r.report["indenter"]["force"] - closed) / closed < 0.025


def test_the_capacitance_matrix_from_python():
    # the actuator's three terminals: reciprocal, each column's charges summing to zero
    c = pc.capacitance(pc.Scene.load("actuator", {"mesh.n": 16}))
    assert c["terminals"] == ["left", "right", "electrode"]
    m = c["matrix"]
    assert m.shape == (3, 3)
    assert abs(m - m.T).max() < 1e-10 * abs(m).max()
    assert abs(m.sum(axis=0)).max() < 1e-10 * abs(m).max()
    assert c["asymmetry"] < 1e-10 and c["column_sum"] < 1e-10
    # in the scene's units: lengths in m, stresses in GPa, plane strain (per unit thickness)
    assert c["unit"] == "(C/m)/GV"
    # the electrode's ends are nodes at n = 16, not at n = 10 (x every 0.1): then it is shorter
    assert c["notes"] == []
    short = pc.capacitance(pc.Scene.load("actuator", {"mesh.n": 10}))
    assert any("covers x in [0.3, 1.7]" in n for n in short["notes"])


def test_an_open_electrode_from_python():
    # the shipped sensor: the open-circuit voltage of a pressed, laterally confined PZT-4 disc
    r = pc.run(pc.Scene.load("sensor"))
    top = next(t for t in r.report["terminals"] if t["group"] == "top")
    assert top["floating"]
    expected = -0.01 * 15.1 * 0.5 / (115.0 * 5.62 + 15.1**2)
    assert abs(top["potential"] - expected) < 1e-10 * abs(expected)
    # the same open top as a floating [[electrode]] half of two, the other half grounded:
    # several electrodes, each its own terminal, from a list of dicts
    scene = pc.Scene.load("sensor")
    data = scene.to_dict()
    data["dirichlet"] = [d for d in data["dirichlet"] if d["group"] != "top"]
    data["electrode"] = [
        {"group": "top", "x_range": [0.0, 0.5], "charge": 0.0, "name": "sense"},
        {"group": "top", "x_range": [0.75, 1.0], "v": 0.0, "name": "guard"},
    ]
    r = pc.run(pc.Scene.from_dict(data))
    groups = {t["group"]: t for t in r.report["terminals"]}
    assert groups["sense"]["floating"] and not groups["guard"].get("floating", False)
    # the grounded guard draws part of the field: the open sense reads less than the whole top
    assert 0.0 < groups["sense"]["potential"] / expected < 1.0


def test_the_piezoelectric_half_space_closed_form_from_python():
    # indent-sphere reports the half-space's closed form beside its own figures
    # (measured 0.58 % in force, 0.27 % in the tip's potential at the shipped mesh)
    r = pc.run(pc.Scene.load("indent-sphere"))
    h = r.report["indenter"]["half_space"]
    assert r.report["exact"]["error"] == h["error"] < 0.01
    assert h["electric_error"] < 0.01
    # a floating (open) conducting tip: its potential found, no charge on it
    scene = pc.Scene.load("indent-sphere")
    scene.set("contact.electric", "conducting")
    scene.set("contact.charge", 0.0)
    ind = pc.run(scene).report["indenter"]
    assert abs(ind["charge"]) < 1e-9 * ind["force"]
    assert ind["potential"] > 0.0 and ind["half_space"]["potential"] > 0.0


def test_several_contact_groups_from_python():
    # a unit square on symmetry rollers squeezed by two walls 1e-3 inside it ([[contact]] as a
    # list of dicts): each wall carries (2 lambda + 2 mu) delta, the corner node a point of both
    young, nu, delta = 100.0, 0.3, 1e-3
    scene = pc.Scene.from_dict(
        {
            "name": "corner",
            "description": "a square squeezed by two walls",
            "mesh": {"kind": "rectangle", "lo": [0.0, 0.0], "hi": [1.0, 1.0], "n": 4},
            "material": [{"region": "body", "model": "isotropic", "young": young, "poisson": nu}],
            "dirichlet": [{"group": "left", "ux": 0.0}, {"group": "bottom", "uy": 0.0}],
            "contact": [
                {"group": "right", "law": "signorini", "normal": [1.0, 0.0], "gap": -delta},
                {"group": "top", "law": "signorini", "normal": [0.0, 1.0], "gap": -delta},
            ],
        }
    )
    r = pc.run(scene)
    lam = young * nu / ((1 + nu) * (1 - 2 * nu))
    mu = young / (2 * (1 + nu))
    p = (2 * lam + 2 * mu) * delta
    groups = r.report["contact"]["groups"]
    assert [g["group"] for g in groups] == ["right", "top"]
    for g in groups:
        assert abs(g["normal_force"] - p) < 1e-9 * p


def test_each_contact_group_keeps_its_own_law_from_python():
    # the corner's two walls from a list of dicts, each its own friction law: the right wall
    # Tresca's bound 1e-3, the top wall Coulomb's 0.3 weakening to 0.1 over 1e-5; every point
    # within its own zone's radius (the weakening one's at its own slip)
    scene = pc.Scene.load("corner")
    scene.set(
        {
            "contact.0.law": "tresca",
            "contact.0.slip_bound": 1e-3,
            "contact.1.law": "coulomb",
            "contact.1.friction_law": "slip-weakening",
            "contact.1.friction_static": 0.3,
            "contact.1.friction_dynamic": 0.1,
            "contact.1.slip_length": 1e-5,
        }
    )
    r = pc.run(scene)
    c = r.contact
    assert c is not None
    assert c.groups == ["right", "top"] == [g["group"] for g in r.report["contact"]["groups"]]
    assert set(c.group.tolist()) == {0, 1}
    weakened = 0
    for i, g in enumerate(c.group):
        ln, lt, ut = c.lambda_n[i], abs(c.lambda_t[i, 0]), abs(c.u_t[i, 0])
        radius = 1e-3 if g == 0 else (0.3 - 0.2 * min(ut / 1e-5, 1.0)) * ln
        assert lt <= radius * (1 + 1e-8) + 1e-14, (i, lt, radius)
        weakened += g == 1 and c.status[i] == pc.SLIP and radius < 0.3 * ln * (1 - 1e-6)
    assert weakened > 0


def test_an_indenter_condenses_only_the_points_it_can_touch():
    # indent-sphere-3d at n = 8: 9 of the face's 81 points lie within 3 depths of the tip; the
    # result still has every point, the ones left out open; pushed onto the sphere by its
    # clamped top, the run is done again with every point
    lines = []
    r = pc.run(pc.Scene.load("indent-sphere-3d", {"mesh.n": 8}), progress=lines.append)
    assert r.report["solver"]["condensed_points"] == 9
    assert any(line.startswith("contact: 9 of 81 points can touch") for line in lines)
    assert r.contact.lambda_n.shape == (81,)
    touching = (r.contact.lambda_n > 0).sum()
    assert 0 < touching <= 9
    lines = []
    pushed = pc.Scene.load("indent-sphere-3d", {"mesh.n": 8, "dirichlet.0.u": [0.0, 0.0, -0.5]})
    r = pc.run(pushed, progress=lines.append)
    assert "condensed_points" not in r.report["solver"]
    assert any("solving again with all 81" in line for line in lines)
    assert (r.contact.lambda_n > 0).sum() > 9 > touching
