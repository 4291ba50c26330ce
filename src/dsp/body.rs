//! A generic instrument body: a few resonant modes driven by the bridge force, plus a
//! direct path. It colours the radiated sound only and feeds nothing back into the
//! strings, so it cannot make the loop gain energy. The mode data are generic (violin
//! signature modes A0, CBR, B1-, B1+ and a bridge hill, docs/parameters.md §2, scaled down for
//! the larger instruments), not measured.
//!
//! ```
//! use colophony::dsp::body::{BodyMode, BodyModes};
//! let modes = [BodyMode { freq_hz: 275.0, q: 12.0, gain: 0.8 }];
//! let mut body = BodyModes::new(&modes, 1.0, 48_000.0);
//! let impulse: Vec<f64> = (0..4800).map(|i| body.tick(if i == 0 { 1.0 } else { 0.0 })).collect();
//! assert!(impulse.iter().all(|x| x.is_finite()));
//! ```

use super::filters::Bandpass;

pub const MAX_BODY_MODES: usize = 6;

/// One body mode: centre frequency, quality factor, gain relative to the direct path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMode {
    pub freq_hz: f64,
    pub q: f64,
    pub gain: f64,
}

#[derive(Debug, Clone)]
pub struct BodyModes {
    filters: [Bandpass; MAX_BODY_MODES],
    gains: [f64; MAX_BODY_MODES],
    count: usize,
    direct_gain: f64,
}

impl BodyModes {
    /// Builds the body at `sample_rate_hz`; modes at or above 0.45 fs are dropped.
    pub fn new(modes: &[BodyMode], direct_gain: f64, sample_rate_hz: f64) -> Self {
        let mut body = Self {
            filters: [Bandpass::default(); MAX_BODY_MODES],
            gains: [0.0; MAX_BODY_MODES],
            count: 0,
            direct_gain,
        };
        for mode in modes.iter().take(MAX_BODY_MODES) {
            if mode.freq_hz < 0.45 * sample_rate_hz {
                body.filters[body.count] = Bandpass::new(mode.freq_hz, mode.q, sample_rate_hz);
                body.gains[body.count] = mode.gain;
                body.count += 1;
            }
        }
        body
    }

    #[inline]
    pub fn tick(&mut self, bridge_force_n: f64) -> f64 {
        let mut y = self.direct_gain * bridge_force_n;
        for (f, g) in self.filters[..self.count].iter_mut().zip(&self.gains) {
            y += g * f.tick(bridge_force_n);
        }
        y
    }

    pub fn reset(&mut self) {
        self.filters.iter_mut().for_each(Bandpass::reset);
    }

    /// Samples until every mode would ring out below `level` with no more input.
    pub fn samples_below(&self, level: f64) -> f64 {
        self.filters[..self.count]
            .iter()
            .map(|f| f.samples_below(level))
            .fold(0.0, f64::max)
    }

    /// Whether every mode has rung out below `level` (state magnitude, N-scale).
    pub fn is_quiet(&self, level: f64) -> bool {
        self.filters[..self.count]
            .iter()
            .all(|f| f.state_magnitude() < level)
    }
}
