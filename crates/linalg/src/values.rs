//! A large factor's values in memory advised to use transparent huge pages.
//!
//! The first touch of a fresh factor's values faults its pages in: at 4 KB pages that is one
//! fault per 512 values, 147 000 for a 576 MB factor (what `paper` at n = 256 held when this
//! was measured), 0.36 s on this project's machine; at 2 MB pages, 0.05 s, and the dense
//! kernels of a 3D factor miss the TLB less. Where the kernel offers transparent huge pages on
//! request (`/sys/kernel/mm/transparent_hugepage/enabled` = `madvise`, as on that machine) an
//! anonymous mapping so advised gets them; where it does not (or the advice is refused, or not
//! Linux), the mapping behaves as any zeroed memory. Small factors keep a `Vec`.
//!
//! The mapping's pages are faulted in at once on all of rayon's threads, one write per page,
//! rather than one by one by the factorisation: the kernel's work per fault (zeroing a page,
//! finding a huge one) then runs on all cores. Measured on `paper` at n = 256 (541 MB of
//! values), two threads, first factorisations in fresh processes: analysis, factorisation and
//! solve 1.45 s without, 1.32 s with (medians of 6); the touch alone took 0.07-0.67 s on one
//! thread (the kernel's huge pages come fast or slow), 0.035-0.32 s on two. On one thread it
//! was left to the factorisation while that was faer's walk (nothing measurable to gain
//! then); the tree's walk, on one thread too since, touches its pages supernode by supernode,
//! and at `paper-3d` n = 24 (1.6 GB of values) the first factorisation took 1.4-2.9 s longer
//! than a refactorisation without the touch, 0-0.45 s with it (8 fresh processes each, one
//! thread, this VM; the 2D floor: no difference within the noise).

use memmap2::{MmapMut, MmapOptions};
use rayon::prelude::*;

/// Values from which a factor's storage is mapped and advised (64 MB: 32 huge pages).
const MAPPED_FROM: usize = 8 << 20;

/// Zero-initialised `f64` storage of a fixed length.
pub(crate) enum Values {
    /// A `Vec`, for small factors.
    Heap(Vec<f64>),
    /// An anonymous mapping (page-aligned, zeroed by the kernel) of `len` values.
    Mapped { map: MmapMut, len: usize },
}

impl Values {
    /// `len` zeros.
    pub(crate) fn zeros(len: usize) -> Values {
        if len >= MAPPED_FROM {
            if let Ok(mut map) = MmapOptions::new().len(len * std::mem::size_of::<f64>()).map_anon() {
                #[cfg(target_os = "linux")]
                {
                    // a hint: refused or unavailable, the pages are small ones
                    let _ = map.advise(memmap2::Advice::HugePage);
                }
                fault_in(&mut map);
                return Values::Mapped { map, len };
            }
        }
        Values::Heap(vec![0.0; len])
    }
}

/// Writes a zero at the start of every 4 KB page of `map` (already zero: the values do not
/// change), a huge page's worth of them per rayon task.
fn fault_in(map: &mut [u8]) {
    const PAGE: usize = 4096;
    const HUGE_PAGE: usize = 2 << 20;
    map.par_chunks_mut(HUGE_PAGE).for_each(|chunk| {
        for i in (0..chunk.len()).step_by(PAGE) {
            chunk[i] = 0;
        }
    });
}

impl std::ops::Deref for Values {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        match self {
            Values::Heap(v) => v,
            Values::Mapped { map, len } => &bytemuck::cast_slice(&map[..])[..*len],
        }
    }
}

impl std::ops::DerefMut for Values {
    fn deref_mut(&mut self) -> &mut [f64] {
        match self {
            Values::Heap(v) => v,
            Values::Mapped { map, len } => &mut bytemuck::cast_slice_mut(&mut map[..])[..*len],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_storage_is_zeros_of_its_length_mapped_or_not() {
        for len in [0, 1, 1000, MAPPED_FROM, MAPPED_FROM + 3] {
            let mut v = Values::zeros(len);
            assert_eq!(v.len(), len);
            assert!(matches!(v, Values::Mapped { .. }) == (len >= MAPPED_FROM));
            assert!(v.iter().all(|&x| x == 0.0));
            if len > 0 {
                v[len - 1] = 2.5;
                v[0] += 1.0;
                let first: f64 = if len == 1 { 3.5 } else { 1.0 };
                assert_eq!((v[0], v[len - 1]), (first, first.max(2.5)));
            }
        }
    }
}
