//! A generic instrument body: a few resonant modes driven by the bridge force, plus a
//! direct path. It colours the radiated sound only and feeds nothing back into the
//! strings, so it cannot make the loop gain energy. The mode data are generic (violin
//! signature modes A0, CBR, B1-, B1+ and a bridge hill, docs/literature-values.md §2, scaled down for
//! the larger instruments), not measured.
//!
//! ```
//! use colophony::dsp::body::{BodyMode, BodyModes};
//! let modes = [BodyMode { freq_hz: 275.0, q: 12.0, gain: 0.8 }];
//! let mut body = BodyModes::new(&modes, 1.0, 48_000.0);
//! let impulse: Vec<f64> = (0..4800).map(|i| body.tick(if i == 0 { 1.0 } else { 0.0 })).collect();
//! assert!(impulse.iter().all(|x| x.is_finite()));
//! ```

use super::bridge::BridgeMode;
use super::filters::Bandpass;
use std::f64::consts::PI;

pub const MAX_BODY_MODES: usize = 6;

/// A mute's mass over the bridge's effective mass in its rocking mode (the bridge hill):
/// a 1.5 g rubber mute on a violin bridge whose rocking mode moves about 0.5 g (a
/// choice; the same ratio for the larger instruments, whose mutes and bridges grow
/// together).
pub const MUTE_MASS_RATIO: f64 = 3.0;
/// The bridge's own modes (the hill) start here, over the violin's frequencies (times
/// the instrument's body scale), Hz: the modes a mute loads.
pub const BRIDGE_MODES_FROM_HZ: f64 = 1500.0;

/// `modes` with a mute on the bridge (con sordino): each bridge mode (from
/// [`BRIDGE_MODES_FROM_HZ`] times `scale` up), a mass on a spring, carries the mute's
/// mass too, so its frequency falls by `sqrt(1 / (1 + r))` and its amplitude by
/// `1 / (1 + r)` (`r` = [`MUTE_MASS_RATIO`]); the body's own modes below are unchanged.
pub fn muted(mode: BodyMode, scale: f64) -> BodyMode {
    if mode.freq_hz < BRIDGE_MODES_FROM_HZ * scale {
        return mode;
    }
    let loaded = 1.0 + MUTE_MASS_RATIO;
    BodyMode {
        freq_hz: mode.freq_hz / loaded.sqrt(),
        q: mode.q,
        gain: mode.gain / loaded,
    }
}

/// [`muted`] for a mode of the thermal model's 2x2 bridge: the same mass on the same
/// modes, so their frequency and bandwidth fall by `sqrt(1 / (1 + r))` (the Q kept, as in
/// [`muted`]) and their gain by `1 / (1 + r)`.
pub fn muted_bridge_mode(mode: BridgeMode, scale: f64) -> BridgeMode {
    if mode.freq_hz < BRIDGE_MODES_FROM_HZ * scale {
        return mode;
    }
    let loaded = 1.0 + MUTE_MASS_RATIO;
    let mut gain = mode.gain;
    for row in &mut gain {
        for g in row {
            *g /= loaded;
        }
    }
    BridgeMode {
        freq_hz: mode.freq_hz / loaded.sqrt(),
        bandwidth_hz: mode.bandwidth_hz / loaded.sqrt(),
        gain,
    }
}

pub use super::vocabulary::BodyMode;

/// How long a body takes to move to a mute's modes and back, s: the old body fades out
/// as the new fades in, so the switch does not click (a player takes longer to slide a
/// mute on).
pub const MUTE_FADE_S: f64 = 0.05;

/// The modes `kind`'s body plays, and how many: `custom` (a fitted bridge's passive
/// reduction, [`body_from_bridge`]; at most [`MAX_BODY_MODES`] are kept) or the generic
/// ones, each loaded by a mute ([`muted`]) when `with_mute`.
pub fn body_modes_for(
    kind: super::vocabulary::InstrumentKind,
    custom: Option<&[BodyMode]>,
    with_mute: bool,
) -> ([BodyMode; MAX_BODY_MODES], usize) {
    let mut modes = [BodyMode {
        freq_hz: 0.0,
        q: 1.0,
        gain: 0.0,
    }; MAX_BODY_MODES];
    let generic = kind.body_modes();
    let chosen = custom.unwrap_or(&generic);
    let n = chosen.len().min(MAX_BODY_MODES);
    modes[..n].copy_from_slice(&chosen[..n]);
    if with_mute {
        let scale = kind.spec().body_scale;
        for mode in &mut modes[..n] {
            *mode = muted(*mode, scale);
        }
    }
    (modes, n)
}

/// A body that moves to new modes without a click: the new modes start from the old
/// ones' ringing state ([`BodyModes::retune`]) and the old body rings on as it fades out
/// over [`MUTE_FADE_S`] (linearly: the new from 0 to 1, the old from 1 to 0).
#[derive(Debug, Clone)]
pub struct FadingBody {
    /// The body now playing (without the fading one).
    pub playing: BodyModes,
    before: BodyModes,
    fade_left: u32,
    fade_total: f64,
}

impl FadingBody {
    pub fn new(body: BodyModes, sample_rate_hz: f64) -> Self {
        Self {
            before: body.clone(),
            playing: body,
            fade_left: 0,
            fade_total: (MUTE_FADE_S * sample_rate_hz).max(1.0),
        }
    }

    /// Moves to `body`'s modes, fading out the present ones over [`MUTE_FADE_S`].
    pub fn fade_to(&mut self, body: &BodyModes, sample_rate_hz: f64) {
        self.before = self.playing.clone();
        self.playing.retune(body);
        self.fade_left = (MUTE_FADE_S * sample_rate_hz).round() as u32;
        self.fade_total = (MUTE_FADE_S * sample_rate_hz).max(1.0);
    }

    /// Whether the old modes are still fading out.
    pub fn is_fading(&self) -> bool {
        self.fade_left > 0
    }

    /// One sample of the bridge force `x` through the body, and the fading one while it
    /// fades.
    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        if self.fade_left > 0 {
            let new = 1.0 - self.fade_left as f64 / self.fade_total;
            self.fade_left -= 1;
            new * self.playing.tick(x) + (1.0 - new) * self.before.tick(x)
        } else {
            self.playing.tick(x)
        }
    }

    /// Silences the body and ends a fade.
    pub fn reset(&mut self) {
        self.playing.reset();
        self.fade_left = 0;
    }
}

/// The modes as parallel band-pass biquads ([`Bandpass`]'s transposed direct form II),
/// stored lane by lane so that one sample's update of every mode is a few vector
/// operations. Unused lanes hold zero coefficients and stay at zero.
#[derive(Debug, Clone)]
pub struct BodyModes {
    b0: [f64; MAX_BODY_MODES],
    /// `-b0`, `-a1` and `-a2` of each mode's biquad (negation is exact, so the update
    /// gives the bits [`Bandpass::tick`] gives).
    neg_b0: [f64; MAX_BODY_MODES],
    neg_a1: [f64; MAX_BODY_MODES],
    a2: [f64; MAX_BODY_MODES],
    s1: [f64; MAX_BODY_MODES],
    s2: [f64; MAX_BODY_MODES],
    gains: [f64; MAX_BODY_MODES],
    count: usize,
    direct_gain: f64,
}

impl BodyModes {
    /// Builds the body at `sample_rate_hz`; modes at or above 0.45 fs are dropped.
    pub fn new(modes: &[BodyMode], direct_gain: f64, sample_rate_hz: f64) -> Self {
        let zero = [0.0; MAX_BODY_MODES];
        let mut body = Self {
            b0: zero,
            neg_b0: zero,
            neg_a1: zero,
            a2: zero,
            s1: zero,
            s2: zero,
            gains: zero,
            count: 0,
            direct_gain,
        };
        for mode in modes.iter().take(MAX_BODY_MODES) {
            if mode.freq_hz < 0.45 * sample_rate_hz {
                let (b0, a1, a2) =
                    Bandpass::new(mode.freq_hz, mode.q, sample_rate_hz).coefficients();
                let k = body.count;
                body.b0[k] = b0;
                body.neg_b0[k] = -b0;
                body.neg_a1[k] = -a1;
                body.a2[k] = a2;
                body.gains[k] = mode.gain;
                body.count += 1;
            }
        }
        body
    }

    #[inline]
    pub fn tick(&mut self, bridge_force_n: f64) -> f64 {
        let x = bridge_force_n;
        let mut out = [0.0; MAX_BODY_MODES];
        for k in 0..MAX_BODY_MODES {
            let y = self.b0[k] * x + self.s1[k];
            self.s1[k] = self.neg_a1[k] * y + self.s2[k];
            self.s2[k] = self.neg_b0[k] * x - self.a2[k] * y;
            out[k] = y;
        }
        // Summed in mode order, as the modes were added one by one.
        let mut y = self.direct_gain * x;
        for k in 0..self.count.min(MAX_BODY_MODES) {
            y += self.gains[k] * out[k];
        }
        y
    }

    /// Takes `other`'s modes and gains, keeping the ringing state: a mute put on or taken
    /// off moves the bridge's modes while they sound, and the output goes on from where it
    /// is (`y = b0 x + s1`: the state carries it) instead of restarting from rest, which
    /// clicks. Modes `other` does not have fall silent.
    pub fn retune(&mut self, other: &BodyModes) {
        let (s1, s2) = (self.s1, self.s2);
        *self = other.clone();
        for k in 0..self.count {
            self.s1[k] = s1[k];
            self.s2[k] = s2[k];
        }
    }

    pub fn reset(&mut self) {
        self.s1 = [0.0; MAX_BODY_MODES];
        self.s2 = [0.0; MAX_BODY_MODES];
    }

    /// Samples until every mode would ring out below `level` with no more input: each
    /// mode's poles have radius `sqrt(a2)`, so its state falls by that factor per sample
    /// (0 if already below).
    pub fn samples_below(&self, level: f64) -> f64 {
        (0..self.count)
            .map(|k| {
                let mag = self.state_magnitude(k);
                let r = self.a2[k].max(0.0).sqrt();
                if mag <= level || !(r > 0.0 && r < 1.0) {
                    0.0
                } else {
                    (level / mag).ln() / r.ln()
                }
            })
            .fold(0.0, f64::max)
    }

    /// Whether every mode has rung out below `level` (state magnitude, N-scale).
    pub fn is_quiet(&self, level: f64) -> bool {
        (0..self.count).all(|k| self.state_magnitude(k) < level)
    }

    fn state_magnitude(&self, k: usize) -> f64 {
        self.s1[k].abs().max(self.s2[k].abs())
    }
}

/// A fitted or measured bridge ([`crate::dsp::bridge_data`]) reduced to a body for the
/// point-bow instrument: a passive reduction of its admittance in the bowing direction.
///
/// The point-bow string moves in the bowing (horizontal) plane only, so the bridge it
/// drives is `Y_hh(s) = sum_m G_hh,m s / (s^2 + 2 pi b_m s + w_m^2)`. Each `G_hh,m` is a
/// diagonal entry of a positive semidefinite gain, so it is `>= 0` and each term is
/// positive real; any subset of the terms is positive real too, so keeping the
/// [`MAX_BODY_MODES`] terms with the largest peak admittance `G_hh / (2 pi b)` leaves a
/// passive admittance. Each kept mode becomes a unit-peak band-pass at `f_m` with
/// `Q = f_m / b_m`, its gain the mode's peak over the strongest's (so the strongest
/// mode's gain is 1, as in the generic bodies, and the loudness stays the instrument's);
/// the body's direct path stays 1. Modes with no horizontal part are dropped. Returns
/// the modes, strongest first, and the share of the summed peak admittance kept.
pub fn body_from_bridge(bridge: &[BridgeMode]) -> (Vec<BodyMode>, f64) {
    let mut peaks: Vec<(f64, &BridgeMode)> = bridge
        .iter()
        .filter(|m| m.freq_hz > 0.0 && m.bandwidth_hz > 0.0 && m.gain[0][0] > 0.0)
        .map(|m| (m.gain[0][0] / (2.0 * PI * m.bandwidth_hz), m))
        .filter(|(p, _)| p.is_finite())
        .collect();
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    let total: f64 = peaks.iter().map(|(p, _)| p).sum();
    peaks.truncate(MAX_BODY_MODES);
    let strongest = peaks.first().map_or(1.0, |(p, _)| *p);
    let kept: f64 = peaks.iter().map(|(p, _)| p).sum();
    let modes = peaks
        .iter()
        .map(|(p, m)| BodyMode {
            freq_hz: m.freq_hz,
            q: m.freq_hz / m.bandwidth_hz,
            gain: p / strongest,
        })
        .collect();
    (modes, if total > 0.0 { kept / total } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::vocabulary::InstrumentKind;

    /// A mute loads the bridge's modes only: the bridge hill's frequency falls by
    /// `sqrt(1 / (1 + r))` (half, for `r` = 3) and its amplitude by `1 / (1 + r)`; the
    /// body's modes below the bridge's, A0 and the B1 pair, are the same for every
    /// instrument.
    #[test]
    fn a_mute_loads_the_bridge_hill_and_leaves_the_body_modes() {
        for kind in InstrumentKind::ALL {
            let scale = kind.spec().body_scale;
            for mode in kind.body_modes() {
                let m = muted(mode, scale);
                if mode.freq_hz >= BRIDGE_MODES_FROM_HZ * scale {
                    // Exact ratios but for f64 rounding.
                    assert!((m.freq_hz / mode.freq_hz - 0.5).abs() < 1e-12);
                    assert!((m.gain / mode.gain - 0.25).abs() < 1e-12);
                } else {
                    assert_eq!(m, mode, "{kind:?}");
                }
            }
        }
    }
    use crate::dsp::bridge_data::shipped_bridge;

    #[test]
    fn a_bridge_reduces_to_its_strongest_horizontal_modes() {
        let mode = |f: f64, b: f64, hh: f64, vv: f64| BridgeMode {
            freq_hz: f,
            bandwidth_hz: b,
            gain: [[hh, 0.0], [0.0, vv]],
        };
        // Peaks G_hh / (2 pi b): 1/(2 pi) * [1, 0.5, 4, 0 (vertical only), 2, 3, 0.1, 5].
        let bridge = [
            mode(100.0, 1.0, 1.0, 1.0),
            mode(200.0, 2.0, 1.0, 0.0),
            mode(300.0, 1.0, 4.0, 0.0),
            mode(400.0, 1.0, 0.0, 9.0),
            mode(500.0, 1.0, 2.0, 0.0),
            mode(600.0, 1.0, 3.0, 0.0),
            mode(700.0, 10.0, 1.0, 0.0),
            mode(800.0, 1.0, 5.0, 0.0),
        ];
        let (modes, kept) = body_from_bridge(&bridge);
        let freqs: Vec<f64> = modes.iter().map(|m| m.freq_hz).collect();
        // The six largest horizontal peaks, strongest first; the vertical-only mode and
        // the weakest horizontal one (700 Hz) are dropped.
        assert_eq!(freqs, [800.0, 300.0, 600.0, 500.0, 100.0, 200.0]);
        for (m, want) in modes.iter().zip([1.0, 0.8, 0.6, 0.4, 0.2, 0.1]) {
            // Ratios of peaks: exact but for rounding.
            assert!(
                (m.gain - want).abs() < 1e-12,
                "{} Hz: {}",
                m.freq_hz,
                m.gain
            );
        }
        assert_eq!(modes[1].q, 300.0);
        assert_eq!(modes[5].q, 100.0);
        // Kept: 15.5 of 15.6.
        // A ratio of sums of the peaks above: f64 rounding only.
        assert!((kept - 15.5 / 15.6).abs() < 1e-12, "{kept}");
    }

    #[test]
    fn the_shipped_bridges_reduce_to_stable_bodies_that_keep_most_of_their_admittance() {
        for bridge in [
            shipped_bridge(InstrumentKind::Cello),
            shipped_bridge(InstrumentKind::Viola),
            shipped_bridge(InstrumentKind::Violin),
        ] {
            let (modes, kept) = body_from_bridge(&bridge.modes);
            println!(
                "{} modes -> {}: {:.1} % of the summed peak kept",
                bridge.modes.len(),
                modes.len(),
                100.0 * kept
            );
            assert_eq!(modes.len(), MAX_BODY_MODES);
            assert!(modes
                .iter()
                .all(|m| m.q > 0.0 && m.gain > 0.0 && m.gain <= 1.0));
            // Six of fourteen modes: the strong ones carry most of the peak admittance.
            assert!(kept > 0.5 && kept <= 1.0, "{kept}");
            let mut body = BodyModes::new(&modes, 1.0, 48_000.0);
            let y: Vec<f64> = (0..48_000)
                .map(|i| body.tick(if i == 0 { 1.0 } else { 0.0 }))
                .collect();
            assert!(y.iter().all(|v| v.is_finite()));
            // Rings down: the last 10 ms far below the first. 1e-3 is 60 dB under the
            // impulse's first sample (about 1.03), T60's level; measured 2.5e-12 at most
            // (the cello: its slowest mode, 218 Hz at Q 35, falls 170 dB a second).
            let tail = y[47_520..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(tail < 1e-3, "{tail}");
        }
    }
}
