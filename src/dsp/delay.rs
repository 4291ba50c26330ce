//! The delay line both string models are built on (the point-bow waveguide,
//! [`super::waveguide`], and paper B's two-polarisation string, [`super::thermal`]): a ring
//! of a power-of-two length, so an index wraps with a mask, and the split of a loop into
//! two integer half-loops and the fractional rest a Thiran allpass tunes.
//!
//! ```
//! use colophony::dsp::delay::{split_loop, DelayLine};
//! let mut line = DelayLine::new(100);
//! assert_eq!(line.len(), 128);
//! // Written at t = 5, read three samples later.
//! line[5] = 1.0;
//! assert_eq!(line[line.back(8, 3)], 1.0);
//! // A loop of 201.3 samples: two half-loops of 100 and 1.3 samples for the allpass.
//! let (m, d) = split_loop(201.3);
//! assert_eq!(m, 100);
//! assert!((d - 1.3).abs() < 1e-9);
//! ```

use std::ops::{Deref, DerefMut};

/// A ring of samples of a power-of-two length: a wave written at time `t` (index
/// `t & mask`) is read `d` samples later at [`DelayLine::back`]`(t + d, d)`. Nothing moves
/// in memory. Dereferences to its samples, so slices of it are plain `&[f64]`.
#[derive(Debug, Clone)]
pub struct DelayLine {
    samples: Vec<f64>,
    mask: usize,
}

impl DelayLine {
    /// Zeros, at least `min_len` of them (rounded up to a power of two). Allocates.
    pub fn new(min_len: usize) -> Self {
        let len = min_len.max(1).next_power_of_two();
        Self {
            samples: vec![0.0; len],
            mask: len - 1,
        }
    }

    /// `len - 1`: `i & mask` wraps any index into the ring.
    #[inline(always)]
    pub fn mask(&self) -> usize {
        self.mask
    }

    /// The index `delay` samples before time `t`.
    #[inline(always)]
    pub fn back(&self, t: usize, delay: usize) -> usize {
        t.wrapping_sub(delay) & self.mask
    }
}

impl Deref for DelayLine {
    type Target = [f64];
    #[inline(always)]
    fn deref(&self) -> &[f64] {
        &self.samples
    }
}

impl DerefMut for DelayLine {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.samples
    }
}

/// Splits a loop of `remainder` samples (the round trip less what its filters delay) into
/// two half-loops of `m` samples and the rest `d = remainder - 2 m`, in `[0.5, 2.5)` when
/// `remainder >= 0.5`: the range where a first-order Thiran allpass is stable and flat.
/// `m` is never negative (a shorter loop leaves a larger `d`; the callers refuse it).
#[inline]
pub fn split_loop(remainder: f64) -> (usize, f64) {
    let m = ((remainder - 0.5) / 2.0).floor().max(0.0) as usize;
    (m, remainder - 2.0 * m as f64)
}
