//! A run, read as the method: make the mesh, set up, assemble, factor, solve, recover, output.

use crate::build;
use crate::contact_setup::{self, ContactBoundary};
use crate::output::{self, Outputs};
use crate::scene::{Scene, Source};
use crate::DriverError;
use contact::{ContactSolution, Law, NewtonParams, StopRule, UzawaParams};
use fe_assembly::{Discretization, Parallelism};
use linalg::{equilibrium_residual, CoupledSolver, DirectLdlt, Ordering, PcgParams, PcgStop, SchurPcg};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// The solver strategies, by name: how each contact iteration's primal problem is solved.
pub const STRATEGIES: &[(&str, &str)] = &[
    ("newton-condensed", "default: semismooth Newton (Alart-Curnier, Coulomb solved directly) on the contact compliance, read once off the L D Lᵀ of K (contact dofs last); one final full solve"),
    ("apg-condensed", "Nesterov-accelerated projected gradient (FISTA, adaptive restart, step 1/mu_max) on the same compliance"),
    ("uzawa-condensed", "Uzawa (r = 1.8/mu_max) on the same compliance"),
    ("uzawa-direct", "Uzawa with one full solve per iteration by the L D Lᵀ of K (factored once)"),
    ("uzawa-schur-pcg", "the paper's: Uzawa with one Schur-complement PCG solve per iteration (Algorithm 3, preconditioned by A)"),
];

/// What a run produced: the `run.json` tree and the solution.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The run.json tree.
    pub report: serde_json::Value,
    /// Node coordinates (`z = 0` in 2D).
    pub nodes: Vec<[f64; 3]>,
    /// Nodal displacements.
    pub u: Vec<[f64; 3]>,
    /// Nodal potentials.
    pub phi: Vec<f64>,
    /// The contact points and their solution, where the plan has contact.
    pub contact: Option<(contact::ContactPoints, ContactSolution)>,
}

/// Bytes of peak resident memory of this process (VmHWM), 0 where unknown.
pub fn peak_memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1).and_then(|kb| kb.parse::<u64>().ok()))
        })
        .map_or(0, |kb| kb * 1024)
}

/// Receives what a run reports: lines, and (for a progress bar) the fraction done of a long
/// stage.
pub trait Reporter {
    /// One line: a stage done, or an outer iteration.
    fn line(&mut self, text: &str);
    /// The fraction in `[0, 1]` of the current iterative stage (`stage` names it).
    fn fraction(&mut self, _stage: &str, _fraction: f64) {}
}

struct Lines<'a>(&'a mut dyn FnMut(&str));

impl Reporter for Lines<'_> {
    fn line(&mut self, text: &str) {
        (self.0)(text)
    }
}

/// Runs a scene and writes its outputs into `out_dir` (atomically; nothing on error).
/// `progress` receives one line per stage or outer iteration.
pub fn run(
    scene: &Scene,
    source: &Source,
    out_dir: Option<&Path>,
    progress: &mut dyn FnMut(&str),
) -> Result<RunOutcome, DriverError> {
    run_with_reporter(scene, source, out_dir, &mut Lines(progress))
}

/// As [`run`], reporting through a [`Reporter`] (the command line draws a progress bar).
pub fn run_with_reporter(
    scene: &Scene,
    source: &Source,
    out_dir: Option<&Path>,
    reporter: &mut dyn Reporter,
) -> Result<RunOutcome, DriverError> {
    // an unknown strategy is rejected before any mesh is built
    if !STRATEGIES.iter().any(|(n, _)| *n == scene.solver.strategy) {
        return Err(DriverError::Input(format!(
            "solver.strategy `{}` is unknown (see `piezocontact strategies`)",
            scene.solver.strategy
        )));
    }
    let t_total = Instant::now();
    let t = Instant::now();
    let build::Setup {
        mesh,
        materials: mats,
        plan,
        constraints: bcs,
        loads,
        exact,
    } = build::setup(scene, source)?;
    let t_setup = t.elapsed().as_secs_f64();
    let dim = mesh.dim;
    reporter.line(&plan.to_string());
    let t = Instant::now();
    let disc = Discretization::new(&mesh, &mats, &bcs)?;
    let blocks = disc.assemble(Parallelism::Rayon);
    let (b_u, b_phi) = disc.rhs(&loads)?;
    let t_assembly = t.elapsed().as_secs_f64();
    let (n_u, n_phi) = (disc.dofs.n_u, disc.dofs.n_phi);
    reporter.line(&format!(
        "mesh: {} nodes, {} cells, h = {:.4e}; dofs: {n_u} u + {n_phi} phi; assembly {:.3} s",
        mesh.n_nodes(),
        mesh.n_cells(),
        mesh.h_max(),
        t_assembly
    ));
    let par = faer::Par::Seq;
    let t = Instant::now();
    let pcg_params = PcgParams {
        rel_tol: scene
            .solver
            .pcg_tol
            .unwrap_or(if plan.rule == "paper" { 1e-2 } else { 1e-12 }),
        max_iters: 10_000,
        stop: if plan.rule == "paper" {
            PcgStop::PaperRz
        } else {
            PcgStop::RelativeResidual
        },
        ..Default::default()
    };
    let mut contact_boundary = match scene.contact.as_ref() {
        Some(c) if plan.contact_law != "none" => Some(contact_setup::boundary(&mesh, &disc.dofs, c)?),
        _ => None,
    };
    let schur = plan.linear_strategy == "uzawa-schur-pcg";
    let mut direct = None;
    let mut pcg_solver = None;
    if schur {
        pcg_solver = Some(SchurPcg::new(
            blocks.a.clone(),
            blocks.g.clone(),
            &blocks.b,
            pcg_params,
            par,
        )?);
    } else {
        // geometric nested dissection (measured no slower than AMD in 2D and 1.6x faster in
        // 3D, docs/performance.md); the condensed strategies put the contact dofs last, to read
        // the contact block off the factor
        let order = disc
            .dofs
            .expand_node_order(&mesh::nested_dissection(&mesh.points, &mesh.node_graph()));
        let ordering = match (&contact_boundary, condensed(&plan.linear_strategy)) {
            (Some(cb), true) => Ordering::GivenThenLast {
                order,
                last: cb.dofs.clone(),
            },
            _ => Ordering::Given(order),
        };
        direct = Some(DirectLdlt::new(&blocks.a, &blocks.g, &blocks.b, &ordering, par)?);
    }
    let t_factor = t.elapsed().as_secs_f64();
    reporter.line(&format!("factorisation {t_factor:.3} s"));
    let t = Instant::now();
    let (mut u, mut phi) = (vec![0.0; n_u], vec![0.0; n_phi]);
    let mut contact_result = None;
    let mut condense_seconds = 0.0;
    let mut condense_route: Option<String> = None;
    let pcg_total;
    if plan.contact_law == "none" {
        pcg_total = built(&mut direct, &mut pcg_solver)
            .solve(&b_u, &b_phi, &mut u, &mut phi)?
            .pcg_iters;
    } else {
        let c = scene.contact.as_ref().expect("a contact law implies a contact section");
        let cb = contact_boundary.take().expect("built with the plan");
        let n_points = cb.points.len();
        let law = match (plan.contact_law.as_str(), plan.friction) {
            (_, false) => Law::Frictionless,
            ("tresca", true) => Law::Tresca(vec![c.slip_bound; n_points]),
            _ => Law::Coulomb,
        };
        let nt = if plan.friction { dim - 1 } else { 0 };
        let params = UzawaParams {
            rule: if plan.rule == "paper" {
                StopRule::Paper
            } else {
                StopRule::Tight { tol: scene.solver.tol }
            },
            report_every: 50,
            accelerate: plan.linear_strategy == "apg-condensed",
            ..Default::default()
        };
        // the condensed strategy forms the contact compliance first
        let mut dense_problem = None;
        if let (Some(d), true) = (&mut direct, condensed(&plan.linear_strategy)) {
            let t_condense = Instant::now();
            let condensed = contact_setup::condense(&cb, d, &b_u, &b_phi, nt)?;
            condense_seconds = t_condense.elapsed().as_secs_f64();
            reporter.line(&format!(
                "condensed the contact compliance ({m} x {m}, {route:?}) in {condense_seconds:.3} s",
                m = condensed.problem.m(),
                route = condensed.route
            ));
            condense_route = Some(format!("{:?}", condensed.route));
            dense_problem = Some(condensed);
        }
        // a line per fixed-point step and per 500 Uzawa steps; the fraction done for a bar,
        // from the residual's way down (log scale) to the tolerance
        let tol = scene.solver.tol;
        let mut first_residual = None;
        let mut report = |p: &contact::Progress| {
            if p.stage == "uzawa" && p.residual > 0.0 {
                let r0 = *first_residual.get_or_insert(p.residual.max(tol * 10.0));
                let f = ((r0 / p.residual).ln() / (r0 / tol).ln()).clamp(0.0, 1.0);
                reporter.fraction("contact", f);
            }
            if p.stage == "newton" {
                reporter.fraction("contact", (p.residual.max(tol).ln() / tol.ln()).clamp(0.0, 1.0));
            }
            if p.stage != "uzawa" || p.iter % 500 == 0 {
                reporter.line(&format!(
                    "{:>11} {:>6}: residual {:.3e}, stick {}, slip {}, separated {}",
                    p.stage, p.iter, p.residual, p.counts.0, p.counts.1, p.counts.2
                ))
            }
        };
        let sol = match (&mut direct, &mut pcg_solver) {
            (Some(d), _) if dense_problem.is_some() => {
                let mut condensed = dense_problem.take().expect("condensed before the solve");
                let dense = &mut condensed.problem;
                let sol = if plan.linear_strategy == "newton-condensed" {
                    let newton = NewtonParams {
                        tol: scene.solver.tol,
                        ..Default::default()
                    };
                    contact::solve_newton(dense, &cb.points, &law, &newton, None, &mut report)?
                } else {
                    contact::solve(dense, &cb.points, &law, &params, None, &mut report)?
                };
                (u, phi) = contact_setup::recover(&cb, d, condensed, &sol.lambda, &b_u, &b_phi)?;
                sol
            }
            (direct, pcg) => {
                let solver = built(direct, pcg);
                let mut op = contact_setup::FullSolve {
                    boundary: &cb,
                    solver,
                    b_u: &b_u,
                    b_phi: &b_phi,
                    nt,
                    u: vec![0.0; n_u],
                    phi: vec![0.0; n_phi],
                };
                let sol = contact::solve(&mut op, &cb.points, &law, &params, None, &mut report)?;
                u = op.u;
                phi = op.phi;
                sol
            }
        };
        pcg_total = sol.info.inner_iters;
        contact_result = Some((cb, sol, law));
    }
    let t_solve = t.elapsed().as_secs_f64();
    // equilibrium of the final pair, with the contact forces in the right-hand side
    let mut b_full = b_u.clone();
    if let Some((cb, sol, _)) = &contact_result {
        cb.add_forces(&sol.lambda, &mut b_full);
    }
    let eq = equilibrium_residual(&blocks.a, &blocks.g, &blocks.b, &u, &phi, &b_full, &b_phi);
    reporter.line(&format!(
        "solve {t_solve:.3} s ({pcg_total} PCG iterations), equilibrium residual {eq:.3e}"
    ));
    let factor_bytes = direct
        .as_ref()
        .map(|d| d.factor_bytes())
        .or(pcg_solver.as_ref().map(|p| p.factor_bytes()))
        .unwrap_or(0);
    let un = disc.dofs.expand_u(&u);
    let pn = disc.dofs.expand_phi(&phi);
    let fields = disc.recover(&un, &pn);
    let contact_summary = contact_json(contact_result.as_ref());
    let exact_report = match (&exact, &contact_result, &scene.exact) {
        (Some(ex), _, Some(spec)) => Some(crate::exact::field_errors(
            &spec.kind,
            &disc,
            &un,
            &pn,
            ex,
            plan.electric,
        )),
        (None, Some((cb, sol, _)), Some(_)) => crate::exact::contact_errors(
            scene,
            &cb.points,
            sol,
            contact_summary["normal_force"].as_f64().unwrap_or(0.0),
            contact_summary["tangential_force"].as_f64().unwrap_or(0.0),
        ),
        _ => None,
    };
    if let Some(e) = &exact_report {
        reporter.line(&format!(
            "exact ({}): {} = {:.4e}",
            e["kind"].as_str().unwrap_or(""),
            e["error_name"].as_str().unwrap_or("error"),
            e["error"].as_f64().unwrap_or(f64::NAN)
        ));
    }
    let report = json!({
        "scene": { "name": scene.name, "source": source.label, "description": scene.description, "settings": scene },
        "plan": plan,
        "mesh": { "n_nodes": mesh.n_nodes(), "n_cells": mesh.n_cells(), "h": mesh.h_max(), "cells_per_axis": build::cells_per_axis(scene) },
        "dofs": { "u": n_u, "phi": n_phi },
        "contact": contact_summary,
        "exact": exact_report,
        "iterations": {
            "fixed_point": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.fixed_point_iters),
            "uzawa": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.uzawa_iters),
            "newton": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.newton_iters),
            "line_search_cuts": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.line_search_cuts),
            "newton_fallback": contact_result.as_ref().is_some_and(|(_, s, _)| s.info.fallback),
            "pcg": pcg_total,
            "primal_solves": contact_result.as_ref().map_or(1, |(_, s, _)| s.info.operator_calls),
            "pcg_in_step_estimate": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.estimate_inner_iters),
        },
        "residuals": {
            "equilibrium": eq,
            "complementarity": contact_result.as_ref().map_or(0.0, |(_, s, _)| s.info.complementarity),
            "converged_to_tolerance": plan.rule == "tight",
        },
        "timings_s": { "setup": t_setup, "assembly": t_assembly, "factorization": t_factor,
            "condense": condense_seconds, "contact": if contact_result.is_some() { t_solve } else { 0.0 }, "solve": t_solve, "total": t_total.elapsed().as_secs_f64() },
        "memory": { "peak_bytes": peak_memory_bytes(), "factor_bytes": factor_bytes },
        "solver": {
            "strategy": plan.linear_strategy,
            "rule": if plan.rule == "paper" { "paper (the loose rules of the paper's Table 1: relative change 1e-3, PCG (r,z) <= 1e-2 (r0,z0); not converged to a tolerance)" } else { "tight" },
            "tol": scene.solver.tol,
            "pcg_rel_tol": pcg_params.rel_tol,
            "step_r": contact_result.as_ref().map(|(_, s, _)| s.info.step),
            "mu_max": contact_result.as_ref().map(|(_, s, _)| s.info.mu_max),
            "step_backoffs": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.step_backoffs),
            "fixed_point_relaxations": contact_result.as_ref().map_or(0, |(_, s, _)| s.info.relaxations),
            "condense_route": condense_route,
            "smallest_pivot_ratio": direct.as_ref().map(|d| d.factor().pivot_ratio()),
        },
    });
    if let Some(dir) = out_dir {
        let mut outs = Outputs::new(dir);
        outs.add(
            "run.json",
            serde_json::to_vec_pretty(&report).map_err(|e| DriverError::Output(e.to_string()))?,
        );
        let status_field = contact_result.as_ref().map(|(cb, sol, _)| {
            let mut st = vec![0.0; mesh.n_nodes()];
            for (i, &node) in cb.nodes.iter().enumerate() {
                st[node] = match sol.status[i] {
                    contact::Status::Stick => 1.0,
                    contact::Status::Slip => 2.0,
                    contact::Status::Separated => 3.0,
                };
            }
            st
        });
        outs.add(
            "solution.vtu",
            output::vtu(&mesh, &un, &pn, &fields, status_field.as_deref())?,
        );
        if let Some((cb, sol, _)) = &contact_result {
            outs.add("contact.csv", output::contact_csv(&cb.points, sol));
        }
        let pics = crate::plots::pictures(
            &mesh,
            &un,
            &pn,
            contact_result.as_ref().map(|(cb, sol, _)| (&cb.points, sol)),
            plan.electric,
        )?;
        for (name, bytes) in pics {
            outs.add(&name, bytes);
        }
        outs.commit()?;
        reporter.line(&format!("wrote {} in {}", plan.outputs.join(", "), dir.display()));
    }
    Ok(RunOutcome {
        report,
        nodes: mesh.points.clone(),
        u: un,
        phi: pn,
        contact: contact_result.map(|(cb, sol, _)| (cb.points, sol)),
    })
}

/// Whether a strategy works on the condensed contact compliance.
fn condensed(strategy: &str) -> bool {
    strategy.ends_with("-condensed")
}

/// The linear solver the plan built: the `L D Lᵀ` of `K` or the Schur PCG.
fn built<'a>(direct: &'a mut Option<DirectLdlt>, pcg: &'a mut Option<SchurPcg>) -> &'a mut dyn CoupledSolver {
    match (direct, pcg) {
        (Some(d), _) => d,
        (None, Some(p)) => p,
        (None, None) => unreachable!("the run builds one linear solver before solving"),
    }
}

fn contact_json(result: Option<&(ContactBoundary, ContactSolution, Law)>) -> serde_json::Value {
    let Some((cb, sol, _)) = result else {
        return json!({ "n_points": 0, "n_stick": 0, "n_slip": 0, "n_separated": 0, "normal_force": 0.0, "tangential_force": 0.0 });
    };
    let p = &cb.points;
    let count = |s| sol.status.iter().filter(|&&x| x == s).count();
    let normal_force: f64 = p.weight.iter().zip(&sol.lambda.normal).map(|(w, l)| w * l).sum();
    let nt = sol.lambda.tangential.len().checked_div(p.len()).unwrap_or(0);
    let mut t = [0.0; 3];
    for i in 0..p.len() {
        for q in 0..nt {
            for k in 0..3 {
                t[k] += p.weight[i] * sol.lambda.tangential[i * nt + q] * p.tangent[i][q][k];
            }
        }
    }
    json!({
        "n_points": p.len(),
        "n_stick": count(contact::Status::Stick),
        "n_slip": count(contact::Status::Slip),
        "n_separated": count(contact::Status::Separated),
        "normal_force": normal_force,
        "tangential_force": (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt(),
        "max_lambda_n": sol.lambda.normal.iter().cloned().fold(0.0f64, f64::max),
    })
}
