//! How far a factorisation has got, shared with another thread while it runs.

use std::sync::atomic::{AtomicU64, Ordering};

/// How far a factorisation has got, read from another thread while it runs: the
/// floating-point operations of the supernodes done against those of all (the tree's
/// `L D Lᵀ` reports them; a factorisation faer walks reports none). A run's progress bar reads
/// it.
#[derive(Debug, Default)]
pub struct FactorProgress {
    done: AtomicU64,
    total: AtomicU64,
}

impl FactorProgress {
    /// The fraction done, `None` before the factorisation reports its total.
    pub fn fraction(&self) -> Option<f64> {
        let total = self.total.load(Ordering::Relaxed);
        (total > 0).then(|| (self.done.load(Ordering::Relaxed) as f64 / total as f64).min(1.0))
    }

    /// A factorisation of the supernodes' `work` (operations each) begins.
    pub(crate) fn start(&self, work: &[f64]) {
        let total: u64 = work.iter().map(|&w| w as u64).sum();
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total.max(1), Ordering::Relaxed);
    }

    /// A supernode of `work` operations is done (all of them: the fraction is 1).
    pub(crate) fn add(&self, work: f64) {
        self.done.fetch_add(work as u64, Ordering::Relaxed);
    }
}
