"""Static frictional contact of piezoelectric bodies with a rigid foundation: scenes in, NumPy
arrays out.

    import piezocontact as pc
    scene = pc.Scene.load("paper", {"mesh.n": 64})
    result = pc.run(scene, progress=True)
    result.contact.lambda_n          # contact pressure, one value per contact node
    result.write("out/paper")        # run.json, solution.vtu, contact.csv, pictures
"""

import os
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from typing_extensions import final

__all__ = [
    "__version__",
    "Scene",
    "Result",
    "Contact",
    "run",
    "capacitance",
    "STICK",
    "SLIP",
    "SEPARATED",
    "PiezocontactError",
    "InputError",
    "MeshError",
    "SolverError",
    "ConvergenceError",
    "OutputError",
]

__version__: str

STICK: int
"""`Contact.status` of a point that sticks (1)."""
SLIP: int
"""`Contact.status` of a point that slides (2)."""
SEPARATED: int
"""`Contact.status` of a point off the foundation (3)."""

class PiezocontactError(Exception):
    """Every error of piezocontact."""

    key: str | None
    """The scene key at fault where the error is a scene value's (e.g. "contact.friction"), else None."""

class InputError(PiezocontactError, ValueError):
    """A scene value, material, file or array that cannot be used; the message names it."""

class MeshError(InputError):
    """A mesh that does not read, or is broken (a bad cell, a missing group, overlapping cells)."""

class SolverError(PiezocontactError, ArithmeticError):
    """A numerical failure: a singular system, a result that is not finite, a run too large for the memory."""

class ConvergenceError(SolverError):
    """The contact solve did not converge; the message gives its last residual and what to try."""

class OutputError(PiezocontactError, OSError):
    """An output file or directory that cannot be written."""

_Value = Union[bool, int, float, str, Sequence[Any], Mapping[str, Any], None]
_Path = Union[str, "os.PathLike[str]"]

@final
class Scene:
    """What to solve: a mesh, materials, boundary conditions, a load, an electrode, the contact
    law and the solver's settings (the keys of a scene file; see the README's scene keys).

    Every change is validated at once, with the errors of the command line: an `InputError`
    naming the key, and the scene left unchanged.
    """

    @staticmethod
    def load(name: _Path, overrides: Optional[Mapping[str, _Value]] = None, **keywords: Any) -> "Scene":
        """A shipped scene by name (`Scene.shipped()`), or a scene file by path, with
        `overrides` (dotted keys; None removes a key) and keywords (as `set` takes them:
        `mesh__n=128`, `solver={"tol": 1e-10}`) applied before it is validated."""
    @staticmethod
    def from_toml(source: _Path, overrides: Optional[Mapping[str, _Value]] = None, **keywords: Any) -> "Scene":
        """A scene from a TOML file (a path, or a string naming a file) or from TOML text."""
    @staticmethod
    def from_dict(
        scene: Mapping[str, Any], overrides: Optional[Mapping[str, _Value]] = None, **keywords: Any
    ) -> "Scene":
        """A scene from a dict of its sections, as the TOML file holds them."""
    @staticmethod
    def shipped() -> list[str]:
        """The names of the shipped scenes."""
    def set(self, *args: Any, **sections: Any) -> None:
        """Changes keys: `set("mesh.n", 128)`, `set({"contact.law": "signorini",
        "contact.friction": None})`, or keywords: a key with `__` for its dots
        (`set(mesh__n=128)`) or a section merged key by key (`set(mesh={"n": 128})`). None
        removes a key. A key named twice in one call (a dict and a keyword, a table and one of
        its keys) is an InputError."""
    def get(self, key: str, default: Any = None) -> Any:
        """The value of a dotted key (`scene.get("mesh.n")`, `scene.get("contact.1.gap")`: read
        as `set` writes it), or `default` where the scene does not set it; an InputError for a
        key that does not say which of several tables it means (`contact.gap` with two zones)."""
    def set_mesh(
        self,
        points: npt.ArrayLike,
        cells: npt.ArrayLike,
        boundary: Mapping[str, npt.ArrayLike],
        regions: Optional[Mapping[str, npt.ArrayLike]] = None,
    ) -> None:
        """Gives the scene a mesh as arrays (`mesh.kind` becomes "given"): `points` (n, 2) or
        (n, 3); `cells` (m, 3) triangles or (m, 4) quadrilaterals in 2D, (m, 4) tetrahedra in
        3D, 0-based, or second-order (m, 6) triangles and (m, 10) tetrahedra (VTK's order);
        `boundary` named facet arrays ((k, 2) in 2D, (k, 3) in 3D; at order 2 (k, 3) and
        (k, 6), the corners then the edges' midpoints); `regions`
        named cell-index arrays (default: all cells in "body"). Checked as a file's mesh is
        (`MeshError`). The arrays replace only how the mesh was made: the `[mesh]` keys that
        describe the body (`axisymmetric`, `revolve`) stay. A mesh too large for the memory
        left is refused before it is copied (`SolverError`, naming the limit)."""
    def to_dict(self) -> dict[str, Any]:
        """The scene as a dict of its sections."""
    def to_toml(self) -> str:
        """The scene as TOML text (a mesh given as arrays is not in it)."""
    def copy(self) -> "Scene":
        """A copy, to change without changing this one."""
    def __copy__(self) -> "Scene": ...
    def __deepcopy__(self, memo: Any) -> "Scene": ...
    @property
    def name(self) -> str:
        """The scene's name."""
    @property
    def dim(self) -> Optional[int]:
        """2 or 3; None for a Gmsh file not yet read."""
    @property
    def source(self) -> str:
        """A shipped scene's name, a path, "<dict>" or "<toml text>"."""

@final
class Contact:
    """The contact boundary's values, one row per contact point (a node of the contact group).
    Read-only float64 arrays unless said otherwise."""

    @property
    def x(self) -> npt.NDArray[np.float64]:
        """Positions, (m, dim)."""
    @property
    def node(self) -> npt.NDArray[np.int64]:
        """The mesh node of each point, (m,)."""
    @property
    def group(self) -> npt.NDArray[np.int64]:
        """The contact group of each point, (m,): its index in `groups` (a node of two groups
        is a point of each)."""
    @property
    def groups(self) -> list[str]:
        """The contact groups, in the scene's order."""
    @property
    def normal(self) -> npt.NDArray[np.float64]:
        """Outward unit normals of the body, (m, dim)."""
    @property
    def weight(self) -> npt.NDArray[np.float64]:
        """Lumped boundary measure, (m,): the normal force is `sum(weight * lambda_n)`."""
    @property
    def gap(self) -> npt.NDArray[np.float64]:
        """Initial gaps, (m,)."""
    @property
    def u_n(self) -> npt.NDArray[np.float64]:
        """Normal displacement, (m,): `u_n <= gap` on a rigid foundation; the penetration
        `u_n - gap` gives the pressure `k [u_n - gap]_+^m` on a compliant one."""
    @property
    def u_t(self) -> npt.NDArray[np.float64]:
        """Tangential displacement, (m, dim - 1)."""
    @property
    def lambda_n(self) -> npt.NDArray[np.float64]:
        """Normal multiplier, the contact pressure, (m,), >= 0."""
    @property
    def lambda_t(self) -> npt.NDArray[np.float64]:
        """Tangential multiplier, (m, dim - 1); zeros without friction."""
    @property
    def flux(self) -> Optional[npt.NDArray[np.float64]]:
        """Electrical contact: the outward flux D.nu through each point, (m,); NaN where an
        electrode prescribes the potential; None on an insulating foundation. The charge on
        the foundation across the zone is -nansum(weight * flux)."""
    @property
    def status(self) -> npt.NDArray[np.int8]:
        """STICK (1), SLIP (2) or SEPARATED (3), (m,)."""
    def __len__(self) -> int: ...

@final
class Result:
    """The solution of a run. The arrays are read-only views of the solution's storage."""

    @property
    def points(self) -> npt.NDArray[np.float64]:
        """Node coordinates, (n_points, dim)."""
    @property
    def cells(self) -> npt.NDArray[np.int64]:
        """Cell connectivity, (n_cells, nodes per cell), 0-based."""
    @property
    def cell_type(self) -> str:
        """"triangle", "quad", "tetra", or at order 2 "triangle6", "tetra10" (meshio's names)."""
    @property
    def dim(self) -> int:
        """2 (plane strain) or 3."""
    @property
    def u(self) -> npt.NDArray[np.float64]:
        """Nodal displacements, (n_points, dim)."""
    @property
    def phi(self) -> npt.NDArray[np.float64]:
        """Nodal electric potentials, (n_points,)."""
    @property
    def stress(self) -> npt.NDArray[np.float64]:
        """Stress per cell, Voigt order: (n_cells, 3) in plane strain, (n_cells, 4) on a body of
        revolution ([rr, zz, rz, θθ]), (n_cells, 6) in 3D."""
    @property
    def strain(self) -> npt.NDArray[np.float64]:
        """Strain per cell, Voigt order with engineering shears, shaped as `stress`."""
    @property
    def stress_tensor(self) -> npt.NDArray[np.float64]:
        """Stress per cell as full symmetric tensors, (n_cells, 3, 3), in every dimension: in
        plane strain with the stresses across the plane (sigma_zz; sigma_yz, sigma_xz where the
        material couples them), on a body of revolution in the axes (r, z, theta), in 3D
        (x, y, z)."""
    @property
    def strain_tensor(self) -> npt.NDArray[np.float64]:
        """Strain per cell as full symmetric tensors (tensor shears), shaped as
        `stress_tensor`."""
    @property
    def electric_displacement(self) -> npt.NDArray[np.float64]:
        """Electric displacement per cell, (n_cells, dim)."""
    @property
    def electric_field(self) -> npt.NDArray[np.float64]:
        """Electric field E = -grad phi per cell, (n_cells, dim)."""
    @property
    def fields_at_nodes(self) -> Optional[dict[str, npt.NDArray[np.float64]]]:
        """On quadratic (P2) cells: `stress`, `strain` ((n_points, nv)), `electric_displacement`
        and `electric_field` ((n_points, dim)) at the nodes, each node's value the
        measure-weighted average of its cells' values there; None on P1 cells (constant in
        each cell: the per-cell arrays are the whole field)."""
    @property
    def contact(self) -> Optional[Contact]:
        """The contact boundary's values; None for a scene without contact."""
    @property
    def path(self) -> Optional[dict[str, Any]]:
        """A load path's series (None for one instant): NumPy arrays over its instants, the
        path.csv columns (`t`, the factors, `normal_force`, `tangential_force` (the magnitude),
        `tangential_force_x`, `_y` (`_z` in 3D), with several contact groups each one's
        `normal_force_G`, `tangential_force_G`, `tangential_force_x_G`, ..., `max_slip`, ...,
        `equilibrium` NaN where the
        fields were not computed), `charges` (n_instants, n_terminals: the charge on each
        conductor) with `terminals` their groups; with `run(..., series=True)` also
        `lambda_n`, `u_n`, `status` (n_instants, n_points) and `lambda_t`, `u_t` (n_instants,
        n_points, dim - 1), and with electrical contact `flux` (n_instants, n_points: the
        outward flux D·n, NaN at a point without an electric unknown)."""
    @property
    def report(self) -> dict[str, Any]:
        """run.json as a dict; its `units` block gives the unit of every quantity
        (`units["quantities"]["potential"]`, ...) and of every CSV column, from the scene's
        `[units]` (SI where absent)."""
    def write(self, directory: _Path) -> None:
        """Writes run.json, solution.vtu, contact.csv and the plan's pictures into
        `directory`, as one set (`OutputError`; nothing half-written)."""
    def to_meshio(self) -> Any:
        """The solution as a `meshio.Mesh` (needs meshio): `u`, `phi`, `contact_status` as point
        data; `stress` and `strain` as cell data of six components in VTK's tensor order
        (xx, yy, zz, xy, yz, xz: what ParaView reads as XX .. XZ; tensor shears), `D` and `E`
        of three, as solution.vtu holds them."""

def capacitance(scene: Scene) -> dict[str, Any]:
    """The capacitance matrix between the terminals of `scene` (its electrode and the groups
    at a prescribed potential; the displacements it prescribes held at 0, no load, the contact
    face free): `terminals` (names; groups joined by a node as one, `a+b`), `matrix`
    (`C[i, j]`: the charge on terminal i per unit potential of terminal j, an ndarray),
    `asymmetry` and `column_sum` (reciprocity and Gauss's law, relative: round-off), `unit`
    (the scene's charge per its potential, e.g. `pC/kV`) and `notes` (what the set-up noted,
    as strings: an electrode the mesh covers less of than its `x_range`, ...).
    Raises InputError, MeshError, SolverError."""

def run(
    scene: Scene,
    progress: Union[bool, Callable[[str], Any], None] = None,
    timeout: Optional[float] = None,
    series: bool = False,
) -> Result:
    """Solves `scene`. `progress`: False, True (lines on sys.stderr) or a callable taking each
    line. `timeout`: seconds after which the run stops at its next check (ConvergenceError);
    inf (or a limit beyond the clock) is no limit, NaN and negatives are refused (InputError).
    `series`: for a scene with a [path], keep every point's contact values at every instant
    (`Result.path`).
    Ctrl-C stops the run at its next check and raises KeyboardInterrupt, nothing written.
    Raises InputError, MeshError, SolverError, ConvergenceError."""
