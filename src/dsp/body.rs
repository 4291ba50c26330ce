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

/// A mute's mass over the bridge's effective mass in its rocking mode (the bridge hill).
/// Chosen from SHARC's violin played open and muted (docs/articulations.md, "Measured
/// mute"): through [`Biquad::mute_load`], 1 puts the violin's loss over 2.5-5 kHz within 2 dB of
/// the recording's band by band (1.5, 2 and 3 deeper than it by 1-3, 3-5 and 6-9 dB); the
/// same ratio for the larger instruments, whose mutes and bridges grow together.
pub const MUTE_MASS_RATIO: f64 = 1.0;
/// The bridge's own modes (the hill) start here, over the violin's frequencies (times
/// the instrument's body scale), Hz: the modes of paper B's fitted bridges a mute loads
/// ([`muted_bridge_mode`]).
pub const BRIDGE_MODES_FROM_HZ: f64 = 1500.0;

/// A biquad in transposed direct form II, `H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1
/// + a2 z^-2)`: a mute's load on the bridge ([`Biquad::mute_load`]) and the sections of a
/// body's fall above its bridge ([`TopFall`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
    s: [f64; 2],
}

impl Biquad {
    /// Passes its input unchanged.
    const PASS: Self = Self {
        b: [1.0, 0.0, 0.0],
        a: [0.0, 0.0],
        s: [0.0; 2],
    };

    /// A mute on the bridge: a filter on the force the bridge passes to the body.
    ///
    /// The bridge hill is the bridge rocking on its feet: its top, where the strings press
    /// (mass `m`), on a spring `k` (its waist) into the body's resistance `c` at its feet
    /// (Woodhouse's bridge-hill model, reduced to one degree of freedom; docs/articulations.md).
    /// The force it passes to the body is then `w_b^2 / (s^2 + B s + w_b^2)`, with
    /// `w_b^2 = k / m` and `B = k / c`. A mute of mass `r m` clamped on the top lowers the
    /// resonance to `w_m = w_b / sqrt(1 + r)` and keeps `B`. The generic body already holds the
    /// open bridge's hill (its last mode, [`InstrumentKind::bridge_hill`]), so the mute
    /// multiplies what it radiates by the loaded transmission over the open one:
    /// `R(s) = (w_m^2 / w_b^2) (s^2 + B s + w_b^2) / (s^2 + B s + w_m^2)`: unity at DC,
    /// `1 / (1 + r)` far above the hill and deepest near it. Bilinear, each resonance
    /// pre-warped, so the digital filter keeps unity at DC and both resonances where they are.
    ///
    /// The mute `mass_ratio` times the bridge's effective mass on the bridge `hill`, at
    /// `sample_rate_hz`. Resonances at or above 0.45 of the rate are taken there (the
    /// filter then passes everything unchanged if both are).
    ///
    /// [`InstrumentKind::bridge_hill`]: super::vocabulary::InstrumentKind::bridge_hill
    pub fn mute_load(hill: BodyMode, mass_ratio: f64, sample_rate_hz: f64) -> Self {
        let k = 2.0 * sample_rate_hz;
        let warp = |f: f64| k * (PI * (f / sample_rate_hz).min(0.45)).tan();
        let w_b = warp(hill.freq_hz);
        let w_m = warp(hill.freq_hz / (1.0 + mass_ratio.max(0.0)).sqrt());
        let bandwidth = w_b / hill.q;
        let poly = |w: f64| {
            [
                k * k + bandwidth * k + w * w,
                2.0 * (w * w - k * k),
                k * k - bandwidth * k + w * w,
            ]
        };
        let (n, d) = (poly(w_b), poly(w_m));
        let g = (w_m * w_m) / (w_b * w_b) / d[0];
        Self {
            b: [g * n[0], g * n[1], g * n[2]],
            a: [d[1] / d[0], d[2] / d[0]],
            s: [0.0; 2],
        }
    }

    /// A second-order low-pass at `corner_hz` of quality `q` (RBJ's cookbook: bilinear,
    /// the corner pre-warped), at `sample_rate_hz`; below 0.45 of the rate.
    fn low_pass(corner_hz: f64, q: f64, sample_rate_hz: f64) -> Self {
        let (sin, cos) = (2.0 * PI * (corner_hz / sample_rate_hz)).sin_cos();
        let alpha = sin / (2.0 * q);
        let a0 = 1.0 + alpha;
        let b1 = (1.0 - cos) / a0;
        Self {
            b: [b1 / 2.0, b1, b1 / 2.0],
            a: [-2.0 * cos / a0, (1.0 - alpha) / a0],
            s: [0.0; 2],
        }
    }

    /// The filter's magnitude at `freq_hz` (its digital frequency response).
    #[cfg(test)]
    fn gain_at(&self, freq_hz: f64, sample_rate_hz: f64) -> f64 {
        let w = 2.0 * PI * freq_hz / sample_rate_hz;
        let z1 = (w.cos(), -w.sin());
        let z2 = ((2.0 * w).cos(), -(2.0 * w).sin());
        let num = (
            self.b[0] + self.b[1] * z1.0 + self.b[2] * z2.0,
            self.b[1] * z1.1 + self.b[2] * z2.1,
        );
        let den = (
            1.0 + self.a[0] * z1.0 + self.a[1] * z2.0,
            self.a[0] * z1.1 + self.a[1] * z2.1,
        );
        num.0.hypot(num.1) / den.0.hypot(den.1)
    }

    /// Transposed direct form II.
    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        let y = self.b[0] * x + self.s[0];
        self.s[0] = self.b[1] * x - self.a[0] * y + self.s[1];
        self.s[1] = self.b[2] * x - self.a[1] * y;
        y
    }

    fn state_magnitude(&self) -> f64 {
        self.s[0].abs().max(self.s[1].abs())
    }
}

/// The fall of a body's radiation above its bridge's resonances: a fourth-order
/// Butterworth low-pass (two sections, bilinear, the corner pre-warped) after the modes.
/// Its corner is each instrument's [`InstrumentSpec::top_fall_hz`], measured
/// (docs/timbre.md, "The bodies' fall above 3 kHz"). A corner at or above 0.45 of the
/// rate passes everything unchanged.
///
/// [`InstrumentSpec::top_fall_hz`]: super::vocabulary::InstrumentSpec::top_fall_hz
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TopFall {
    sections: [Biquad; 2],
}

impl TopFall {
    pub fn new(corner_hz: f64, sample_rate_hz: f64) -> Self {
        if corner_hz >= 0.45 * sample_rate_hz {
            return Self {
                sections: [Biquad::PASS; 2],
            };
        }
        // Butterworth's pole angles, pi/8 and 3 pi/8 from the imaginary axis.
        let sections = [1.0, 3.0]
            .map(|k: f64| Biquad::low_pass(corner_hz, 0.5 / (k * PI / 8.0).sin(), sample_rate_hz));
        Self { sections }
    }

    /// The filter's magnitude at `freq_hz` (its digital frequency response).
    #[cfg(test)]
    fn gain_at(&self, freq_hz: f64, sample_rate_hz: f64) -> f64 {
        self.sections
            .iter()
            .map(|s| s.gain_at(freq_hz, sample_rate_hz))
            .product()
    }

    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        let y = self.sections[0].tick(x);
        self.sections[1].tick(y)
    }

    fn state_magnitude(&self) -> f64 {
        self.sections[0]
            .state_magnitude()
            .max(self.sections[1].state_magnitude())
    }

    fn reset(&mut self) {
        for s in &mut self.sections {
            s.s = [0.0; 2];
        }
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

/// The body `kind` plays at `sample_rate_hz`: its `custom` modes (a fitted bridge's
/// passive reduction, [`body_from_bridge`]; at most [`MAX_BODY_MODES`] are kept) or the
/// generic ones, with a mute on the bridge ([`Biquad::mute_load`], on the instrument's bridge hill)
/// when `with_mute`.
pub fn body_for(
    kind: super::vocabulary::InstrumentKind,
    custom: Option<&[BodyMode]>,
    with_mute: bool,
    sample_rate_hz: f64,
) -> BodyModes {
    let generic = kind.body_modes();
    let mut body = BodyModes::new(custom.unwrap_or(&generic), 1.0, sample_rate_hz);
    body.top = kind
        .spec()
        .top_fall_hz
        .map(|corner| TopFall::new(corner, sample_rate_hz));
    if with_mute {
        body.mute = Some(Biquad::mute_load(
            kind.bridge_hill(),
            MUTE_MASS_RATIO,
            sample_rate_hz,
        ));
    }
    body
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
    /// A mute on the bridge, filtering the body's output ([`body_for`]).
    mute: Option<Biquad>,
    /// The fall above the bridge's resonances, after the mute ([`body_for`]).
    top: Option<TopFall>,
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
            mute: None,
            top: None,
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
        self.tick_inline(bridge_force_n)
    }

    /// [`BodyModes::tick`] inlined where it is called (a block's loop over the body).
    #[inline(always)]
    pub fn tick_inline(&mut self, bridge_force_n: f64) -> f64 {
        let x = bridge_force_n;
        let mut out = [0.0; MAX_BODY_MODES];
        for k in 0..MAX_BODY_MODES {
            let y = self.b0[k] * x + self.s1[k];
            self.s1[k] = self.neg_a1[k] * y + self.s2[k];
            self.s2[k] = self.neg_b0[k] * x - self.a2[k] * y;
            out[k] = y;
        }
        // Summed in mode order, as the modes were added one by one. Every lane is added:
        // an unused one adds `0 * 0 = +0`, which leaves any sum but a negative zero as it
        // is, and needs no test of the mode count per lane.
        let mut y = self.direct_gain * x;
        for k in 0..MAX_BODY_MODES {
            y += self.gains[k] * out[k];
        }
        let y = match &mut self.mute {
            Some(mute) => mute.tick(y),
            None => y,
        };
        match &mut self.top {
            Some(top) => top.tick(y),
            None => y,
        }
    }

    /// Takes `other`'s modes and gains, keeping the ringing state: a mute put on or taken
    /// off moves the bridge's modes while they sound, and the output goes on from where it
    /// is (`y = b0 x + s1`: the state carries it) instead of restarting from rest, which
    /// clicks. Modes `other` does not have fall silent.
    pub fn retune(&mut self, other: &BodyModes) {
        let (s1, s2, mute, top) = (self.s1, self.s2, self.mute, self.top);
        *self = other.clone();
        for k in 0..self.count {
            self.s1[k] = s1[k];
            self.s2[k] = s2[k];
        }
        if let (Some(new), Some(old)) = (&mut self.mute, mute) {
            new.s = old.s;
        }
        if let (Some(new), Some(old)) = (&mut self.top, top) {
            new.sections = [0, 1].map(|k| Biquad {
                s: old.sections[k].s,
                ..new.sections[k]
            });
        }
    }

    pub fn reset(&mut self) {
        self.s1 = [0.0; MAX_BODY_MODES];
        self.s2 = [0.0; MAX_BODY_MODES];
        if let Some(mute) = &mut self.mute {
            mute.s = [0.0; 2];
        }
        if let Some(top) = &mut self.top {
            top.reset();
        }
    }

    /// Samples until every mode (and a mute's filter) would ring out below `level` with
    /// no more input: each one's poles have radius `sqrt(a2)`, so its state falls by that
    /// factor per sample (0 if already below).
    pub fn samples_below(&self, level: f64) -> f64 {
        let below = |mag: f64, a2: f64| {
            let r = a2.max(0.0).sqrt();
            if mag <= level || !(r > 0.0 && r < 1.0) {
                0.0
            } else {
                (level / mag).ln() / r.ln()
            }
        };
        let mute = self
            .mute
            .map_or(0.0, |m| below(m.state_magnitude(), m.a[1]));
        let mute = self.top.map_or(mute, |t| {
            t.sections
                .iter()
                .map(|s| below(s.state_magnitude(), s.a[1]))
                .fold(mute, f64::max)
        });
        (0..self.count)
            .map(|k| below(self.state_magnitude(k), self.a2[k]))
            .fold(mute, f64::max)
    }

    /// Whether every mode has rung out below `level` (state magnitude, N-scale).
    pub fn is_quiet(&self, level: f64) -> bool {
        (0..self.count).all(|k| self.state_magnitude(k) < level)
            && self.mute.is_none_or(|m| m.state_magnitude() < level)
            && self.top.is_none_or(|t| t.state_magnitude() < level)
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

    /// A mute on the bridge is the loaded bridge's transmission over the open one
    /// (`R(s)` of [`Biquad::mute_load`], written out here from the bridge-hill model): unity at
    /// low frequencies, `1 / (1 + r)` far above the hill and deepest near it, on every
    /// instrument and at 44.1-192 kHz; the body's modes below are the open body's.
    #[test]
    fn a_mute_lowers_the_bridge_hill_as_a_mass_on_its_spring() {
        let r = MUTE_MASS_RATIO;
        // The analogue loaded-over-open transmission at `f` for the hill `(f_b, q)`.
        let analogue = |f: f64, f_b: f64, q: f64| {
            let x = f / f_b;
            let num = (1.0 - x * x).hypot(x / q);
            let den = (1.0 / (1.0 + r) - x * x).hypot(x / q);
            num / den / (1.0 + r)
        };
        let db = |g: f64| 20.0 * g.log10();
        for kind in InstrumentKind::ALL {
            let hill = kind.bridge_hill();
            for fs in [44_100.0, 48_000.0, 96_000.0, 192_000.0] {
                let mute = Biquad::mute_load(hill, r, fs);
                // Unity at 10 Hz: the bridge is rigid far below its hill. 0.01 dB: the
                // loaded resonance's own rise, `(f / f_m)^2` of it, is 1e-3 dB there.
                let low = db(mute.gain_at(10.0, fs));
                assert!(low.abs() < 0.01, "{kind:?} {fs}: {low}");
                // The digital filter follows the analogue one: within 0.3 dB up to three
                // times the hill, the bilinear transform's frequency warping (both
                // resonances pre-warped) at 44.1 kHz.
                for x in [0.25, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0] {
                    let f = x * hill.freq_hz;
                    let got = db(mute.gain_at(f, fs));
                    let want = db(analogue(f, hill.freq_hz, hill.q));
                    assert!(
                        (got - want).abs() < 0.3,
                        "{kind:?} {fs} Hz, {f:.0} Hz: {got:.2} dB against {want:.2}"
                    );
                }
                // The hill itself loses more than the far top keeps: deepest near it.
                let at_hill = db(mute.gain_at(hill.freq_hz, fs));
                let top = db(analogue(1e6, hill.freq_hz, hill.q));
                assert!((top + 10.0 * (1.0 + r).log10() * 2.0).abs() < 0.01, "{top}");
                assert!(
                    at_hill < top - 3.0,
                    "{kind:?} {fs}: {at_hill} against {top}"
                );
                // Stable: the poles' radius below one.
                assert!(mute.a[1] > 0.0 && mute.a[1] < 1.0);
            }
            // The body's modes are the open body's; only the mute's filter is added.
            let open = body_for(kind, None, false, 48_000.0);
            let muted = body_for(kind, None, true, 48_000.0);
            assert_eq!(open.b0, muted.b0);
            assert_eq!(open.gains, muted.gains);
            assert!(open.mute.is_none() && muted.mute.is_some());
        }
    }

    #[test]
    fn the_top_fall_is_a_fourth_order_butterworth_low_pass() {
        let db = |g: f64| 20.0 * g.log10();
        for fs in [8_000.0, 44_100.0, 48_000.0, 96_000.0, 192_000.0] {
            let fall = TopFall::new(3450.0, fs);
            // Unity far below the corner (the sections' DC gain is one by construction).
            assert!((fall.gain_at(1.0, fs) - 1.0).abs() < 1e-9, "{fs}");
            // Butterworth: -3.01 dB at the corner, which the bilinear transform keeps
            // where it is (pre-warped).
            let corner = db(fall.gain_at(3450.0, fs));
            assert!((corner + 3.01).abs() < 0.01, "{fs}: {corner}");
            // Everywhere, the analogue fourth-order Butterworth at the bilinear
            // transform's warped frequency, `1 / sqrt(1 + (tan(pi f / fs) / tan(pi fc /
            // fs))^8)` (24 dB an octave far above the corner, steeper nearer Nyquist):
            // f64 rounding.
            let warp = |f: f64| (PI * f / fs).tan();
            for k in 1..40 {
                let f = k as f64 * 0.0112 * fs;
                let expected = 1.0 / (1.0 + (warp(f) / warp(3450.0)).powi(8)).sqrt();
                let got = fall.gain_at(f, fs);
                assert!(
                    (got - expected).abs() < 1e-9 * expected.max(1e-6),
                    "{fs} {f}: {got} {expected}"
                );
            }
            // Stable: both sections' poles inside the unit circle.
            assert!(fall.sections.iter().all(|s| s.a[1] > 0.0 && s.a[1] < 1.0));
        }
        // A corner above 0.45 of the rate passes everything.
        let pass = TopFall::new(3450.0, 6_000.0);
        assert!((pass.gain_at(2_000.0, 6_000.0) - 1.0).abs() < 1e-12);
    }

    /// The cello's fall against Percival's radiated impulse responses of three cellos and
    /// five violins, each tapped at the bridge and recorded the same way (Artifastring,
    /// `research/impulses/short-impulses`, 44.1 kHz, 4096 samples; docs/timbre.md): the
    /// cellos' mean third-octave level less the violins', from 1 to 5 kHz, each
    /// instrument's power normalised over 250 Hz-2 kHz. The tap's and the microphone's own
    /// spectra are the same on both sides and cancel; the violin's body, whose modelled top
    /// matches its recording (docs/timbre.md), is the reference.
    #[test]
    fn the_cellos_body_falls_above_3_khz_as_measured_cellos_do_against_violins() {
        let bands = [
            1000.0, 1259.0, 1585.0, 1995.0, 2512.0, 3162.0, 3981.0, 5012.0,
        ];
        let measured = [-0.57, -4.35, -3.66, 0.96, 1.48, 0.32, -11.52, -12.07];
        let fs = 48_000.0;
        let kind = super::super::vocabulary::InstrumentKind::Cello;
        let fall = TopFall::new(kind.spec().top_fall_hz.unwrap(), fs);
        let violin = super::super::vocabulary::InstrumentKind::Violin;
        assert!(violin.spec().top_fall_hz.is_none());
        // The RMS difference after taking out the mean (the levels are relative).
        let residual = |model: &dyn Fn(f64) -> f64| {
            let d: Vec<f64> = bands
                .iter()
                .zip(measured)
                .map(|(&f, m)| m - model(f))
                .collect();
            let mean = d.iter().sum::<f64>() / d.len() as f64;
            (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
        };
        let with = residual(&|f| 20.0 * fall.gain_at(f, fs).log10());
        let without = residual(&|_| 0.0);
        // Without a fall the cello's body is the violin's scaled, flat on top: 5.1 dB from
        // the measurement. The eight bands' own scatter below 3 kHz (-4.4 to +1.5 dB,
        // 2.0 dB RMS, the instruments' individual modes) is what no smooth fall removes:
        // within 3 dB, and closer than without.
        assert!(without > 5.0, "{without}");
        assert!(with < 3.0, "{with}");
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
