"""A mesh passed as arrays gives the answer of the same mesh from a file, or generated."""

import meshio
import numpy as np
import pytest

import piezocontact as pc

from conftest import REPO

SCENE = REPO / "tests" / "scenes" / "layered-gmsh.toml"
MSH = REPO / "crates" / "mesh" / "tests" / "fixtures" / "layered2d.msh"


def gmsh_arrays(path):
    """points, cells, named boundary facets and named regions of a Gmsh file, through meshio
    (as a user holding gmsh's or meshio's arrays has them)."""
    m = meshio.read(path)
    names = {(int(tag), int(dim)): name for name, (tag, dim) in m.field_data.items()}
    tags = m.cell_data["gmsh:physical"]
    boundary, regions, cells = {}, {}, []
    for block, tag in zip(m.cells, tags):
        if block.type in ("line", "line3"):
            for t in np.unique(tag):
                boundary.setdefault(names[(t, 1)], []).append(block.data[tag == t])
        elif block.type in ("triangle", "triangle6"):
            for t in np.unique(tag):
                first = sum(len(c) for c in cells)
                regions.setdefault(names[(t, 2)], []).append(first + np.flatnonzero(tag == t))
            cells.append(block.data)
    boundary = {k: np.concatenate(v) for k, v in boundary.items()}
    regions = {k: np.concatenate(v) for k, v in regions.items()}
    return m.points, np.concatenate(cells), boundary, regions


def by_position(points, values):
    """Values reordered by their points' coordinates (two meshes may number nodes apart)."""
    order = np.lexsort(points.T[::-1])
    return values[order]


def test_a_gmsh_mesh_as_arrays_gives_the_files_answer():
    from_file = pc.run(pc.Scene.from_toml(SCENE))
    scene = pc.Scene.from_toml(SCENE)
    points, cells, boundary, regions = gmsh_arrays(MSH)
    # meshio's points of a 2D mesh have three columns, z = 0: a plane, so a 2D mesh
    assert points.shape[1] == 3
    scene.set_mesh(points, cells, boundary, regions)
    assert scene.get("mesh.kind") == "given" and scene.get("mesh.file") is None
    from_arrays = pc.run(scene)
    assert len(from_arrays.points) == len(from_file.points) and from_arrays.dim == 2
    # as two columns, the same mesh
    scene.set_mesh(points[:, :2], cells, {k: v.tolist() for k, v in boundary.items()}, regions)
    assert np.array_equal(pc.run(scene).u, from_arrays.u)
    for field in ["u", "phi"]:
        a = by_position(from_arrays.points, getattr(from_arrays, field))
        b = by_position(from_file.points, getattr(from_file, field))
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max(), field
    assert np.isclose(
        from_arrays.report["contact"]["normal_force"], from_file.report["contact"]["normal_force"], rtol=1e-12
    )


def rectangle_groups(points, cells):
    """The boundary edges of a triangle mesh of a rectangle, by side."""
    edges = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    outer = unique[count == 1]
    lo, hi = points.min(axis=0), points.max(axis=0)
    on = lambda k, v: np.all(np.isclose(points[outer][:, :, k], v), axis=1)  # noqa: E731
    return {"left": outer[on(0, lo[0])], "right": outer[on(0, hi[0])], "bottom": outer[on(1, lo[1])], "top": outer[on(1, hi[1])]}


def test_the_paper_mesh_as_arrays_gives_the_generated_answer():
    generated = pc.run(pc.Scene.load("paper", {"mesh.n": 8}))
    points, cells = np.array(generated.points), np.array(generated.cells)
    scene = pc.Scene.load("paper")
    # clockwise triangles (as some generators write them) are turned round
    scene.set_mesh(points, cells[:, ::-1], rectangle_groups(points, cells))
    given = pc.run(scene, progress=lambda line: None)
    # [c2, c1, c0] turned round is [c2, c0, c1], the same triangle as [c0, c1, c2]
    assert np.array_equal(given.cells, generated.cells[:, [2, 0, 1]])
    assert np.abs(given.u - generated.u).max() <= 1e-12 * np.abs(generated.u).max()
    assert np.abs(given.contact.lambda_n - generated.contact.lambda_n).max() <= 1e-12 * generated.contact.lambda_n.max()
    # back to a generated mesh: the arrays go, and the generated mesh is run
    scene.set("mesh", {"kind": "rectangle", "lo": [0.0, 0.0], "hi": [2.0, 1.0], "n": 4})
    assert "mesh given" not in repr(scene)
    assert len(pc.run(scene).points) == 9 * 5


def test_a_3d_mesh_as_arrays_gives_the_generated_answer():
    generated = pc.run(pc.Scene.load("paper-3d", {"mesh.n": 2}))
    points, cells = np.array(generated.points), np.array(generated.cells)
    faces = np.sort(np.concatenate([cells[:, f] for f in ([0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3])]), axis=1)
    unique, count = np.unique(faces, axis=0, return_counts=True)
    outer = unique[count == 1]
    lo, hi = points.min(axis=0), points.max(axis=0)
    on = lambda k, v: outer[np.all(np.isclose(points[outer][:, :, k], v), axis=1)]  # noqa: E731
    groups = {"left": on(0, lo[0]), "right": on(0, hi[0]), "front": on(1, lo[1]), "back": on(1, hi[1]), "bottom": on(2, lo[2]), "top": on(2, hi[2])}
    scene = pc.Scene.load("paper-3d")
    scene.set_mesh(points, cells, groups)
    given = pc.run(scene)
    assert np.abs(given.u - generated.u).max() <= 1e-12 * np.abs(generated.u).max()
    assert np.isclose(given.report["contact"]["normal_force"], generated.report["contact"]["normal_force"], rtol=1e-12)


def test_quadratic_elements_from_the_scene_and_as_arrays():
    # mesh.order = 2 raises the generated mesh: six-node triangles, the manufactured error far
    # below order 1's on the same cells
    p1 = pc.run(pc.Scene.load("manufactured", {"mesh.n": 8}))
    p2 = pc.run(pc.Scene.load("manufactured", {"mesh.n": 8, "mesh.order": 2}))
    assert p2.cell_type == "triangle6" and np.asarray(p2.cells).shape == (np.asarray(p1.cells).shape[0], 6)
    e1, e2 = (r.report["exact"]["error"] for r in (p1, p2))
    assert e2 < 0.2 * e1, (e1, e2)
    # its arrays handed back as a given mesh (edge nodes in VTK's order, facets of 3 nodes)
    # give the same answer
    points, cells = np.array(p2.points), np.array(p2.cells)
    corners = rectangle_groups(points, cells[:, :3])
    mids = {}
    for name, edges in corners.items():
        # each boundary edge's midpoint node: the node of the cell's edge with both corners
        at = {tuple(sorted((c[a], c[b]))): c[m] for c in cells for a, b, m in ((0, 1, 3), (1, 2, 4), (2, 0, 5))}
        mids[name] = np.array([[e[0], e[1], at[tuple(sorted(e))]] for e in edges])
    scene = pc.Scene.load("manufactured", {"mesh.order": 2, "exact.groups": list(mids)})
    scene.set_mesh(points, cells, mids)
    given = pc.run(scene)
    assert given.cell_type == "triangle6"
    assert np.abs(given.u - p2.u).max() <= 1e-12 * np.abs(p2.u).max()
    # edge nodes made per cell (each cell its own copy of a shared edge's midpoint) split the
    # body along the edge: refused by name, not run
    split_points = np.vstack([points, points[cells[1, 3:]]])
    split_cells = cells.copy()
    split_cells[1, 3:] = len(points) + np.arange(3)
    with pytest.raises(pc.MeshError, match="second midpoint node"):
        scene.set_mesh(split_points, split_cells, mids)
    # the fields at the nodes of P2 cells (none on P1 cells, constant in each), in meshio's
    # point data too
    assert p1.fields_at_nodes is None
    at = p2.fields_at_nodes
    assert at["stress"].shape == (len(points), 3) and at["electric_field"].shape == (len(points), 2)
    # to meshio: the quadratic cells under their name
    m = p2.to_meshio()
    assert m.cells[0].type == "triangle6"
    # as solution.vtu holds it: six components in VTK's order, [xx, yy, zz, xy, yz, xz]
    assert np.array_equal(m.point_data["stress"][:, [0, 1, 3]], at["stress"])
    # contact at order 2 in 3D runs (the modified basis), electrical contact too
    r = pc.run(pc.Scene.load("paper-3d", {"mesh.n": 2, "mesh.order": 2}))
    assert r.cell_type == "tetra10" and r.report["residuals"]["converged_to_tolerance"]
    r = pc.run(pc.Scene.load("indent-sphere-3d", {"mesh.n": 4, "mesh.order": 2, "contact.electric": "conducting"}))
    assert r.report["residuals"]["converged_to_tolerance"] and r.report["indenter"]["charge"] != 0.0
    # an order other than 1 or 2 is refused by its key
    with pytest.raises(pc.InputError, match="mesh.order"):
        pc.run(pc.Scene.load("paper", {"mesh.n": 4, "mesh.order": 3}))
    # in 2D it runs
    r = pc.run(pc.Scene.load("paper", {"mesh.n": 8, "mesh.order": 2}))
    assert r.report["residuals"]["converged_to_tolerance"] and len(r.contact.lambda_n) == 2 * 16 - 1  # the clamped ends are no points


def test_curved_second_order_cells_as_arrays():
    # Gmsh's quarter annulus 1 < r < 2 at second order, its edge nodes on the arcs (curved,
    # isoparametric cells), handed over as meshio's arrays: a cylindrical capacitor whose
    # electrode's charge is pi eps V / (2 ln 2)
    points, cells, boundary, regions = gmsh_arrays(REPO / "crates" / "mesh" / "tests" / "fixtures" / "annulus2d-order2.msh")
    assert cells.shape[1] == 6
    scene = pc.Scene.from_dict(
        {
            "name": "capacitor",
            "description": "a cylindrical capacitor on curved cells",
            "mesh": {"kind": "given"},
            "material": [{"region": "body", "model": "isotropic", "young": 100.0, "poisson": 0.3, "permittivity": [3.0]}],
            "dirichlet": [{"group": "inner", "u": [0.0, 0.0], "phi": 0.0}],
            "electrode": {"group": "outer", "v": 1.0},
        }
    )
    scene.set_mesh(points[:, :2], cells, boundary, regions)
    r = pc.run(scene)
    assert r.report["mesh"]["curved_cells"] > 0 and r.cell_type == "triangle6"
    q = next(t["charge"] for t in r.report["terminals"] if t["group"] == "electrode")
    assert abs(q / (np.pi * 3.0 / (2 * np.log(2.0))) - 1.0) < 1e-4, q

