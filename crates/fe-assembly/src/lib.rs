//! P1 finite elements for static electro-elasticity: materials, element kernels, dof maps,
//! parallel assembly of the blocks `A`, `G`, `B`, loads, and recovery of stress and electric
//! displacement.
//!
//! # Glossary (signs fixed by docs/theory.md)
//! - `u`: displacement; `φ` (`phi`): electric potential; `E = -∇φ`.
//! - Law: `σ = C ε(u) + eᵀ ∇φ`, `D = e ε(u) - β ∇φ` (`C`: elasticity, `e`: piezoelectric
//!   stress constants, `β` (`beta`): permittivity). Voigt order `[xx, yy, xy]` (2D, plane
//!   strain) or `[xx, yy, zz, yz, xz, xy]` (3D), engineering shear strains.
//! - Blocks over free dofs: `A = ∫ Bᵀ C B` (u-u), `G_{ψ,u} = ∫ (e ε(u)) · ∇ψ` (φ-u),
//!   `B = ∫ ∇Nᵀ β ∇N` (φ-φ). The paper's system is `[[A, Gᵀ], [-G, B]] [u; φ] = [f; q]`;
//!   negating the electric rows gives the symmetric quasi-definite
//!   `K = [[A, Gᵀ], [G, -B]]` with right-hand side `[f; -q]`, which is what
//!   [`Discretization::rhs`] returns.
//! - Loads: body force `f0`, traction `f2 = σ n`, body charge `q0` (the paper's `div D = q0`),
//!   surface charge `q2 = D · n`.
//! - Units: those of the scene (scaled scenes: m, GPa, C/m², nF/m, so φ is in GV).
//!
//! # Example
//! ```
//! use fe_assembly::{Constraint, Coordinates, Crystal, Discretization, Field, Load, Material, Parallelism};
//! use std::sync::Arc;
//! let mesh = mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4);
//! let pzt = Material::from_crystal("pzt5a", &Crystal::pzt5a(), [0.0, 1.0, 0.0], 2).unwrap();
//! let mut bcs = vec![];
//! for side in ["left", "right"] {
//!     bcs.push(Constraint::constant(side, Field::Displacement(0), 0.0));
//!     bcs.push(Constraint::constant(side, Field::Displacement(1), 0.0));
//!     bcs.push(Constraint::constant(side, Field::Potential, 0.0));
//! }
//! let disc = Discretization::new(&mesh, Coordinates::Cartesian, &[("body".into(), pzt)], &bcs).unwrap();
//! let blocks = disc.assemble(Parallelism::Rayon);
//! let load = Load::Traction { group: "top".into(), value: Arc::new(|_| [0.0, -2.0, 0.0]) };
//! let (b_u, b_phi) = disc.rhs(&[load]).unwrap();
//! assert_eq!(blocks.a.nrows(), disc.dofs.n_u);
//! assert_eq!(blocks.g.nrows(), disc.dofs.n_phi);
//! // the total vertical load is p times the length of the top face, less what the clamped
//! // corners take
//! let total: f64 = b_u.iter().skip(1).step_by(2).sum();
//! assert!((total - (-2.0 * 2.0 * 7.0 / 8.0)).abs() < 1e-12);
//! assert!(b_phi.iter().all(|&q| q == 0.0));
//! ```

mod assembly;
mod dofs;
pub mod exact;
pub mod held;
pub mod kernels;
mod loads;
pub mod mapping;
mod material;
mod recovery;

pub use assembly::{cell_materials, Blocks, Discretization, Parallelism};
pub use dofs::{Constraint, Dof, DofMap, Field, Prescribed};
pub use exact::{ErrorNorms, Exact, Face, FaceConstants, FaceElectric, FrictionFn, Sliding};
pub use held::{free_in, rigid_gram, Held, Support, Unheld};
pub use loads::{facet_measure, FacetMap, Load, RhsParts};
pub use material::{voigt, voigt_len, Coordinates, Crystal, Material, MaterialError, OutOfPlane};
pub use recovery::{CellFields, ChargeFunctional, NodeFields, Tensors, VTK_TENSOR_ORDER};

use std::sync::Arc;

/// A scalar function of position (its argument holds `dim` coordinates).
pub type ScalarFn = Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;
/// A vector function of position (`dim` meaningful components of the result).
pub type VectorFn = Arc<dyn Fn(&[f64]) -> [f64; 3] + Send + Sync>;

/// Inconsistent input of a discretisation: the first bad item, by name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// The mesh's cells are not P1 simplices.
    #[error("{kind} cells are not supported: the kernels are P1 simplices")]
    CellKind {
        /// The cells' name.
        kind: &'static str,
    },
    /// A material of another dimension than the mesh.
    #[error("material of region `{region}` is {material}D, the mesh is {mesh}D")]
    MaterialDimension {
        /// The region.
        region: String,
        /// The material's dimension.
        material: usize,
        /// The mesh's.
        mesh: usize,
    },
    /// A cell in two regions of the materials.
    #[error("cell {cell} lies in region `{first}` and in region `{second}`: one material per cell")]
    TwoMaterials {
        /// The cell.
        cell: usize,
        /// The region of its first material.
        first: String,
        /// The other region.
        second: String,
    },
    /// A cell in no region of the materials.
    #[error(
        "cell {cell} has no material (regions given: {}): {cells} cells lie in no region a material names; {}",
        .regions.join(", "),
        match &.theirs[..] {
            [] => "they lie in no region of their own (the materials' regions must cover the mesh: check their boxes or physical groups)".to_string(),
            theirs => format!(
                "they lie in the mesh's {} {} (give {} a material, [[material]] region = \"{}\")",
                if theirs.len() == 1 { "region" } else { "regions" },
                theirs.iter().map(|r| format!("`{r}`")).collect::<Vec<_>>().join(", "),
                if theirs.len() == 1 { "it" } else { "each" },
                theirs[0]
            ),
        }
    )]
    NoMaterial {
        /// The first cell without one.
        cell: usize,
        /// How many cells have none.
        cells: usize,
        /// The mesh's regions made of such cells alone (a Gmsh physical group left unnamed is
        /// its tag), none of them a material's.
        theirs: Vec<String>,
        /// The regions of the materials.
        regions: Vec<String>,
    },
    /// A condition on a displacement component the problem does not have.
    #[error("condition on `{group}` prescribes displacement component {component} in a {dim}D problem")]
    Component {
        /// The condition's group.
        group: String,
        /// The component.
        component: usize,
        /// The problem's dimension.
        dim: usize,
    },
    /// A condition whose value is not finite at a node.
    #[error("condition on `{group}` gives the non-finite value {value} at node {node}")]
    NotFiniteCondition {
        /// The condition's group.
        group: String,
        /// The value.
        value: f64,
        /// The node.
        node: usize,
    },
    /// Two conditions that prescribe different values to one unknown.
    #[error("node {node} at {at:?} gets {field} = {first_value} from `{first}` and {field} = {second_value} from `{second}`: two conditions prescribe different values to one unknown where their groups meet")]
    Conflicting {
        /// The node.
        node: usize,
        /// Its coordinates.
        at: Vec<f64>,
        /// The field.
        field: Field,
        /// The first condition's group, and its value.
        first: String,
        /// The first value.
        first_value: f64,
        /// The second condition's group.
        second: String,
        /// The second value.
        second_value: f64,
    },
    /// A charge put on a group that is no floating terminal.
    #[error("a charge is put on `{group}`, which is no floating terminal (no Field::Floating condition on it)")]
    NotFloating {
        /// The group.
        group: String,
    },
    /// A floating terminal that shares a node with another terminal (one conductor).
    #[error("node {node} at {at:?} lies on the floating terminal `{floating}` and on the terminal `{other}`: they touch, so they are one conductor (give them one condition)")]
    JoinedTerminals {
        /// The node.
        node: usize,
        /// Its coordinates.
        at: Vec<f64>,
        /// The floating terminal's group.
        floating: String,
        /// The other terminal's group.
        other: String,
    },
    /// A condition that reaches no unknown.
    #[error("condition on {field} of `{group}` reaches no degree of freedom{}", if matches!(*.field, Field::Potential | Field::Floating) { " (no node of it carries a potential)" } else { "" })]
    ReachesNothing {
        /// The field.
        field: Field,
        /// The condition's group.
        group: String,
    },
    /// A material whose Voigt layout is not the body's coordinates' (a body of revolution's
    /// material on a plane body, or the other way).
    #[error("region `{region}`'s material is made for {} coordinates and the body's are {} (a body is of revolution as a whole, each material made for it)", .material.name(), .body.name())]
    MaterialCoordinates {
        /// The region.
        region: String,
        /// Its material's coordinates.
        material: Coordinates,
        /// The body's.
        body: Coordinates,
    },
    /// A body of revolution whose mesh is not its 2D meridian section.
    #[error("a body of revolution is meshed in its 2D meridian plane, and the mesh is {dim}D")]
    AxisymmetricDimension {
        /// The mesh's dimension.
        dim: usize,
    },
    /// A node of a body of revolution's meridian section on the negative side of the axis.
    #[error("node {node} at {at:?} has r = x < 0: a body of revolution is meshed in its meridian plane r >= 0 (the axis is x = 0)")]
    NegativeRadius {
        /// The node.
        node: usize,
        /// Its coordinates.
        at: Vec<f64>,
    },
    /// A load whose value is not finite.
    #[error("{what} is not finite ({value})")]
    NotFiniteLoad {
        /// The load (`the body force`, `the traction`, ...).
        what: &'static str,
        /// The value.
        value: f64,
    },
}

/// What can go wrong while setting up or assembling.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AssemblyError {
    /// A mesh problem (a missing group, a bad cell).
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
    /// A material problem.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// Inconsistent input (materials, conditions, loads), naming the item.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A rigid motion or a potential the Dirichlet conditions leave free.
    #[error(transparent)]
    Unheld(#[from] Unheld),
}
