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

/// Refuses a user's override (`--set KEY=VALUE`, `--set ~KEY`) of a value that `study` (a
/// sweep, a study) sets on each of its runs itself: `decided` pairs such keys with the option
/// that decides them. The study's own override comes last and would replace the user's
/// silently.
///
/// # Errors
/// A usage error naming both.
pub fn refuse_decided(study: &str, sets: &[String], decided: &[(&str, &str)]) -> Result<(), crate::DriverError> {
    for set in sets {
        if let Some((k, by)) = decided
            .iter()
            .find(|(k, _)| scene_file::keys_overlap(scene_file::override_key(set), k))
        {
            return Err(crate::DriverError::Usage(format!(
                "--set {set}: {study} sets {k} on each of its runs ({by}), which would replace this silently; drop the --set"
            )));
        }
    }
    Ok(())
}

/// The time left in a series of runs, estimated from the runs done: a pending run of size `n`
/// (cells per edge) takes the mean time of the done runs of its size, else the time of the
/// nearest done size scaled by `(n / m)^p`, `p` the growth measured between the two largest
/// sizes done (3 until two sizes are; kept within 1..7).
#[derive(Debug, Default)]
pub struct Eta {
    done: Vec<(usize, f64)>,
}

impl Eta {
    /// A run of size `n` took `seconds`.
    pub fn record(&mut self, n: usize, seconds: f64) {
        self.done.push((n, seconds));
    }

    /// The seconds the `pending` runs (their sizes) should take; `None` before any run is done.
    pub fn left(&self, pending: &[usize]) -> Option<f64> {
        if self.done.is_empty() {
            return None;
        }
        let mean = |n: usize| {
            let at: Vec<f64> = self.done.iter().filter(|d| d.0 == n).map(|d| d.1).collect();
            (!at.is_empty()).then(|| at.iter().sum::<f64>() / at.len() as f64)
        };
        let mut sizes: Vec<usize> = self.done.iter().map(|d| d.0).collect();
        sizes.sort_unstable();
        sizes.dedup();
        let power = match sizes[..] {
            [.., a, b] => match (mean(a), mean(b)) {
                (Some(ta), Some(tb)) if ta > 0.0 && tb > 0.0 => (tb / ta).ln() / (b as f64 / a as f64).ln(),
                _ => 3.0,
            },
            _ => 3.0,
        }
        .clamp(1.0, 7.0);
        Some(
            pending
                .iter()
                .map(|&n| {
                    mean(n).unwrap_or_else(|| {
                        let m = *sizes.iter().min_by_key(|&&m| m.abs_diff(n)).unwrap_or(&n);
                        mean(m).unwrap_or(0.0) * (n.max(1) as f64 / m.max(1) as f64).powf(power)
                    })
                })
                .sum(),
        )
    }

    /// `about 12 s left`, `about 3.5 min left`, `about 1.2 h left`; `none left` after the last
    /// run, and empty before the first.
    pub fn words(&self, pending: &[usize]) -> String {
        if pending.is_empty() {
            return "none left".into();
        }
        match self.left(pending) {
            None => String::new(),
            Some(s) if s < 90.0 => format!("about {s:.0} s left"),
            Some(s) if s < 5400.0 => format!("about {:.1} min left", s / 60.0),
            Some(s) => format!("about {:.1} h left", s / 3600.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Eta;

    /// The mean of a size for its pending runs; a new size by the growth measured between the
    /// two largest done (n² here: 1 s at 10, 4 s at 20, so 16 s at 40).
    #[test]
    fn the_time_left_follows_the_runs_done() {
        let mut eta = Eta::default();
        assert_eq!(eta.left(&[10]), None);
        eta.record(10, 1.0);
        assert_eq!(eta.left(&[10, 10]), Some(2.0));
        eta.record(20, 4.0);
        let left = eta.left(&[20, 40]).unwrap();
        assert!((left - 20.0).abs() < 1e-9, "{left}");
        assert_eq!(eta.words(&[20]), "about 4 s left");
        assert_eq!(eta.words(&[40; 10]), "about 2.7 min left");
        assert_eq!(eta.words(&[]), "none left");
    }
}
