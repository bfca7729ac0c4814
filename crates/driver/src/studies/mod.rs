//! The studies over many runs, each building its own table and series: a scene along one
//! parameter ([`sweep`]), the paper's Table 1 ([`table1`]), error against h and run time
//! ([`convergence`]), the verification report ([`verification`]), the stiff and extreme
//! cases ([`stability`]), the hostile inputs ([`inputs`]) and the sphere's friction loop
//! against its closed form ([`loops`]).

pub mod child;
pub mod convergence;
pub mod inputs;
pub mod loops;
pub mod stability;
pub mod sweep;
pub mod table1;
pub mod verification;

use files::scene_file;
use problem::{Silent, Solution};

/// Solves a shipped scene or scene file with overrides, silently, writing nothing.
///
/// # Errors
/// The scene's or the run's error.
pub fn solve(scene: &str, sets: &[String]) -> Result<Solution, files::Error> {
    let (scene, source) = scene_file::load(scene, sets)?;
    files::run::solve(&scene, &source, &mut Silent)
}
