//! Schelleng's window: the bow forces between which a string plays Helmholtz motion, for
//! one string and bow position. Framework-free: the editor draws it, the performer's tests
//! and the tools measure against it.
//!
//! **The limits** (docs/literature-values.md §1.6). For a bow at `beta` moving at `v_b` on a
//! string of impedance `Z0`, with static and dynamic friction coefficients `mu_s`, `mu_d`,
//! Helmholtz motion lives between
//!
//! * `F_max = 2 Z0 v_b / (beta (mu_s - mu_d))`, and
//! * `F_min = Z0^2 v_b / (2 R beta^2 (mu_s - mu_d))` for a dashpot bridge of resistance `R`.
//!
//! **Choice of `R`.** The waveguide strings have a rigid bridge and lump all their losses in
//! one reflection filter whose loop gain at the fundamental is `exp(-pi / Q1)`. A dashpot
//! bridge reflects velocity waves with `-(R - Z0) / (R + Z0) ~ -(1 - 2 Z0 / R)`, so the dashpot
//! that loses as much per period as the model does is `R = 2 Q1 Z0 / pi` ([`bridge_resistance`]):
//! about 161 kg/s for the cello D string (`Z0` 0.506 kg/s, `Q1` 500). Then
//! `F_min = pi Z0 v_b / (4 Q1 beta^2 (mu_s - mu_d))`; the violin D string's lower
//! coefficient `F_min beta^2 / v_b` is 2.4 g/s, inside the measured 1.8-7 g/s that §1.6 quotes
//! (Schoonderwaldt, Guettler and Askenfelt 2008). `mu_s` 0.4 and `mu_d` 0.2 are the defaults
//! of the hyperbolic friction law (and of the bristle models).

use crate::dsp::vocabulary::{InstrumentKind, STRINGS};
use std::f64::consts::PI;

/// Static friction coefficient of the hyperbolic law's defaults.
pub const MU_S: f64 = 0.4;
/// Dynamic (fast sliding) friction coefficient of the hyperbolic law's defaults.
pub const MU_D: f64 = 0.2;

/// Resistance of the dashpot bridge that loses as much per period as a string of impedance
/// `z0` (kg/s) with fundamental quality factor `q1`: `R = 2 Q1 Z0 / pi`, kg/s (see the
/// module notes).
pub fn bridge_resistance(z0_kg_per_s: f64, q1: f64) -> f64 {
    2.0 * q1 * z0_kg_per_s / PI
}

/// The String Weight reference (kg/s) and the friction coefficients (`mu_s`, `mu_d`) of the
/// window a model plays: paper A's laws (0.2 kg/s, [`MU_S`], [`MU_D`]) or paper B's thermal
/// bow (`thermal`: 1 kg/s, the cold and hot ends of its `mu(T)`).
pub fn model_coefficients(thermal: bool) -> (f64, f64, f64) {
    if thermal {
        let p = crate::dsp::thermal::ThermalParams::default();
        (
            crate::dsp::thermal_instrument::THERMAL_WEIGHT_REFERENCE_Z0,
            p.mu_cold,
            p.mu_hot,
        )
    } else {
        (crate::dsp::vocabulary::WEIGHT_REFERENCE_Z0, MU_S, MU_D)
    }
}

/// Schelleng's bow-force limits for one string and bow position. Velocities may be signed:
/// the limits depend on the bow speed `|v_b|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SchellengWindow {
    /// Characteristic impedance of the string, kg/s.
    pub z0_kg_per_s: f64,
    /// Dashpot bridge resistance, kg/s.
    pub bridge_r_kg_per_s: f64,
    /// Bow distance from the bridge over the vibrating length.
    pub beta: f64,
    pub mu_s: f64,
    pub mu_d: f64,
}

impl SchellengWindow {
    /// The window of the string that plays `note` on `kind`, bowed at `beta`, with the
    /// bridge resistance from the string's own `Q1` and the default friction
    /// coefficients. `None` if the instrument cannot play the note.
    pub fn for_note(kind: InstrumentKind, note: u8, beta: f64) -> Option<Self> {
        Some(Self::for_string(kind, kind.string_for_note(note)?, beta))
    }

    /// The window of string `string` of `kind` (0 = the lowest; clamped to the highest),
    /// as [`Self::for_note`] (a stopped note's window is its open string's).
    pub fn for_string(kind: InstrumentKind, string: usize, beta: f64) -> Self {
        let spec = kind.strings()[string.min(STRINGS - 1)];
        Self {
            z0_kg_per_s: spec.z0_kg_per_s,
            bridge_r_kg_per_s: bridge_resistance(spec.z0_kg_per_s, spec.q1),
            beta,
            mu_s: MU_S,
            mu_d: MU_D,
        }
    }

    /// The window of string `string` of `kind` at `beta` as the plugin bows it: with the
    /// friction coefficients of paper A's laws or of paper B's thermal bow (`thermal`,
    /// [`model_coefficients`]) and, with String Weight on (`weighted`), in the force
    /// parameter's units. What the editor draws, the playing-space map measures against
    /// and the performer's catch aims at.
    pub fn for_model(
        kind: InstrumentKind,
        string: usize,
        beta: f64,
        thermal: bool,
        weighted: bool,
    ) -> Self {
        let (reference, mu_s, mu_d) = model_coefficients(thermal);
        let window = Self {
            mu_s,
            mu_d,
            ..Self::for_string(kind, string, beta)
        };
        if weighted {
            window.seen_through_weight(kind.string_weight_for(string, reference))
        } else {
            window
        }
    }

    /// The window in units of the force parameter when the string is bowed with `weight`
    /// times it ([`crate::dsp::vocabulary::InstrumentKind::string_weight`]): both limits
    /// divided by `weight` (Z0 and R divided by it).
    pub fn seen_through_weight(self, weight: f64) -> Self {
        Self {
            z0_kg_per_s: self.z0_kg_per_s / weight,
            bridge_r_kg_per_s: self.bridge_r_kg_per_s / weight,
            ..self
        }
    }

    /// Maximum bow force for Helmholtz motion, N: `2 Z0 |v_b| / (beta (mu_s - mu_d))`.
    pub fn max_force_n(&self, v_b: f64) -> f64 {
        2.0 * self.z0_kg_per_s * v_b.abs() / (self.beta * (self.mu_s - self.mu_d))
    }

    /// Minimum bow force for Helmholtz motion, N:
    /// `Z0^2 |v_b| / (2 R beta^2 (mu_s - mu_d))`.
    pub fn min_force_n(&self, v_b: f64) -> f64 {
        self.z0_kg_per_s * self.z0_kg_per_s * v_b.abs()
            / (2.0 * self.bridge_r_kg_per_s * self.beta * self.beta * (self.mu_s - self.mu_d))
    }

    /// Whether force `f` at velocity `v_b` lies inside the window.
    pub fn contains(&self, v_b: f64, f: f64) -> bool {
        f >= self.min_force_n(v_b) && f <= self.max_force_n(v_b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cello_d(beta: f64) -> SchellengWindow {
        SchellengWindow::for_note(InstrumentKind::Cello, 50, beta).unwrap()
    }

    #[test]
    fn schelleng_max_matches_paper_a_cello_d() {
        // docs/literature-values.md §1.6: Z0 0.506, v_b 0.1, beta 0.1, delta mu 0.2 gives about 5.1 N.
        let w = cello_d(0.1);
        assert_eq!(w.z0_kg_per_s, 0.506);
        // 2 x 0.506 x 0.1 / (0.1 x 0.2) = 5.06 N: rounding only.
        assert!((w.max_force_n(0.1) - 5.06).abs() < 1e-9);
        // Paper A's 1.1 N plays Helmholtz motion.
        assert!(w.contains(0.1, 1.1));
    }

    #[test]
    fn bridge_resistance_loses_what_the_string_loses_per_period() {
        let z0 = 0.506;
        let r = bridge_resistance(z0, 500.0);
        // 2 Q1 Z0 / pi = 161.066 kg/s, written to two decimals.
        assert!((r - 161.06).abs() < 0.01, "R {r}");
        // Dashpot reflection magnitude equals the loop gain exp(-pi / Q1) to first order.
        let reflection = (r - z0) / (r + z0);
        // (1 - e) / (1 + e), e = pi / (2 Q1), and exp(-pi / Q1) agree to second order;
        // they differ by about 2e-8.
        assert!((reflection - (-PI / 500.0f64).exp()).abs() < 1e-4);
    }

    #[test]
    fn schelleng_max_scales_as_velocity_over_beta() {
        let w = cello_d(0.1);
        let base = w.max_force_n(0.1);
        // Exact ratios but for f64 rounding.
        assert!((w.max_force_n(0.3) / base - 3.0).abs() < 1e-12);
        assert!((cello_d(0.05).max_force_n(0.1) / base - 2.0).abs() < 1e-12);
        assert!((cello_d(0.2).max_force_n(0.4) / base - 2.0).abs() < 1e-12);
    }

    #[test]
    fn schelleng_min_scales_as_velocity_over_beta_squared() {
        let w = cello_d(0.1);
        let base = w.min_force_n(0.1);
        // Exact ratios but for f64 rounding.
        assert!((w.min_force_n(0.3) / base - 3.0).abs() < 1e-12);
        assert!((cello_d(0.05).min_force_n(0.1) / base - 4.0).abs() < 1e-12);
        assert!((cello_d(0.2).min_force_n(0.4) / base - 1.0).abs() < 1e-12);
    }

    #[test]
    fn schelleng_limits_ignore_the_bow_direction() {
        let w = cello_d(0.1);
        assert_eq!(w.max_force_n(-0.2), w.max_force_n(0.2));
        assert_eq!(w.min_force_n(-0.2), w.min_force_n(0.2));
        assert_eq!(w.max_force_n(0.0), 0.0);
    }

    #[test]
    fn schelleng_min_is_below_max_over_the_playing_range() {
        for kind in InstrumentKind::ALL {
            let (lo, hi) = kind.note_range();
            for note in lo..=hi {
                for beta in [0.02, 0.1, 0.5] {
                    let w = SchellengWindow::for_note(kind, note, beta).unwrap();
                    assert!(w.min_force_n(0.1) < w.max_force_n(0.1));
                }
            }
        }
    }

    #[test]
    fn schelleng_lower_coefficient_is_in_the_measured_range_on_violin_d() {
        // §1.6: c_lower = F_min beta^2 / v_b measured at 1.8-7 g/s on a violin D string.
        let w = SchellengWindow::for_note(InstrumentKind::Violin, 62, 0.1).unwrap();
        let c_lower = w.min_force_n(0.1) * 0.1 * 0.1 / 0.1;
        assert!((0.0018..0.007).contains(&c_lower), "c_lower {c_lower} kg/s");
    }

    #[test]
    fn schelleng_uses_the_string_that_plays_the_note() {
        // Cello A3 (57) and above go to the A string, G2 to the G string.
        assert_eq!(cello_d(0.1).z0_kg_per_s, 0.506);
        let a = SchellengWindow::for_note(InstrumentKind::Cello, 60, 0.1).unwrap();
        assert_eq!(a.z0_kg_per_s, 0.504);
        let g = SchellengWindow::for_note(InstrumentKind::Cello, 44, 0.1).unwrap();
        assert_eq!(g.z0_kg_per_s, 0.833);
        assert!(SchellengWindow::for_note(InstrumentKind::Violin, 40, 0.1).is_none());
    }
}
