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

    /// The sample at index `i` wrapped into the ring (`i & mask`), with no bounds check:
    /// a wrapped index is always inside.
    #[inline(always)]
    pub fn at(&self, i: usize) -> f64 {
        // SAFETY: `samples.len() == mask + 1` from `new` on (the length never changes: the
        // field is private and `DerefMut` lends a slice), and `i & mask <= mask`.
        unsafe { *self.samples.get_unchecked(i & self.mask) }
    }

    /// [`DelayLine::at`], to write.
    #[inline(always)]
    pub fn at_mut(&mut self, i: usize) -> &mut f64 {
        // SAFETY: as in `at`.
        unsafe { self.samples.get_unchecked_mut(i & self.mask) }
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

/// A string pulled aside into two straight lines meeting at a kink rounded over a
/// finger's width (a pluck), as the slopes `c y0'` (m/s) its travelling waves take, sample
/// by sample along the delay lines from the bridge.
#[derive(Debug, Clone, Copy)]
pub struct PluckShape {
    /// `c y0'` between the bridge and the kink, m/s.
    pub bridge_side: f64,
    /// `c y0'` between the kink and the nut, m/s.
    pub nut_side: f64,
    start: f64,
    end: f64,
    width: f64,
}

impl PluckShape {
    /// The shape of a string `length` samples long (one way), of which the delay lines
    /// hold `lines`, pulled aside by `scale` (the displacement times the rate, m/s) at
    /// `position_beta` of its length from the bridge, the kink rounded over `width` of it
    /// (at least a sample) and kept a sample inside the lines. `None` if the lines are too
    /// short for it.
    pub fn new(
        length: f64,
        lines: f64,
        position_beta: f64,
        width: f64,
        scale: f64,
    ) -> Option<Self> {
        let w = (width.clamp(0.0, 0.5) * length).max(1.0);
        let x0 = (position_beta * length).clamp(0.5 * w + 1.0, lines - 0.5 * w - 1.0);
        if !(x0 > 0.0 && x0 < lines && scale.is_finite()) {
            return None;
        }
        Some(Self {
            bridge_side: scale / x0,
            nut_side: -scale / (length - x0),
            start: x0 - 0.5 * w,
            end: x0 + 0.5 * w,
            width: w,
        })
    }

    /// The slope at sample `k` of the lines (its middle, `k + 0.5`), m/s.
    #[inline]
    pub fn slope(&self, k: usize) -> f64 {
        let x = k as f64 + 0.5;
        if x <= self.start {
            self.bridge_side
        } else if x >= self.end {
            self.nut_side
        } else {
            self.bridge_side + (self.nut_side - self.bridge_side) * (x - self.start) / self.width
        }
    }
}
