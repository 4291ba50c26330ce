//! Cremer's corner rounding, predicted from the string's own losses and friction law: the
//! slip fraction a Helmholtz motion with rounded corners shows at the bow.
//!
//! **Method** (Cremer, *The Physics of the Violin*, 1984, ch. 7; Guettler, Schoonderwaldt
//! and Askenfelt, SMAC 2003, for the force and velocity dependence). In Helmholtz motion
//! one corner circulates: a step of height `D = v_b / beta` in the string's velocity. On
//! each trip round the string the terminations' frequency-dependent losses smooth it; at
//! each of its two passes under the bow the friction law steepens it again, the more the
//! harder the bow presses. The corner's shape settles where the two balance, and a rounded
//! corner lengthens the slip as the analysis measures it (corner to corner, at the
//! half-jump). The prediction follows one corner round the loop, period after period, with
//! nothing else of the motion:
//!
//! 1. **Release.** The bow holds the string while the corner arriving from the nut side
//!    lowers the velocity the string would have without friction, `v_h = v_b - s0 - D c(t)`
//!    (`c` rising from 0 to 1, the corner's shape), until the friction law lets go; from
//!    then the contact's own solver gives the string's velocity `v`. The corner leaving
//!    toward the bridge is `r(t) = (v_b - v) / D`.
//! 2. **Capture.** The bridge reflects it rigidly: it returns after the bridge-side round
//!    trip, raising `v_h = v_b - s0 - D (1 - r(t))` from the slip plateau until the law
//!    grips; the corner leaving toward the nut is the string's rise `q(t) = (v - v_b + D) /
//!    D`.
//! 3. **The loop's losses.** The nut's reflection filters (the loss, the stiffness
//!    dispersion and the fractional delay, [`WaveguideString::loop_kernel`]) act on `q`,
//!    normalised to keep the corner's height (the bow restores what the loop takes from it
//!    at low frequency): the next release's `c`.
//!
//! `s0` is the sticking force before release over `2 Z0`: in steady Helmholtz motion the
//! corner leaves the bow as high as it came, so the string must slip at `D` on the plateau,
//! where the friction force is the law's at that slip speed: `s0 = f(D) / (2 Z0)`.
//! Once the shape stops changing, the bow-point velocity of one period is the release's
//! fall and, the bridge-side trip later, the capture's rise, superposed as the travelling
//! waves they are (the slip is the fall less the rise, so where the two corners overlap
//! the period keeps the zero mean velocity of a string fixed at both ends), and
//! [`crate::analysis::slip_stats`] measures it as it measures the model.
//!
//! **What it leaves out**, so a model may differ from it: the secondary waves the bow
//! reflects while sticking, the torsion's and the hair's admittance at the contact, and the
//! friction law acting on the two corners together where they overlap (each pass sees one
//! corner alone).

use crate::analysis::slip_stats;
use crate::dsp::friction::{BowInput, FrictionContact, LoadLine};
use crate::dsp::waveguide::WaveguideString;

/// Most periods the corner is followed round the loop before its shape is taken as settled.
pub const MAX_PERIODS: usize = 4000;
/// The shape has settled when its width (the rise's variance, samples^2), averaged over a
/// block of [`BLOCK`] periods, moves by less than this fraction from one block to the
/// next. The variance never stops moving altogether: the release and capture instants
/// fall on whole samples while the corner drifts across them, which makes it jitter by
/// about 1e-4 of itself from period to period and, on some strings, swing by 2 % over
/// hundreds of periods. A 1 % change of the variance moves the corner's width by 0.5 %.
pub const SETTLED: f64 = 1e-2;
/// Periods per block of the settling test.
const BLOCK: usize = 50;
/// Samples the contact is held at its starting state before a pass (long enough for the
/// bristle laws' bristles to settle at the plugin's rates).
const PRELUDE: usize = 256;

/// The corner-to-corner slip fraction of Helmholtz motion on `string` bowed with `bow`
/// through `contact` (its friction law; its state is reset), with the corner rounded by the
/// string's loop and sharpened by the bow as in the module's method. `None` where the law
/// never lets the string go or never grips it again (no Helmholtz motion to predict).
/// Allocates: not for the audio thread.
pub fn predicted_slip_fraction(
    string: &WaveguideString,
    contact: &mut impl FrictionContact,
    bow: BowInput,
) -> Option<f64> {
    let v = predicted_period(string, contact, bow, SETTLED)?;
    let v_b = bow.velocity_m_per_s.abs();
    let stats = slip_stats(&v.repeat(4), v_b, 1.0, 1.0 / v.len() as f64, 0.05 * v_b);
    Some(stats.slip_fraction)
}

/// One period of the predicted bow-point velocity, m/s, one value a sample, with the
/// corner's shape taken as settled at `settled_at` (see [`SETTLED`]).
fn predicted_period(
    string: &WaveguideString,
    contact: &mut impl FrictionContact,
    bow: BowInput,
    settled_at: f64,
) -> Option<Vec<f64>> {
    let loop_samples = string.loop_samples();
    let bridge_trip = (string.effective_beta() * loop_samples).round() as usize;
    let period = loop_samples.round() as usize;
    if period < 4 || bridge_trip == 0 || bridge_trip >= period {
        return None;
    }
    let v_b = bow.velocity_m_per_s.abs();
    if v_b <= 0.0 || bow.normal_force_n <= 0.0 {
        return None;
    }
    let bow = BowInput {
        velocity_m_per_s: v_b,
        ..bow
    };
    let admittance = 0.5 / string.spec().z0_kg_per_s;
    let d = v_b / string.effective_beta();
    let mut kernel = string.loop_kernel(period);
    // The tail beyond a part in 10^12 adds nothing a sample can show.
    while kernel.len() > 1 && kernel.last().is_some_and(|k| k.abs() < 1e-12) {
        kernel.pop();
    }
    let pass = Pass {
        bow,
        admittance,
        d,
        s0: plateau_force(contact, bow, admittance, d)? * admittance,
    };

    // The corner's shape over one period's window, a sharp step to start.
    let w = period;
    let mut c: Vec<f64> = (0..w).map(|i| if i >= w / 2 { 1.0 } else { 0.0 }).collect();
    let mut r = vec![0.0; w];
    let mut q = vec![0.0; w];
    let mut next = vec![0.0; w];
    let mut settled = false;
    let (mut block_sum, mut last_block) = (0.0, f64::NAN);
    for period_index in 0..MAX_PERIODS {
        pass.release(contact, &c, &mut r)?;
        pass.capture(contact, &r, &mut q)?;
        for (i, y) in next.iter_mut().enumerate() {
            // Before the window the corner has not arrived (0); q is 1 after it.
            *y = kernel
                .iter()
                .enumerate()
                .map(|(j, k)| k * if j <= i { q[i - j] } else { 0.0 })
                .sum();
        }
        recentre(&mut next);
        std::mem::swap(&mut c, &mut next);
        block_sum += variance(&c);
        if (period_index + 1) % BLOCK == 0 {
            let block = block_sum / BLOCK as f64;
            block_sum = 0.0;
            if (block - last_block).abs() <= settled_at * block.max(1.0) {
                settled = true;
                break;
            }
            last_block = block;
        }
    }
    if !settled {
        return None;
    }
    pass.release(contact, &c, &mut r)?;
    pass.capture(contact, &r, &mut q)?;

    // One period of the bow-point velocity: the release's fall centred at a quarter of
    // the period, the capture's rise the bridge-side trip later. The two travelling
    // corners superpose, so the slip is their difference: where they overlap, a string
    // fixed at both ends keeps a mean velocity of zero over the period.
    let start = period / 4;
    let at = |shape: &[f64], k: isize| -> f64 {
        if k < 0 {
            0.0
        } else if k as usize >= w {
            1.0
        } else {
            shape[k as usize]
        }
    };
    let mut v = Vec::with_capacity(period);
    for t in 0..period as isize {
        let fall = at(&r, t - start as isize + (w / 2) as isize);
        let rise = at(&q, t - (start + bridge_trip) as isize + (w / 2) as isize);
        let slipping = (fall - rise).max(0.0);
        v.push(v_b - d * slipping);
    }
    Some(v)
}

/// The bow, the contact's admittance and the corner's scale for the passes.
struct Pass {
    bow: BowInput,
    admittance: f64,
    /// The corner's height, m/s.
    d: f64,
    /// The sticking force before release over `2 Z0`, m/s.
    s0: f64,
}

impl Pass {
    fn solve(&self, contact: &mut impl FrictionContact, v_h: f64) -> f64 {
        let load = LoadLine {
            free_velocity_m_per_s: v_h,
            admittance_s_per_kg: self.admittance,
        };
        v_h + contact.solve(load, self.bow) * self.admittance
    }

    /// The corner `c` arriving from the nut while the string sticks: the shape `r` it
    /// leaves with toward the bridge. `None` if the string never lets go.
    fn release(&self, contact: &mut impl FrictionContact, c: &[f64], r: &mut [f64]) -> Option<()> {
        let v_b = self.bow.velocity_m_per_s;
        contact.reset();
        // From no load (sticking) up to the sticking load before release.
        for i in 0..PRELUDE {
            let s = self.s0 * (i as f64 / PRELUDE as f64).min(1.0);
            self.solve(contact, v_b - s);
        }
        for _ in 0..PRELUDE {
            self.solve(contact, v_b - self.s0);
        }
        for (ci, ri) in c.iter().zip(r.iter_mut()) {
            let v = self.solve(contact, v_b - self.s0 - self.d * ci);
            *ri = (v_b - v) / self.d;
        }
        (r.last().copied().unwrap_or(0.0) > 0.5).then_some(())
    }

    /// The corner `r` returning from the bridge while the string slips: the shape `q` it
    /// leaves with toward the nut. `None` if the string never grips again.
    fn capture(&self, contact: &mut impl FrictionContact, r: &[f64], q: &mut [f64]) -> Option<()> {
        let v_b = self.bow.velocity_m_per_s;
        contact.reset();
        let plateau = v_b - self.s0 - self.d;
        for _ in 0..2 * PRELUDE {
            self.solve(contact, plateau);
        }
        for (ri, qi) in r.iter().zip(q.iter_mut()) {
            let v = self.solve(contact, plateau + self.d * ri);
            *qi = (v - v_b + self.d) / self.d;
        }
        (q.last().copied().unwrap_or(0.0) > 0.5).then_some(())
    }
}

/// The friction force while the string slips at `d` under the bow (the Helmholtz slip
/// plateau), N: the sticking load before release is set so that the plateau slips at
/// exactly `d`. `None` if no such slip exists.
fn plateau_force(
    contact: &mut impl FrictionContact,
    bow: BowInput,
    admittance: f64,
    d: f64,
) -> Option<f64> {
    let v_b = bow.velocity_m_per_s;
    let mut s0 = 0.0;
    let mut force = 0.0;
    for _ in 0..40 {
        contact.reset();
        let v_h = v_b - s0 - d;
        let load = LoadLine {
            free_velocity_m_per_s: v_h,
            admittance_s_per_kg: admittance,
        };
        for _ in 0..2 * PRELUDE {
            force = contact.solve(load, bow);
        }
        let slip = v_b - (v_h + force * admittance);
        if slip <= 0.0 {
            return None;
        }
        let next = force * admittance;
        if (next - s0).abs() < 1e-12 * d.max(1e-9) {
            break;
        }
        s0 = next;
    }
    force.is_finite().then_some(force)
}

/// The rise of the shape `c` (0 to 1) as a distribution over the samples: (total, centroid,
/// variance in samples^2).
fn moments(c: &[f64]) -> (f64, f64, f64) {
    let mut prev = 0.0;
    let (mut mass, mut first, mut second) = (0.0, 0.0, 0.0);
    for (i, y) in c.iter().enumerate() {
        let dm = y - prev;
        let x = i as f64;
        mass += dm;
        first += dm * x;
        second += dm * x * x;
        prev = *y;
    }
    if mass.abs() < 1e-12 {
        return (mass, 0.0, 0.0);
    }
    let centroid = first / mass;
    (mass, centroid, second / mass - centroid * centroid)
}

/// The corner's width: its rise's variance, samples^2.
fn variance(c: &[f64]) -> f64 {
    moments(c).2
}

/// Shifts the shape `c` (0 to 1) by whole samples so that its centroid (of the rise) sits
/// near the window's middle, filling with 0 before and 1 after, once it has drifted an
/// eighth of the window away: the period adjusts to where the corner is, so only the shape
/// carries from one period to the next (and a shift every period would dither).
fn recentre(c: &mut [f64]) {
    let w = c.len();
    let (mass, centroid, _) = moments(c);
    if mass.abs() < 1e-12 {
        return;
    }
    let off = centroid - (w / 2) as f64;
    if off.abs() < (w / 8) as f64 {
        return;
    }
    let shift = off.round() as isize;
    let k = shift.unsigned_abs().min(w);
    if shift > 0 {
        c.copy_within(k.., 0);
        c[w - k..].fill(1.0);
    } else {
        c.copy_within(..w - k, k);
        c[..k].fill(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::friction::HyperbolicFriction;
    use crate::dsp::waveguide::StringSpec;

    /// A cello D string with quality factors `q1` at its fundamental and `q_hi` at ten
    /// times it, stopped open and bowed at beta 0.1, 48 kHz.
    fn cello_d(q1: f64, q_hi: f64, inharmonicity: f64) -> WaveguideString {
        let spec = StringSpec {
            open_hz: 146.83,
            z0_kg_per_s: 0.506,
            inharmonicity_open: inharmonicity,
            q1,
            q_hi,
        };
        let mut s = WaveguideString::new(spec, 48_000.0, 60.0);
        s.stop_at(146.83);
        s.set_bow_position(0.1);
        s
    }

    /// The predicted slip fraction at `ratio` of Schelleng's `F_max` (v_b 0.1 m/s, the
    /// hyperbolic law's 0.4 and 0.2).
    fn at(string: &WaveguideString, ratio: f64) -> Option<f64> {
        let f_max = 2.0 * 0.506 * 0.1 / (string.effective_beta() * 0.2);
        let bow = BowInput {
            velocity_m_per_s: 0.1,
            normal_force_n: ratio * f_max,
        };
        predicted_slip_fraction(string, &mut HyperbolicFriction::default(), bow)
    }

    #[test]
    fn a_nearly_lossless_stiffless_loop_keeps_raman_s_slip_fraction() {
        // Q of 10^9 at every partial and no stiffness: the loop hardly rounds the corner,
        // so the slip lasts beta of the period at any force, to within one sample of the
        // period (the half-jump instants fall on whole samples).
        let s = cello_d(1e9, 1e9, 0.0);
        let sample = 1.0 / s.loop_samples();
        for ratio in [0.01, 0.05, 0.3] {
            let sf = at(&s, ratio).expect("a sharp corner is released and captured");
            assert!(
                (sf - s.effective_beta()).abs() <= sample + 1e-12,
                "at {ratio} F_max: {sf} against beta {}",
                s.effective_beta()
            );
        }
    }

    #[test]
    fn the_predicted_slip_lengthens_as_the_bow_force_falls() {
        // Cremer: the bow sharpens the corner in proportion to its force, the loop rounds
        // it by the same amount each period, so a lighter bow leaves a rounder corner and a
        // longer half-jump slip. Compared a factor of two in force apart, where the slip
        // changes by several samples (more than the one-sample rounding of the measure).
        let s = cello_d(500.0, 250.0, 1.5e-4);
        let ratios = [0.005, 0.01, 0.02, 0.05, 0.3];
        let sf: Vec<f64> = ratios
            .iter()
            .map(|r| at(&s, *r).expect("Helmholtz motion is predicted"))
            .collect();
        for (pair, r) in sf.windows(2).zip(ratios.windows(2)) {
            assert!(pair[0] > pair[1], "{sf:?} at {ratios:?}: {r:?}");
        }
        // Near the top of the window the corner is sharp: Raman's beta within 10 %.
        let beta = s.effective_beta();
        assert!((sf[4] - beta).abs() <= 0.1 * beta, "{sf:?}");
    }

    #[test]
    fn the_predicted_period_keeps_the_zero_mean_velocity_of_a_fixed_string() {
        // A string fixed at both ends has no mean velocity, so neither may the period the
        // prediction composes where the corner is as wide as the slip (a light bow on a
        // lossy string, the two corners overlapping). Near the top of the window the
        // corners are sharp and apart, and the period's mean is what the passes' timing on
        // whole samples leaves (about a sample and a half of the slip's corner height over
        // the period): overlapping corners may not add to it.
        let s = cello_d(500.0, 125.0, 1.5e-4);
        let f_max = 2.0 * 0.506 * 0.1 / (s.effective_beta() * 0.2);
        let mean_at = |ratio: f64| {
            let bow = BowInput {
                velocity_m_per_s: 0.1,
                normal_force_n: ratio * f_max,
            };
            let v = predicted_period(&s, &mut HyperbolicFriction::default(), bow, SETTLED)
                .expect("Helmholtz motion is predicted");
            v.iter().sum::<f64>() / v.len() as f64
        };
        let apart = mean_at(0.3).abs();
        for ratio in [0.005, 0.01] {
            let overlapping = mean_at(ratio);
            assert!(
                overlapping.abs() <= apart,
                "at {ratio} F_max the mean is {overlapping} m/s, at 0.3 F_max {apart}"
            );
        }
    }

    #[test]
    fn a_lossier_string_rounds_the_corner_more() {
        // Half the high-frequency Q loses twice as much of the corner's upper partials each
        // period: at the same force the corner settles rounder and the slip is longer.
        let (shipped, lossy) = (cello_d(500.0, 250.0, 1.5e-4), cello_d(500.0, 125.0, 1.5e-4));
        for ratio in [0.01, 0.05] {
            let (a, b) = (at(&shipped, ratio).unwrap(), at(&lossy, ratio).unwrap());
            assert!(b > a, "at {ratio} F_max: Q_hi 250 {a}, Q_hi 125 {b}");
        }
    }
}
