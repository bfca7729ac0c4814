//! What a run produced: the report, the mesh, the nodal solution, the per-cell fields and the
//! contact solution; whichever backend solved it, at one instant or the last of a path.

use crate::report::RunReport;
use contact::{ContactPoints, ContactSolution, PointValues};
use fe_assembly::CellFields;

/// What a run produced: its report, the mesh, the nodal solution, the per-cell fields, and the
/// contact solution where the plan has contact.
pub struct Solution {
    /// What `run.json` holds.
    pub report: RunReport,
    /// The mesh (with the scene's regions and electrode group).
    pub mesh: mesh::Mesh,
    /// Nodal displacements (`z = 0` in 2D).
    pub u: Vec<[f64; 3]>,
    /// Nodal potentials (0 where a node has no electric unknown).
    pub phi: Vec<f64>,
    /// Per-cell stress, strain, electric displacement and field.
    pub fields: CellFields,
    /// The contact points and their solution.
    pub contact: Option<ContactResult>,
}

/// The contact solution on its points.
pub struct ContactResult {
    /// The contact points.
    pub points: ContactPoints,
    /// The mesh node of each point.
    pub nodes: Vec<usize>,
    /// Multipliers, displacements and status, as the contact solver returned them (without
    /// friction, the displacements have no tangential part).
    pub solution: ContactSolution,
    /// `u_n` and all `dim - 1` components of `u_t` of the final displacement, whatever the law
    /// (a frictionless body slides too).
    pub displacement: PointValues,
    /// The contact groups, in the scene's order.
    pub groups: Vec<String>,
    /// The group of each point (an index into `groups`).
    pub group_of: Vec<usize>,
}
