//! The memory a run needs, estimated before it is allocated, so that a run too large for the
//! machine stops with a typed error instead of an abort.
//!
//! Two checks. Before a generated mesh is made, a model of the sparse factor (nested
//! dissection: `α n log₂ n` entries in 2D, `α n^{4/3}` in 3D, with `n` the unknowns) gives a
//! lower estimate; the constants are the smallest measured on the shipped scenes (2D: 9.2 to
//! 9.9 at n = 64..256; 3D: 27 to 34 at n = 8..24), so a mesh refused here would not have fit.
//! Once assembled, the symbolic factorisation counts the factor's entries exactly
//! (`linalg`'s `new_within`), and the dense contact compliance of a condensed strategy is
//! `m²` doubles a copy: the run gets the memory left for the factor as its budget.

use crate::scene::{MeshKind, Scene};

/// The peak of a run per byte of its assembled system, dense contact problem and factor (the
/// factorisation's workspace and the recovery beside them), above [`BASE_BYTES`]: the excess
/// is nearly constant in bytes, so the ratio falls with the size (1.45 on `paper-3d` n = 12,
/// 1.03 on `paper` n = 1024, where a ratio of 1.5 refused a run of 16.4 GiB that fits in
/// 22.6); 1.2 with the base covers every run measured (docs/stability.md).
pub const PEAK_RATIO: f64 = 1.2;
/// Bytes of a run beside its system (the program, its threads' stacks and heaps, the
/// allocator's arenas, the outputs' buffers).
pub const BASE_BYTES: f64 = 256.0 * 1048576.0;

/// Bytes in a gibibyte, for messages.
pub const GIB: f64 = (1u64 << 30) as f64;

/// A count of bytes as a message writes it: in GiB from one GiB up, in MiB below (a small
/// run's estimate is not "0.0 GiB").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bytes(pub f64);

impl std::fmt::Display for Bytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const MIB: f64 = (1u64 << 20) as f64;
        match self.0 {
            b if b >= GIB => write!(f, "{:.1} GiB", b / GIB),
            b if b >= 10.0 * MIB => write!(f, "{:.0} MiB", b / MIB),
            b => write!(f, "{:.1} MiB", b / MIB),
        }
    }
}

/// Entries of the factor per `n log₂ n` (2D) in the nested-dissection model.
const ALPHA_2D: f64 = 9.0;
/// Entries of the factor per `n^{4/3}` (3D).
const ALPHA_3D: f64 = 25.0;
/// Bytes of the run per byte of the factor beside it (the matrix, its blocks, the mesh, the
/// solution; measured 1.5 to 1.7 on the shipped scenes, taken low).
const OVERHEAD: f64 = 1.3;

/// A generated mesh's sizes before it is made: `(dimension, nodes, cells, unknowns)`, with
/// displacements at every node and a potential where the scene has a piezoelectric or
/// dielectric body; `None` for a Gmsh mesh.
pub(crate) fn generated(scene: &Scene) -> Option<(usize, f64, f64, f64)> {
    let dim = scene.mesh.dim()?;
    let axes = scene.mesh.cells_per_axis();
    // a second-order mesh: the nodes of the grid of half the spacing
    let per_cell = scene.mesh.order.unwrap_or(1) as f64;
    let nodes: f64 = axes.iter().map(|&c| per_cell * c as f64 + 1.0).product();
    // simplices per square (2) or cube (6, Kuhn's split)
    let cells = axes.iter().map(|&c| c as f64).product::<f64>() * if dim == 2 { 2.0 } else { 6.0 };
    let electric = scene
        .material
        .iter()
        .any(|m| m.e.iter().any(|&x| x != 0.0) || m.permittivity.first().is_some_and(|&p| p > 0.0));
    let unknowns = nodes * (dim as f64 + if electric { 1.0 } else { 0.0 });
    Some((dim, nodes, cells, unknowns))
}

/// The lower estimate of a run's peak memory on a generated mesh, in bytes, with what it
/// counts; `None` for a Gmsh mesh (its size is known once read).
pub fn before_mesh(scene: &Scene) -> Option<(f64, String)> {
    let (_, _, _, unknowns) = generated(scene)?;
    let entries = match scene.mesh.kind {
        MeshKind::Rectangle => ALPHA_2D * unknowns * unknowns.log2().max(1.0),
        _ => ALPHA_3D * unknowns.powf(4.0 / 3.0),
    };
    let bytes = 8.0 * entries * OVERHEAD;
    Some((
        bytes,
        format!(
            "about {unknowns:.3e} unknowns, a sparse factor of at least {:.3e} entries ({})",
            entries,
            Bytes(8.0 * entries)
        ),
    ))
}

/// The same lower estimate on a mesh once it is known (read from a file, or handed over), for
/// `dim + 1` unknowns per node where the body is `electric`, else `dim`.
pub fn after_mesh(mesh: &mesh::Mesh, electric: bool) -> Option<(f64, String)> {
    let unknowns = mesh.n_nodes() as f64 * (mesh.dim as f64 + if electric { 1.0 } else { 0.0 });
    let entries = if mesh.dim == 2 {
        ALPHA_2D * unknowns * unknowns.log2().max(1.0)
    } else {
        ALPHA_3D * unknowns.powf(4.0 / 3.0)
    };
    Some((
        8.0 * entries * OVERHEAD,
        format!(
            "{unknowns:.3e} unknowns on the mesh of {} cells, a sparse factor of at least {entries:.3e} entries ({})",
            mesh.n_cells(),
            Bytes(8.0 * entries)
        ),
    ))
}

/// Bytes of the dense contact problem of a condensed strategy: the inverse block on the `k`
/// contact dofs, the compliance on its `m` components, and Newton's inverse and step matrices.
pub fn dense_contact(k: usize, m: usize) -> f64 {
    8.0 * ((k * k) as f64 + 3.0 * (m * m) as f64)
}

/// Bytes held once the blocks are assembled: the blocks and the lower triangle of `K` built
/// from them (values and row indices), the mesh and the vectors (a small share).
pub fn assembled(nnz_blocks: usize, n_nodes: usize, n_unknowns: usize) -> f64 {
    16.0 * 2.0 * nnz_blocks as f64 + 64.0 * n_nodes as f64 + 8.0 * 8.0 * n_unknowns as f64
}
