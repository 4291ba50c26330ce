//! Modal objects and friction between two of them (paper A, docs/models.md §A; the sound
//! effects of its §5.2).
//!
//! A [`ModalObject`] is a bank of second-order modes `m x'' + r x' + k x = w f`, each
//! weighted by its shape `w` at the contact point, discretised by the bilinear transform
//! (trapezoidal rule) with the stiffness pre-warped so each discrete resonance sits exactly
//! at its frequency. Modes at or above Nyquist are dropped. Each sample the object offers
//! the contact a load line: its contact velocity with no new force and its instantaneous
//! admittance `Y = sum w^2 (T / 2m) / D`, `D = 1 + T r / 2m + T^2 k / 4m`.
//!
//! [`FrictionPair`] rubs a resonator with an exciter (a rigid velocity source or a modal
//! object pushed by a force), through any [`FrictionContact`]: the relative velocity is
//! `v = (v_bow_free - v_res_free) - (Y_bow + Y_res) F`, one load line, solved without delay.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `f` | mode frequency | Hz |
//! | `Q` | quality factor (`r = 2 pi f m / Q`) | 1 |
//! | `m` | modal mass | kg |
//! | `w` | mode shape at the contact | 1 |
//!
//! ```
//! use colophony::dsp::modal::{ModalObject, ModeSpec};
//! let mode = ModeSpec { freq_hz: 660.0, q: 1000.0, mass_kg: 0.01, weight: 1.0 };
//! let mut glass = ModalObject::new(&[mode], 48_000.0).unwrap();
//! // A 1 N push for one sample (the trapezoid spreads it over two), then the glass
//! // rings freely and loses energy.
//! let tick = |glass: &mut ModalObject, force_n: f64| {
//!     glass.begin(force_n);
//!     glass.finish(0.0);
//! };
//! tick(&mut glass, 1.0);
//! tick(&mut glass, 0.0);
//! let struck = glass.energy_j();
//! (0..4_800).for_each(|_| tick(&mut glass, 0.0));
//! assert!(struck > 0.0 && glass.energy_j() < struck);
//! ```

use super::filters::flush_tiny;
use super::friction::{BowInput, FrictionContact, LoadLine};
use std::f64::consts::PI;

/// Most modes an object holds (storage is fixed, so switching presets never allocates).
pub const MAX_MODES: usize = 32;

/// One mode as data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeSpec {
    pub freq_hz: f64,
    pub q: f64,
    pub mass_kg: f64,
    /// Mode shape at the contact point.
    pub weight: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct Mode {
    /// `T / (2 m D)`: velocity per unit force this sample.
    b: f64,
    /// `(1 - T r / 2m - T^2 k / 4m) / D`.
    a_v: f64,
    /// `-(T k / m) / D`.
    a_x: f64,
    half_t: f64,
    weight: f64,
    x: f64,
    v: f64,
    /// Total force on the mode last sample.
    f_prev: f64,
    /// Free velocity this sample (before the contact force).
    v_free: f64,
    x_prev: f64,
    v_prev: f64,
    mass: f64,
    k: f64,
    /// Energy decay per sample of the free mode, `-2 ln |z|` for its slower discrete pole
    /// (0 for an undamped or free mode: it never rings out).
    decay_per_sample: f64,
    /// How far the energy of the free mode can rise above its envelope `E0 |z|^2n`:
    /// `(1 + zeta) / (1 - zeta)`, `zeta = r / (2 sqrt(k m))`; infinite from critical
    /// damping on (no finite bound claimed there).
    envelope_factor: f64,
}

impl Mode {
    /// Kinetic plus potential energy, J.
    fn energy_j(&self) -> f64 {
        0.5 * self.mass * self.v * self.v + 0.5 * self.k * self.x * self.x
    }
}

/// A bank of modes (see the module doc).
#[derive(Debug, Clone)]
pub struct ModalObject {
    modes: [Mode; MAX_MODES],
    count: usize,
    admittance_s_per_kg: f64,
    /// External force on the object this sample (e.g. the player's push on a bow), N.
    external_n: f64,
}

impl ModalObject {
    /// Builds the object at `sample_rate_hz`. Rejects non-finite or non-positive data and
    /// more than [`MAX_MODES`] modes; modes at or above Nyquist are dropped silently
    /// (they cannot be represented). A mode at 0 Hz is a free mass.
    pub fn new(modes: &[ModeSpec], sample_rate_hz: f64) -> Result<Self, String> {
        if modes.len() > MAX_MODES {
            return Err(format!("at most {MAX_MODES} modes, got {}", modes.len()));
        }
        let mut object = Self {
            modes: [Mode::default(); MAX_MODES],
            count: 0,
            admittance_s_per_kg: 0.0,
            external_n: 0.0,
        };
        let t = 1.0 / sample_rate_hz;
        for spec in modes {
            if !(spec.freq_hz.is_finite() && spec.freq_hz >= 0.0)
                || !(spec.q.is_finite() && spec.q > 0.0)
                || !(spec.mass_kg.is_finite() && spec.mass_kg > 0.0)
                || !spec.weight.is_finite()
            {
                return Err(format!("invalid mode {spec:?}: need f >= 0, Q > 0, m > 0"));
            }
            if spec.freq_hz >= 0.5 * sample_rate_hz {
                continue;
            }
            let m = spec.mass_kg;
            // Pre-warped stiffness: the trapezoidal rule maps w_d to (2/T) tan(w_d T/2).
            let w = (2.0 / t) * (PI * spec.freq_hz * t).tan();
            let k = m * w * w;
            let r = 2.0 * PI * spec.freq_hz * m / spec.q;
            let d = 1.0 + t * r / (2.0 * m) + t * t * k / (4.0 * m);
            object.modes[object.count] = Mode {
                b: t / (2.0 * m * d),
                a_v: (1.0 - t * r / (2.0 * m) - t * t * k / (4.0 * m)) / d,
                a_x: -(t * k / m) / d,
                half_t: 0.5 * t,
                weight: spec.weight,
                mass: m,
                k,
                decay_per_sample: discrete_decay_per_sample(m, r, k, t),
                envelope_factor: {
                    let zeta = r / (2.0 * (k * m).sqrt());
                    if zeta < 1.0 {
                        (1.0 + zeta) / (1.0 - zeta)
                    } else {
                        f64::INFINITY
                    }
                },
                ..Mode::default()
            };
            object.admittance_s_per_kg += spec.weight * spec.weight * object.modes[object.count].b;
            object.count += 1;
        }
        Ok(object)
    }

    /// Modes kept (below Nyquist).
    pub fn mode_count(&self) -> usize {
        self.count
    }

    pub fn admittance_s_per_kg(&self) -> f64 {
        self.admittance_s_per_kg
    }

    pub fn reset(&mut self) {
        for mode in &mut self.modes[..self.count] {
            mode.x = 0.0;
            mode.v = 0.0;
            mode.f_prev = 0.0;
        }
    }

    /// Sets every mode's velocity to `v` (e.g. a bow already moving).
    pub fn set_velocity(&mut self, v_m_per_s: f64) {
        for mode in &mut self.modes[..self.count] {
            mode.v = v_m_per_s;
        }
    }

    /// Starts a sample with an external force (at the contact point) and returns the load
    /// line: the contact velocity without the contact force, and the admittance.
    pub fn begin(&mut self, external_n: f64) -> LoadLine {
        self.external_n = external_n;
        let mut v = 0.0;
        for mode in &mut self.modes[..self.count] {
            let f_now = mode.weight * external_n;
            mode.x_prev = mode.x;
            mode.v_prev = mode.v;
            mode.v_free = mode.a_v * mode.v + mode.a_x * mode.x + mode.b * (mode.f_prev + f_now);
            v += mode.weight * mode.v_free;
        }
        LoadLine {
            free_velocity_m_per_s: v,
            admittance_s_per_kg: self.admittance_s_per_kg,
        }
    }

    /// Finishes the sample with the contact force `force_n` on the object; returns the
    /// contact velocity.
    pub fn finish(&mut self, force_n: f64) -> f64 {
        let mut v = 0.0;
        for mode in &mut self.modes[..self.count] {
            let f_total = mode.weight * (self.external_n + force_n);
            mode.v = flush_tiny(mode.v_free + mode.b * mode.weight * force_n);
            mode.x = flush_tiny(mode.x_prev + mode.half_t * (mode.v_prev + mode.v));
            mode.f_prev = f_total;
            v += mode.weight * mode.v;
        }
        v
    }

    /// Displacement at the contact point, m.
    pub fn displacement_m(&self) -> f64 {
        self.modes[..self.count]
            .iter()
            .map(|m| m.weight * m.x)
            .sum()
    }

    /// Kinetic plus potential energy of the modes, J (with the pre-warped stiffness).
    pub fn energy_j(&self) -> f64 {
        self.modes[..self.count].iter().map(Mode::energy_j).sum()
    }

    /// Samples until the energy falls below `threshold_j` if nothing drives the object, or
    /// `None` if a mode holding energy has no finite bound (undamped, a free mass, or
    /// damped critically or more). An upper bound: a free under-damped mode's energy stays
    /// below `(1 + zeta) / (1 - zeta)` times its envelope `E0 |z|^2n` (the continuous
    /// oscillator's exact worst case over initial states; `zeta = 1 / 2Q`), each mode must
    /// fall below `threshold / modes`, and the modes are independent once nothing drives
    /// them.
    pub fn ring_out_samples(&self, threshold_j: f64) -> Option<f64> {
        let target = threshold_j / self.count.max(1) as f64;
        let mut longest = 0.0f64;
        for m in &self.modes[..self.count] {
            let e = m.energy_j();
            if e <= 0.0 {
                continue;
            }
            if m.decay_per_sample <= 0.0 || !m.envelope_factor.is_finite() {
                return None;
            }
            let peak = m.envelope_factor * e;
            if peak > target {
                longest = longest.max((peak / target).ln() / m.decay_per_sample);
            }
        }
        Some(longest)
    }
}

/// `-2 ln |z|` for the slower of a mode's two discrete poles: the trapezoidal rule maps
/// each continuous pole `s` of `m s^2 + r s + k` to `z = (1 + sT/2) / (1 - sT/2)`.
fn discrete_decay_per_sample(m: f64, r: f64, k: f64, t: f64) -> f64 {
    let sigma = -r / (2.0 * m);
    let disc = sigma * sigma - k / m;
    // |z|^2 for a pole s = a + jb.
    let z2 = |a: f64, b: f64| {
        let (nr, ni) = (1.0 + 0.5 * t * a, 0.5 * t * b);
        let (dr, di) = (1.0 - 0.5 * t * a, -0.5 * t * b);
        (nr * nr + ni * ni) / (dr * dr + di * di)
    };
    let slowest = if disc >= 0.0 {
        // Over-damped: two real poles; the one nearer zero decays slower.
        z2(sigma + disc.sqrt(), 0.0)
    } else {
        z2(sigma, (-disc).sqrt())
    };
    (-slowest.ln()).max(0.0)
}

/// What drives the rubbing object.
#[derive(Debug, Clone)]
pub enum Exciter {
    /// A velocity source: the bow moves at the commanded velocity whatever the friction.
    Rigid,
    /// A modal object (e.g. a free 50 g mass) pushed along by a force; the commanded
    /// velocity sets the push to the steady sliding friction at that velocity, as in the
    /// authors' script.
    Modal(ModalObject),
}

/// One sample of a [`FrictionPair`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PairOutput {
    /// Resonator velocity at the contact, m/s.
    pub resonator_velocity_m_per_s: f64,
    /// Exciter (bow) velocity at the contact, m/s.
    pub exciter_velocity_m_per_s: f64,
    /// Friction force on the resonator, N.
    pub friction_force_n: f64,
}

/// An exciter rubbing a resonator through a friction contact.
#[derive(Debug, Clone)]
pub struct FrictionPair {
    pub resonator: ModalObject,
    pub exciter: Exciter,
}

impl FrictionPair {
    /// One sample. For a rigid exciter `bow.velocity_m_per_s` is its velocity; for a modal
    /// one it is the velocity the push aims at, and `push_n` the force on it.
    pub fn tick(
        &mut self,
        contact: &mut impl FrictionContact,
        bow: BowInput,
        push_n: f64,
    ) -> PairOutput {
        let res = self.resonator.begin(0.0);
        let (bow_free, bow_admittance) = match &mut self.exciter {
            Exciter::Rigid => (bow.velocity_m_per_s, 0.0),
            Exciter::Modal(object) => {
                let load = object.begin(push_n);
                (load.free_velocity_m_per_s, load.admittance_s_per_kg)
            }
        };
        let load = LoadLine {
            free_velocity_m_per_s: res.free_velocity_m_per_s,
            admittance_s_per_kg: res.admittance_s_per_kg + bow_admittance,
        };
        let force = contact.solve(
            load,
            BowInput {
                velocity_m_per_s: bow_free,
                normal_force_n: bow.normal_force_n,
            },
        );
        let v_res = self.resonator.finish(force);
        let v_bow = match &mut self.exciter {
            Exciter::Rigid => bow.velocity_m_per_s,
            Exciter::Modal(object) => object.finish(-force),
        };
        PairOutput {
            resonator_velocity_m_per_s: v_res,
            exciter_velocity_m_per_s: v_bow,
            friction_force_n: force,
        }
    }

    pub fn reset(&mut self) {
        self.resonator.reset();
        if let Exciter::Modal(object) = &mut self.exciter {
            object.reset();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ring_out_estimate_bounds_the_free_decay_to_the_threshold_and_is_not_far_off() {
        let fs = 48_000.0;
        // A low-Q mode (large envelope ripple), a high-Q one and a free mass.
        let mode = |freq_hz: f64, q: f64| ModeSpec {
            freq_hz,
            q,
            mass_kg: 1e-3,
            weight: 1.0,
        };
        let threshold = 1e-16;
        for modes in [
            vec![mode(500.0, 2.0), mode(1300.0, 80.0)],
            vec![mode(660.0, 3000.0), mode(1780.0, 2000.0)],
            vec![mode(300.0, 0.7)],
        ] {
            let mut object = ModalObject::new(&modes, fs).unwrap();
            // Struck over a few samples (some in x, some in v), then free.
            for n in 0..7 {
                object.begin(0.0);
                object.finish(if n % 3 == 0 { 0.2 } else { -0.05 });
            }
            let told = object.ring_out_samples(threshold).unwrap();
            let mut rang = 0.0;
            let mut last_above = 0.0;
            while rang < told * 3.0 + 1000.0 {
                object.begin(0.0);
                object.finish(0.0);
                rang += 1.0;
                if object.energy_j() >= threshold {
                    last_above = rang;
                }
            }
            assert!(
                last_above <= told,
                "{modes:?}: above at {last_above}, told {told}"
            );
            // Measured 1.011, 1.007 and 1.062 (Q 0.7: the largest ripple factor). The
            // estimate's slack, ln(ripple factor x modes) over the decay rate, is a few per
            // cent of a ring-out to 1e-16 J; an estimate at two thirds of the rate fails.
            assert!(
                told <= 1.5 * last_above,
                "{modes:?}: told {told}, rang {last_above}"
            );
        }
        let mass = ModeSpec {
            freq_hz: 0.0,
            q: 1e5,
            mass_kg: 0.05,
            weight: 1.0,
        };
        let mut free = ModalObject::new(&[mass], fs).unwrap();
        free.begin(0.0);
        free.finish(1.0);
        assert_eq!(
            free.ring_out_samples(threshold),
            None,
            "a free mass never rings out"
        );
    }

    #[test]
    fn a_struck_mode_rings_at_its_frequency_and_decays_at_its_q() {
        let fs = 48_000.0;
        let spec = ModeSpec {
            freq_hz: 440.0,
            q: 50.0,
            mass_kg: 1e-3,
            weight: 1.0,
        };
        let mut object = ModalObject::new(&[spec], fs).unwrap();
        // One-sample force impulse, then free ringing.
        let mut v = Vec::new();
        for n in 0..48_000 {
            object.begin(0.0);
            v.push(object.finish(if n == 0 { 1.0 } else { 0.0 }));
        }
        let f = crate::analysis::peak_frequency_hz(&v[..24_000], fs, 440.0, 50.0);
        // pre-warped bilinear: exact to the estimator's resolution
        assert!(crate::analysis::cents(f, 440.0).abs() < 0.5, "{f} Hz");
        // amplitude decay exp(-pi f t / Q) over 0.1 s
        let peak = |a: usize| v[a..a + 480].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let ratio = peak(9_600) / peak(4_800);
        let expected = (-PI * 440.0 * 0.1 / 50.0).exp();
        // Measured 0.21 % over: the trapezoidal rule's pole decays slower than the
        // continuous one by about (w T / 2)^2 = 0.08 % of its rate, 0.23 % over 0.1 s.
        // 2 % still sees a Q off by 1 % (2.8 % in the ratio).
        assert!(
            (ratio / expected - 1.0).abs() < 0.02,
            "{ratio} vs {expected}"
        );
    }

    #[test]
    fn modes_at_or_above_nyquist_are_dropped() {
        let specs = [
            ModeSpec {
                freq_hz: 1000.0,
                q: 10.0,
                mass_kg: 1e-3,
                weight: 1.0,
            },
            ModeSpec {
                freq_hz: 30_000.0,
                q: 10.0,
                mass_kg: 1e-3,
                weight: 1.0,
            },
        ];
        assert_eq!(ModalObject::new(&specs, 44_100.0).unwrap().mode_count(), 1);
        assert_eq!(ModalObject::new(&specs, 96_000.0).unwrap().mode_count(), 2);
    }
}
