//! Small linear filters used inside the string loop and the body: first-order allpass
//! (dispersion and Thiran fractional delay), linear-interpolation fractional delay, one-pole
//! loss filter, bandpass biquad.
//!
//! Every loop filter exposes its phase delay in samples at a normalised angular
//! frequency `w` (rad/sample), so the string can account for it in the loop length.
//!
//! ```
//! use colophony::dsp::filters::{Allpass1, OnePoleLoss};
//! use std::f64::consts::PI;
//! let w = |f: f64| 2.0 * PI * f / 48_000.0;
//! // Thiran's fractional delay of 0.3 samples: its phase delay at low frequency is 0.3.
//! let a = (1.0 - 0.3) / (1.0 + 0.3);
//! assert!((Allpass1::phase_delay(a, w(20.0)) - 0.3).abs() < 1e-6);
//! // A loss filter losing 1 % per trip at 100 Hz and 10 % at 1 kHz: a 100 Hz sine
//! // through it comes out at 0.99 of its amplitude.
//! let mut loss = OnePoleLoss::fit(w(100.0), 0.99, w(1000.0), 0.9);
//! let peak = (0..48_000)
//!     .map(|n| loss.tick((w(100.0) * n as f64).sin()))
//!     .skip(24_000)
//!     .fold(0.0f64, |m, y| m.max(y.abs()));
//! assert!((peak - 0.99).abs() < 1e-3);
//! let _ = Allpass1::new(a).tick(1.0);
//! ```

use std::f64::consts::PI;

/// First-order allpass `A(z) = (a + z^-1) / (1 + a z^-1)`, |a| < 1.
///
/// With `a = (1 - d) / (1 + d)` it is Thiran's first-order fractional delay of `d` samples
/// (exact at DC); with `a < 0` its delay falls with frequency, which is what a stiff
/// string's dispersion needs (Van Duyne and Smith 1994).
#[derive(Debug, Clone, Copy, Default)]
pub struct Allpass1 {
    pub a: f64,
    /// Transposed-direct-form state `s = x[n-1] - a y[n-1]`: `y = a x + s`.
    s: f64,
}

impl Allpass1 {
    pub fn new(a: f64) -> Self {
        Self { a, s: 0.0 }
    }

    /// One sample. In transposed direct form the input reaches the output through one
    /// multiply and one add (`y = a x + s`), so a chain of sections (the string's
    /// dispersion) is a short dependency chain; the state's update `s = x - a y` runs
    /// beside the next section.
    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        let y = self.a * x + self.s;
        self.s = x - self.a * y;
        y
    }

    pub fn reset(&mut self) {
        self.s = 0.0;
    }

    /// Energy the section holds, in squared signal units: `s^2 / (1 - a^2)` for its state
    /// `s` (`y = a x + s`). The section is lossless, and this is exactly what has gone in
    /// and not yet come out: `S(n+1) - S(n) = x^2 - y^2` on every sample (expand
    /// `s' = x - a y = (1 - a^2) x - a s`).
    pub fn stored_energy(&self) -> f64 {
        self.s * self.s / (1.0 - self.a * self.a)
    }

    /// Phase delay in samples at `w` rad/sample (`w` in (0, pi)).
    pub fn phase_delay(a: f64, w: f64) -> f64 {
        1.0 - 2.0 * (a * w.sin()).atan2(1.0 + a * w.cos()) / w
    }

    /// The coefficient whose phase delay at `w` is exactly `delay` samples, in closed
    /// form: with `psi = (1 - delay) w / 2`, [`Allpass1::phase_delay`] asks
    /// `atan2(a sin w, 1 + a cos w) = psi`, i.e. `a = sin psi / sin(w - psi)` (at low `w`,
    /// Thiran's `(1 - delay) / (1 + delay)`). `delay` should lie in [0.5, 2.5]; the result
    /// is kept within +-0.99. Cheap enough for a vibrato that retunes every few hundred
    /// samples.
    pub fn coefficient_for_delay(delay: f64, w: f64) -> f64 {
        let psi = 0.5 * (1.0 - delay) * w;
        let a = psi.sin() / (w - psi).sin();
        if a.is_finite() {
            a.clamp(-0.99, 0.99)
        } else {
            0.0
        }
    }
}

/// A chain of identical first-order allpass sections ([`Allpass1`]) sharing one
/// coefficient: a stiff string's dispersion. The same arithmetic as ticking the sections
/// one by one, with the coefficient loaded once.
#[derive(Debug, Clone, Copy)]
pub struct AllpassChain<const N: usize> {
    a: f64,
    stages: usize,
    s: [f64; N],
}

impl<const N: usize> Default for AllpassChain<N> {
    fn default() -> Self {
        Self {
            a: 0.0,
            stages: 0,
            s: [0.0; N],
        }
    }
}

impl<const N: usize> AllpassChain<N> {
    /// `stages` sections (at most `N`) of coefficient `a`; the states are kept.
    pub fn set(&mut self, stages: usize, a: f64) {
        self.stages = stages.min(N);
        self.a = a;
    }

    pub fn stages(&self) -> usize {
        self.stages
    }

    pub fn coefficient(&self) -> f64 {
        self.a
    }

    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        let stages = self.stages;
        self.tick_first(stages, x)
    }

    /// [`AllpassChain::tick`] where the caller knows the chain has `K` sections
    /// ([`AllpassChain::stages`]), compiled for that count: no loop bookkeeping.
    #[inline(always)]
    pub fn tick_known<const K: usize>(&mut self, x: f64) -> f64 {
        debug_assert_eq!(K, self.stages);
        self.tick_first(K, x)
    }

    /// The first `stages` sections (`stages <= N`).
    #[inline(always)]
    fn tick_first(&mut self, stages: usize, mut x: f64) -> f64 {
        let a = self.a;
        for s in &mut self.s[..stages] {
            let y = a * x + *s;
            *s = x - a * y;
            x = y;
        }
        x
    }

    /// Phase delay in samples at `w` rad/sample: the sections' delays summed one by one.
    pub fn phase_delay(&self, w: f64) -> f64 {
        let one = Allpass1::phase_delay(self.a, w);
        (0..self.stages).map(|_| one).sum()
    }

    /// What the sections hold (see [`Allpass1::stored_energy`]), summed one by one.
    pub fn stored_energy(&self) -> f64 {
        let scale = 1.0 - self.a * self.a;
        self.s[..self.stages].iter().map(|s| s * s / scale).sum()
    }

    pub fn reset(&mut self) {
        self.s = [0.0; N];
    }
}

/// One-pole lowpass loss filter `H(z) = g (1 - p) / (1 - p z^-1)`, 0 <= p < 1.
/// Its gain is largest at DC (`g`), which is kept below 1 so the loop is passive.
#[derive(Debug, Clone, Copy, Default)]
pub struct OnePoleLoss {
    g: f64,
    p: f64,
    /// The input's coefficient `g (1 - p)`.
    b: f64,
    y1: f64,
}

impl OnePoleLoss {
    /// The filter of DC gain `g` and pole `p`, at rest.
    pub fn new(g: f64, p: f64) -> Self {
        Self {
            g,
            p,
            b: g * (1.0 - p),
            y1: 0.0,
        }
    }

    /// Takes `other`'s coefficients, keeping the state.
    pub fn retune(&mut self, other: &Self) {
        *self = Self {
            y1: self.y1,
            ..*other
        };
    }

    /// Fits `p` and `g` so the filter's gain is `gain1` at `w1` and `gain2` at `w2`
    /// (`w1 < w2`, `gain2 <= gain1 < 1`). The DC gain is capped at `MAX_DC_GAIN`.
    pub fn fit(w1: f64, gain1: f64, w2: f64, gain2: f64) -> Self {
        const MAX_DC_GAIN: f64 = 0.99995;
        let target = (gain2 / gain1).min(1.0);
        let ratio = |p: f64| {
            ((1.0 - 2.0 * p * w1.cos() + p * p) / (1.0 - 2.0 * p * w2.cos() + p * p)).sqrt()
        };
        let (mut lo, mut hi) = (0.0, 0.999);
        if ratio(hi) > target {
            lo = hi;
        } else {
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if ratio(mid) > target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        let p = 0.5 * (lo + hi);
        let g = (gain1 / Self::unit_gain(p, w1)).min(MAX_DC_GAIN);
        Self::new(g, p)
    }

    /// The loss of a string's loop, one design for both string models: per round trip the
    /// fundamental `f1_hz` keeps `exp(-pi / q1)` of its amplitude (it decays at `Q1`), and
    /// ten times it (at most `0.4 fs`) decays at a Q interpolated in log frequency between
    /// `q1` and `q_hi` (`q_hi` at exactly ten times). `termination_gain` is what the loop's
    /// own real (frequency-independent) terminations keep per round trip (1 for rigid
    /// ones): the filter supplies only the rest, and nothing where they alone lose more.
    /// `fs` is the loop's sample rate.
    pub fn for_string(f1_hz: f64, fs: f64, q1: f64, q_hi: f64, termination_gain: f64) -> Self {
        let w1 = 2.0 * PI * f1_hz / fs;
        let f2 = (10.0 * f1_hz).min(0.4 * fs);
        let q2 = q1 * (q_hi / q1).powf((f2 / f1_hz).log10());
        let t = termination_gain.clamp(1e-3, 1.0);
        let gain1 = ((-PI / q1).exp() / t).min(1.0);
        let gain2 = ((-PI * f2 / (q2 * f1_hz)).exp() / t).min(gain1);
        Self::fit(w1, gain1, 2.0 * PI * f2 / fs, gain2)
    }

    fn unit_gain(p: f64, w: f64) -> f64 {
        (1.0 - p) / (1.0 - 2.0 * p * w.cos() + p * p).sqrt()
    }

    pub fn gain(&self, w: f64) -> f64 {
        self.g * Self::unit_gain(self.p, w)
    }

    /// Phase delay in samples at `w`.
    pub fn phase_delay(&self, w: f64) -> f64 {
        (self.p * w.sin()).atan2(1.0 - self.p * w.cos()) / w
    }

    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        self.y1 = self.b * x + self.p * self.y1;
        self.y1
    }

    /// Energy the filter holds, in squared signal units: the smallest storage `c y1^2` for
    /// which `S(n+1) - S(n) <= x^2 - y^2` on every sample (the filter is passive, `|H| <= g
    /// <= 1`), so a loop through it with lossless parts has a total energy that never grows.
    ///
    /// With `b = g (1 - p)` and `y = b x + p y1`, the inequality is a quadratic form in
    /// `(x, y1)` that is negative semidefinite exactly when `u = c + 1` lies between the
    /// roots of `b^2 u^2 - (1 + b^2 - p^2) u + 1 = 0`; the smaller root, written without
    /// cancellation, is `2 / (1 + b^2 - p^2 + sqrt(((1 - b)^2 - p^2) ((1 + b)^2 - p^2)))`
    /// (it is at least `1 / (1 - p^2)`, which the form's `y1^2` term needs). `p = 0` gives
    /// `c = 0`: a plain gain holds nothing.
    pub fn stored_energy(&self) -> f64 {
        let (b, p) = (self.b, self.p);
        let d = (((1.0 - b).powi(2) - p * p) * ((1.0 + b).powi(2) - p * p)).max(0.0);
        let u = 2.0 / (1.0 + b * b - p * p + d.sqrt());
        (u - 1.0).max(0.0) * self.y1 * self.y1
    }

    pub fn reset(&mut self) {
        self.y1 = 0.0;
    }
}

/// Constant-peak-gain bandpass biquad (RBJ cookbook), transposed direct form II.
#[derive(Debug, Clone, Copy, Default)]
pub struct Bandpass {
    b0: f64,
    a1: f64,
    a2: f64,
    s1: f64,
    s2: f64,
}

impl Bandpass {
    /// Largest state magnitude (to tell when the filter has rung out).
    pub fn state_magnitude(&self) -> f64 {
        self.s1.abs().max(self.s2.abs())
    }

    /// Samples for the state's envelope to fall below `level` if the input stops: the
    /// poles' radius is `sqrt(a2)`, so it falls by that factor per sample (0 if already
    /// below).
    pub fn samples_below(&self, level: f64) -> f64 {
        let mag = self.state_magnitude();
        let r = self.a2.max(0.0).sqrt();
        if mag <= level || !(r > 0.0 && r < 1.0) {
            return 0.0;
        }
        (level / mag).ln() / r.ln()
    }

    pub fn new(freq_hz: f64, q: f64, sample_rate_hz: f64) -> Self {
        let w0 = 2.0 * PI * freq_hz / sample_rate_hz;
        let alpha = w0.sin() / (2.0 * q);
        let a0 = 1.0 + alpha;
        Self {
            b0: alpha / a0,
            a1: -2.0 * w0.cos() / a0,
            a2: (1.0 - alpha) / a0,
            s1: 0.0,
            s2: 0.0,
        }
    }

    /// `(b0, a1, a2)`: `H(z) = b0 (1 - z^-2) / (1 + a1 z^-1 + a2 z^-2)`.
    pub fn coefficients(&self) -> (f64, f64, f64) {
        (self.b0, self.a1, self.a2)
    }

    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        // b1 = 0, b2 = -b0
        let y = self.b0 * x + self.s1;
        self.s1 = -self.a1 * y + self.s2;
        self.s2 = -self.b0 * x - self.a2 * y;
        y
    }

    pub fn reset(&mut self) {
        self.s1 = 0.0;
        self.s2 = 0.0;
    }
}

/// Magnitude below which [`flush_tiny`] gives zero.
pub const FLUSH_BELOW: f64 = 1e-30;

/// Flushes values too small to matter (and subnormal) to exact zero.
#[inline]
pub fn flush_tiny(x: f64) -> f64 {
    if x.abs() < FLUSH_BELOW {
        0.0
    } else {
        x
    }
}

/// Output safety limiter: the identity up to `SAFETY_KNEE` of full scale, then a smooth
/// (C1) curve that approaches but never exceeds 1. Only extreme bowing (several N at over
/// 1 m/s near the bridge) reaches it; it keeps a host's output audible-sane.
pub const SAFETY_KNEE: f64 = 0.9;

#[inline]
pub fn safety_limit(x: f64) -> f64 {
    let a = x.abs();
    if a <= SAFETY_KNEE {
        x
    } else {
        let room = 1.0 - SAFETY_KNEE;
        let over = (a - SAFETY_KNEE) / room;
        x.signum() * (SAFETY_KNEE + room * over / (1.0 + over))
    }
}

/// A fractional delay by linear interpolation between two neighbouring inputs,
/// `y = (1 - f) x[n - i] + f x[n - i - 1]`. A convex combination, so it only takes energy
/// out (`y^2 <= (1 - f) x[n-i]^2 + f x[n-i-1]^2`), and a sharp wave comes out of it
/// within those two samples, after its delay at every frequency. A first-order allpass
/// tuned to the same delay at the partial would pass a sharp wave's high frequencies
/// after about a whole sample instead (its phase is `pi` at Nyquist), and a bowed
/// harmonic's corner, which runs round the part between the bridge and the finger,
/// would go round early or late with the fraction (docs/articulations.md#harmonics). The
/// bridge's fraction of a touched waveguide string ([`super::waveguide::WaveguideString::set_touch`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Interpolation {
    /// The last inputs, newest first.
    x: [f64; 4],
    i: usize,
    f: f64,
}

impl Interpolation {
    /// Tuned so that its phase delay at `w` rad/sample (`w` under `pi / 2`) is `delay`
    /// (0 to 3 samples): with `p` its fraction, `atan2(f sin w, 1 - f + f cos w) = p w`.
    pub fn set(&mut self, delay: f64, w: f64) {
        let i = (delay.floor().max(0.0) as usize).min(2);
        let t = ((delay - i as f64) * w).tan();
        self.i = i;
        let f = t / (w.sin() + t * (1.0 - w.cos()));
        self.f = if f.is_finite() {
            f.clamp(0.0, 1.0)
        } else {
            0.5
        };
    }

    #[inline]
    pub fn tick(&mut self, x: f64) -> f64 {
        self.x = [x, self.x[0], self.x[1], self.x[2]];
        (1.0 - self.f) * self.x[self.i] + self.f * self.x[self.i + 1]
    }

    pub fn phase_delay(&self, w: f64) -> f64 {
        let f = self.f;
        self.i as f64 + (f * w.sin()).atan2(1.0 - f + f * w.cos()) / w
    }

    /// What has gone in and not yet come out, in squared signal units: the inputs the
    /// output has not reached yet and `f` of the first one it reads. With
    /// `S(n) = x[n]^2 + .. + x[n-i+1]^2 + f x[n-i]^2`,
    /// `S(n) - S(n-1) = x[n]^2 - (1 - f) x[n-i]^2 - f x[n-i-1]^2 <= x[n]^2 - y[n]^2` on
    /// every sample.
    pub fn stored_energy(&self) -> f64 {
        let held: f64 = self.x[..self.i].iter().map(|x| x * x).sum();
        held + self.f * self.x[self.i] * self.x[self.i]
    }

    pub fn reset(&mut self) {
        self.x = [0.0; 4];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic, broadband test signal in (-0.5, 0.5) (the logistic map).
    fn chaotic(n: usize) -> impl Iterator<Item = f64> {
        (0..n).scan(0.123_f64, |x, _| {
            *x = 3.99 * *x * (1.0 - *x);
            Some(*x - 0.5)
        })
    }

    #[test]
    fn allpass_storage_changes_by_exactly_what_goes_in_minus_what_comes_out() {
        for a in [-0.95, -0.6, 0.0, 0.4, 0.95] {
            let mut ap = Allpass1::new(a);
            for x in chaotic(2000) {
                let before = ap.stored_energy();
                let y = ap.tick(x);
                let balance = ap.stored_energy() - before - (x * x - y * y);
                // Rounding only: a few products of size up to 1 / (1 - a^2) ~ 10, each
                // within 2^-53 relative.
                assert!(balance.abs() < 1e-13, "a {a}: balance {balance:e}");
            }
        }
    }

    #[test]
    fn loss_filter_storage_grows_by_at_most_what_goes_in_minus_what_comes_out() {
        for (g, p) in [
            (0.99995, 0.0),
            (0.99995, 0.3),
            (0.999, 0.9),
            (0.9, 0.99),
            (1.0, 0.999),
        ] {
            let mut loss = OnePoleLoss::new(g, p);
            let mut dissipated = 0.0;
            for x in chaotic(20_000) {
                let before = loss.stored_energy();
                let y = loss.tick(x);
                let supplied = x * x - y * y;
                let gained = loss.stored_energy() - before;
                // Rounding only, as above (the storage factor is at most 1 / (1 - p^2)).
                assert!(
                    gained <= supplied + 1e-12,
                    "g {g}, p {p}: {gained:e} > {supplied:e}"
                );
                dissipated += supplied - gained;
            }
            assert!(dissipated >= 0.0);
        }
    }

    #[test]
    fn the_safety_limiter_is_transparent_below_its_knee_and_never_reaches_full_scale() {
        for x in [-0.9, -0.5, 0.0, 0.3, 0.9] {
            assert_eq!(safety_limit(x), x);
        }
        let mut last = 0.0;
        for k in 1..2000 {
            let x = 0.9 + k as f64 * 0.05;
            let y = safety_limit(x);
            assert!(y > last && y < 1.0, "{x} -> {y}");
            assert_eq!(safety_limit(-x), -y);
            last = y;
        }
        // C1 at the knee: slope 1 on both sides.
        let h = 1e-7;
        let slope = (safety_limit(SAFETY_KNEE + h) - SAFETY_KNEE) / h;
        // A one-sided difference over h = 1e-7: the curve's bend past the knee
        // (f'' = -2 / 0.1) gives 1e-6, rounding 2e-9.
        assert!((slope - 1.0).abs() < 1e-5);
    }

    #[test]
    fn thiran_coefficient_gives_the_requested_phase_delay() {
        // From 30 Hz at 384 kHz to a loop of 6 samples (w = 1; the strings' loops are
        // longer), every delay the strings ask for.
        for w in [
            2.0 * PI * 30.0 / 384_000.0,
            2.0 * PI * 147.0 / 48_000.0,
            0.3,
            0.7,
            1.0,
        ] {
            for &d in &[0.5, 0.9, 1.0, 1.37, 2.0, 2.4, 2.5] {
                let a = Allpass1::coefficient_for_delay(d, w);
                // Closed form: exact but for rounding (1e-9 samples is far below any pitch
                // a player hears).
                let got = Allpass1::phase_delay(a, w);
                assert!((got - d).abs() < 1e-9, "w {w}, d {d}: {got}");
            }
        }
    }

    #[test]
    fn loss_filter_hits_both_gains_and_stays_passive() {
        let (w1, w2) = (0.02, 0.2);
        let f = OnePoleLoss::fit(w1, 0.99, w2, 0.9);
        // The gain at w1 is set in closed form: rounding only.
        assert!((f.gain(w1) - 0.99).abs() < 1e-9);
        // p from 60 halvings of [0, 0.999], past f64's resolution: rounding only, measured
        // 1.1e-16. 1e-6 is 1e-5 dB at this gain, far below any loss a listener hears.
        assert!((f.gain(w2) - 0.9).abs() < 1e-6);
        assert!(f.gain(0.0) < 1.0);
    }

    /// The linear interpolation as a touched string's bridge fraction: tuned to its delay at the partial
    /// (0.5 to 2.5 samples, partials from 0.1 to 6 kHz at 48 kHz), and it never gives out
    /// more than it took in: on every sample of a chaotic input its stored energy grows by
    /// at most what went in less what came out (f64 rounding).
    #[test]
    fn the_bridge_fraction_is_tuned_at_the_partial_and_only_takes_energy_out() {
        for delay in [0.5, 0.73, 1.0, 1.21, 1.5, 1.99, 2.3, 2.49] {
            for f_hz in [100.0, 1000.0, 3000.0, 6000.0] {
                let w = 2.0 * PI * f_hz / 48_000.0;
                let mut fraction = Interpolation::default();
                fraction.set(delay, w);
                let got = fraction.phase_delay(w);
                assert!(
                    (got - delay).abs() < 1e-9,
                    "{delay} samples at {f_hz} Hz: {got}"
                );
                let mut x: f64 = 0.3;
                let mut stored = fraction.stored_energy();
                for _ in 0..1000 {
                    x = 3.9 * x * (1.0 - x);
                    let input = x - 0.5;
                    let output = fraction.tick(input);
                    let now = fraction.stored_energy();
                    assert!(
                        now - stored <= input * input - output * output + 1e-15,
                        "{delay} samples at {f_hz} Hz: the fraction gave out energy"
                    );
                    stored = now;
                }
            }
        }
    }
}
