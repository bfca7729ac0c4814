//! A run, read as the method: make the mesh, set up, assemble, factor, solve, recover, output.

use crate::build;
use crate::output::{self, Outputs};
use crate::scene::{Scene, Source};
use crate::DriverError;
use fe_assembly::{Discretization, Parallelism};
use linalg::{
    equilibrium_residual, CoupledSolver, DirectLdlt, Ordering, PcgParams, PcgStop, SchurPcg,
};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// The linear strategies, by name.
pub const LINEAR_STRATEGIES: &[(&str, &str)] = &[
    ("direct-ldlt", "one sparse L D Lᵀ of the quasi-definite K, one forward/back solve per step"),
    ("schur-pcg", "the paper's Algorithm 3: PCG on S = A + Gᵀ B⁻¹ G preconditioned by A (Cholesky of A and B)"),
];

/// What a run produced (also written as `run.json`).
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The run.json tree.
    pub report: serde_json::Value,
}

/// Bytes of peak resident memory of this process (VmHWM), 0 where unknown.
pub fn peak_memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|kb| kb.parse::<u64>().ok())
            })
        })
        .map_or(0, |kb| kb * 1024)
}

/// Runs a scene and writes its outputs into `out_dir` (atomically; nothing on error).
/// `progress` receives one line per stage or outer iteration.
pub fn run(
    scene: &Scene,
    source: &Source,
    out_dir: Option<&Path>,
    progress: &mut dyn FnMut(&str),
) -> Result<RunOutcome, DriverError> {
    let t_total = Instant::now();
    let t = Instant::now();
    let mesh = build::mesh(scene, source)?;
    let t_mesh = t.elapsed().as_secs_f64();
    let dim = mesh.dim;
    let mats = build::materials(scene, dim)?;
    let plan = build::plan(scene, dim, &mats);
    progress(&plan.to_string());
    if !LINEAR_STRATEGIES
        .iter()
        .any(|(n, _)| *n == plan.linear_strategy)
    {
        return Err(DriverError::Input(format!(
            "solver.strategy `{}` is unknown (see `piezocontact strategies`)",
            plan.linear_strategy
        )));
    }
    if plan.contact_law != "none" {
        return Err(DriverError::Input(format!(
            "contact.law = {} is not available in this build: run with --set contact.law=none",
            plan.contact_law
        )));
    }
    let mats = if plan.electric {
        mats
    } else {
        build::without_electric(mats)
    };
    let bcs = build::constraints(scene, &plan)?;
    let loads = build::loads(scene, dim)?;
    let t = Instant::now();
    let disc = Discretization::new(&mesh, &mats, &bcs)?;
    let blocks = disc.assemble(Parallelism::Rayon);
    let (b_u, b_phi) = disc.rhs(&loads)?;
    let t_assembly = t.elapsed().as_secs_f64();
    let (n_u, n_phi) = (disc.dofs.n_u, disc.dofs.n_phi);
    progress(&format!(
        "mesh: {} nodes, {} cells, h = {:.4e}; dofs: {n_u} u + {n_phi} phi; assembly {:.3} s",
        mesh.n_nodes(),
        mesh.n_cells(),
        mesh.h_max(),
        t_assembly
    ));
    let par = faer::Par::Seq;
    let t = Instant::now();
    let pcg_params = PcgParams {
        rel_tol: scene.solver.pcg_tol.unwrap_or(1e-12),
        max_iters: 10_000,
        stop: if plan.rule == "paper" {
            PcgStop::PaperRz
        } else {
            PcgStop::RelativeResidual
        },
        ..Default::default()
    };
    let mut solver: Box<dyn CoupledSolver> = match plan.linear_strategy.as_str() {
        "schur-pcg" => Box::new(SchurPcg::new(
            blocks.a.clone(),
            blocks.g.clone(),
            &blocks.b,
            pcg_params,
            par,
        )?),
        _ => Box::new(DirectLdlt::new(
            &blocks.a,
            &blocks.g,
            &blocks.b,
            &Ordering::Amd,
            par,
        )?),
    };
    let t_factor = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (mut u, mut phi) = (vec![0.0; n_u], vec![0.0; n_phi]);
    let info = solver.solve(&b_u, &b_phi, &mut u, &mut phi)?;
    let t_solve = t.elapsed().as_secs_f64();
    let eq = equilibrium_residual(&blocks.a, &blocks.g, &blocks.b, &u, &phi, &b_u, &b_phi);
    progress(&format!(
        "factorisation {:.3} s, solve {:.3} s ({} PCG iterations), equilibrium residual {:.3e}",
        t_factor, t_solve, info.pcg_iters, eq
    ));
    let un = disc.dofs.expand_u(&u);
    let pn = disc.dofs.expand_phi(&phi);
    let fields = disc.recover(&un, &pn);
    let report = json!({
        "scene": { "name": scene.name, "source": source.label, "description": scene.description, "settings": scene },
        "plan": plan,
        "mesh": { "n_nodes": mesh.n_nodes(), "n_cells": mesh.n_cells(), "h": mesh.h_max(), "cells_per_axis": build::cells_per_axis(scene) },
        "dofs": { "u": n_u, "phi": n_phi },
        "contact": { "n_points": 0, "n_stick": 0, "n_slip": 0, "n_separated": 0, "normal_force": 0.0, "tangential_force": 0.0 },
        "iterations": { "fixed_point": 0, "uzawa": 0, "pcg": info.pcg_iters },
        "residuals": { "equilibrium": eq, "complementarity": 0.0 },
        "timings_s": { "mesh": t_mesh, "assembly": t_assembly, "factorization": t_factor, "solve": t_solve, "contact": 0.0, "total": t_total.elapsed().as_secs_f64() },
        "memory": { "peak_bytes": peak_memory_bytes(), "factor_bytes": solver.factor_bytes() },
        "solver": { "strategy": plan.linear_strategy, "rule": plan.rule, "pcg_rel_tol": pcg_params.rel_tol },
    });
    if let Some(dir) = out_dir {
        let mut outs = Outputs::new(dir);
        outs.add(
            "run.json",
            serde_json::to_vec_pretty(&report).map_err(|e| DriverError::Output(e.to_string()))?,
        );
        outs.add("solution.vtu", output::vtu(&mesh, &un, &pn, &fields, None)?);
        outs.commit()?;
        progress(&format!(
            "wrote {} in {}",
            plan.outputs.join(", "),
            dir.display()
        ));
    }
    Ok(RunOutcome { report })
}
