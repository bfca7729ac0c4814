//! The capacitance matrix between a scene's terminals (the boundary groups at a prescribed
//! potential: its `[electrode]` and `dirichlet.phi` groups; groups that share a node are one
//! conductor, named `a+b`): `Q_i = Σ_j C_ij V_j`, `Q_i` the charge on terminal i (the negative
//! of the flux `∫ D·ν ds` out of the body through it), `V_j` the terminals' potentials.
//!
//! Column j is the charges of the state with terminal j at unit potential, every other
//! terminal at 0, the scene's prescribed displacements at 0 and no load: the small-signal
//! capacitance of the body as its mechanical conditions hold it (clamped where they clamp it,
//! free where it is free; the contact face free). One preparation of `K` by the backend serves
//! every column: a run over unit-potential instants (this module names no backend). Reciprocity (`C = Cᵀ`) and Gauss's law (each column's charges sum to 0 where the
//! terminals enclose every flux) are identities of the discrete problem, reported as checks.

use crate::backend::{Backend, InstantSolution, Limits, Loads, Posed};
use crate::progress::Silent;
use crate::run::terminal_groups;
use crate::scene::Scene;
use crate::setup::setup;
use crate::ProblemError;
use crate::SetupError;
use fe_assembly::{AssemblyError, Dof, DofMap};
use serde::{Deserialize, Serialize};

/// The capacitance matrix of a scene's terminals, in the scene's units (charge per unit
/// potential: nF in the scaled scenes' nF/m times m, per metre of depth in plane strain, the
/// whole body's on a body of revolution).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Capacitance {
    /// The terminals, in the order of the scene's conditions (groups joined by a node as one,
    /// `a+b`).
    pub terminals: Vec<String>,
    /// `matrix[i][j] = C_ij`.
    pub matrix: Vec<Vec<f64>>,
    /// `max |C_ij - C_ji| / max |C_ij|`: reciprocity, round-off.
    pub asymmetry: f64,
    /// `max_j |Σ_i C_ij| / max |C_ij|`: Gauss's law where the terminals take every flux (a
    /// charge may leave through a face with a surface charge or through the contact face of
    /// a conductive foundation, which the matrix leaves out).
    pub column_sum: f64,
    /// The unit of each `C_ij`: the scene's charge per its potential (`pC/kV`, a femtofarad,
    /// with lengths in µm and stresses in GPa; per unit thickness in plane strain).
    pub unit: String,
    /// What the set-up noted without refusing the scene, as a run says it (an electrode the
    /// mesh covers less of than its `x_range`, a region by box off the mesh's lines, ...).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// `scene` with each floating terminal (a `dirichlet.charge`, an `[[electrode]]`'s `charge`)
/// at a potential: in the capacitance matrix a floating terminal is a terminal like the
/// others, its potential a column's.
fn with_every_terminal_driven(scene: &Scene) -> Scene {
    let mut scene = scene.clone();
    for d in scene.dirichlet.iter_mut().filter(|d| d.charge.is_some()) {
        d.phi = Some(0.0);
        d.charge = None;
    }
    for e in scene
        .electrode
        .iter_mut()
        .flat_map(|e| e.all_mut())
        .filter(|e| e.charge.is_some())
    {
        e.v = Some(0.0);
        e.charge = None;
    }
    scene
}

/// The conductors of the terminal `groups` ([`conductors`]); refused where there are none, or
/// one: every flux that leaves one conductor enters it again, its capacitance is 0, and a
/// number computed for it is round-off.
fn terminal_conductors(
    setup: &crate::setup::Setup,
    groups: &[&str],
) -> Result<(Vec<usize>, Vec<String>), ProblemError> {
    if groups.is_empty() {
        let why = "the scene has no terminal (no [electrode], no dirichlet.phi)";
        return Err(SetupError::new("dirichlet", why).into());
    }
    let (conductor, names) = conductors(&setup.mesh, groups)?;
    if let [one] = &names[..] {
        let why = format!(
            "the scene has one terminal (`{one}`), and a capacitance is between two conductors at least: ground another group (dirichlet.phi) or add an [electrode]"
        );
        return Err(SetupError::new("dirichlet", why).into());
    }
    Ok((conductor, names))
}

/// The capacitance matrix of `scene` on `backend` (validated here; `mesh` the mesh of a
/// `gmsh` or `given` scene, read by the caller); `None` on a process that does not hold the
/// gathered solutions.
///
/// # Errors
/// The scene's and set-up's errors, as a run's; a scene without electric unknowns or without
/// a terminal (key `dirichlet`); a body its mechanical conditions do not hold; the backend's.
pub(crate) fn capacitance<B: Backend>(
    backend: &mut B,
    scene: &Scene,
    mesh: Option<mesh::Mesh>,
) -> Result<Option<Capacitance>, B::Error> {
    let scene = with_every_terminal_driven(scene);
    let valid = scene.validate().map_err(ProblemError::from)?;
    let setup = setup(valid, mesh)?;
    if !setup.plan.electric {
        let why = "the scene has no electric unknowns (no permittivity): no capacitance";
        return Err(ProblemError::from(SetupError::new("material", why)).into());
    }
    let groups = terminal_groups(&setup);
    let (conductor, names) = terminal_conductors(&setup, &groups)?;
    let mut disc = setup.discretize().map_err(ProblemError::from)?;
    disc.check_held()
        .map_err(|e| ProblemError::from(AssemblyError::from(e)))?;
    let mut member = vec![None; setup.mesh.n_nodes()];
    for (g, group) in groups.iter().enumerate() {
        for v in setup.mesh.boundary(group).map_err(ProblemError::from)?.nodes() {
            member[v] = Some(conductor[g]);
        }
    }
    let base = disc.dofs.clone();
    let n = names.len();
    let mut matrix = vec![vec![0.0; n]; n];
    let mut system = None;
    for j in 0..n {
        disc.dofs = unit_potential(&base, &member, j);
        let (b_u, b_phi) = disc.rhs(&[]).map_err(ProblemError::from)?;
        let posed = Posed {
            scene: valid,
            setup: &setup,
            disc: &disc,
            loads: Loads {
                b_u,
                b_phi,
                factors: None,
            },
            bed: None,
        };
        // one preparation for every column: the matrix does not change with the potentials
        if system.is_none() {
            let assembled = backend.assemble(&posed)?;
            let mut prepared = backend.prepare(&posed, assembled, None, Limits::default(), &mut Silent)?;
            backend.begin(&mut prepared, &posed, None, &[], &mut Silent)?;
            system = Some(prepared);
        }
        let Some(system) = system.as_mut() else { continue };
        let Some(InstantSolution { x: (u, phi), .. }) = backend.instant_fields(system, &posed, None, &mut Silent)?
        else {
            continue;
        };
        let (u, phi) = (disc.dofs.expand_u(&u), disc.dofs.expand_phi(&phi));
        // a node of several groups counts for the first: a conductor's charge is its groups'
        for (g, charge) in disc
            .charges(&u, &phi, &groups, &[])
            .map_err(ProblemError::from)?
            .into_iter()
            .enumerate()
        {
            matrix[conductor[g]][j] += charge;
        }
    }
    if let Some(system) = system {
        backend.finish(system)?;
    }
    let big = matrix
        .iter()
        .flatten()
        .fold(0.0f64, |m, c| m.max(c.abs()))
        .max(f64::MIN_POSITIVE);
    let asymmetry = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (matrix[i][j] - matrix[j][i]).abs())
        .fold(0.0, f64::max)
        / big;
    let column_sum = (0..n)
        .map(|j| (0..n).map(|i| matrix[i][j]).sum::<f64>().abs())
        .fold(0.0, f64::max)
        / big;
    Ok(Some(Capacitance {
        terminals: names,
        matrix,
        asymmetry,
        column_sum,
        unit: unit(&scene, setup.mesh.dim),
        notes: crate::progress::mesh_notes(&setup.notes),
    }))
}

/// The unit of a capacitance in `scene`'s system: its charge per its potential.
fn unit(scene: &Scene, dim: usize) -> String {
    let units = crate::Units::of(scene, dim);
    let (charge, potential) = (units.of_quantity("charge"), units.of_quantity("potential"));
    match charge.contains('/') {
        true => format!("({charge})/{potential}"),
        false => format!("{charge}/{potential}"),
    }
}

/// The dof map of column `j`: terminal `j` (the nodes whose `member` it is) at unit
/// potential, the other terminals and the prescribed displacements of `base` at 0.
fn unit_potential(base: &DofMap, member: &[Option<usize>], j: usize) -> DofMap {
    let mut dofs = base.clone();
    dofs.u.iter_mut().for_each(|d| {
        if let Dof::Fixed(v) = d {
            *v = 0.0;
        }
    });
    for (v, d) in dofs.phi.iter_mut().enumerate() {
        if let Dof::Fixed(x) = d {
            *x = if member[v] == Some(j) { 1.0 } else { 0.0 };
        }
    }
    dofs
}

/// The conductor of each group (groups that share a node joined, in the order of their first
/// group) and each conductor's name (its groups joined by `+`).
fn conductors(mesh: &mesh::Mesh, groups: &[&str]) -> Result<(Vec<usize>, Vec<String>), ProblemError> {
    // union-find over the groups, joined through their shared nodes
    let mut parent: Vec<usize> = (0..groups.len()).collect();
    fn root(parent: &mut [usize], mut g: usize) -> usize {
        while parent[g] != g {
            parent[g] = parent[parent[g]];
            g = parent[g];
        }
        g
    }
    let mut first = vec![usize::MAX; mesh.n_nodes()];
    for (g, group) in groups.iter().enumerate() {
        for v in mesh.boundary(group)?.nodes() {
            if first[v] == usize::MAX {
                first[v] = g;
            } else {
                let (a, b) = (root(&mut parent, first[v]), root(&mut parent, g));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let (mut conductor, mut names, mut index) = (
        vec![0; groups.len()],
        Vec::<String>::new(),
        vec![usize::MAX; groups.len()],
    );
    for g in 0..groups.len() {
        let r = root(&mut parent, g);
        if index[r] == usize::MAX {
            index[r] = names.len();
            names.push(groups[g].to_string());
        } else {
            names[index[r]] = format!("{}+{}", names[index[r]], groups[g]);
        }
        conductor[g] = index[r];
    }
    Ok((conductor, names))
}
