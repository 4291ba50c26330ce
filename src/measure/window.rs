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

use crate::dsp::intonation::TunedModel;
use crate::dsp::vocabulary::{InstrumentKind, STRINGS};
use std::f64::consts::PI;
use std::sync::OnceLock;

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

/// Bow positions the window was measured at: the playing-space map's grid, the
/// defaults' 0.1, and 0.15, where the Dynamics Guard takes the bow at the softest.
pub const MEASURED_BETAS: [f64; 6] = [0.05, 0.08, 0.1, 0.12, 0.15, 0.18];

/// The first line of the measured window's file.
pub const MEASURED_WINDOW_HEADER: &str = "model,instrument,string,beta,low,high,held,regimes";

/// The window each model plays, measured (`colophony bench window`, shipped as
/// `assets/measured-window.csv`; method in docs/playing-space.md): for every model,
/// instrument, string and beta of [`MEASURED_BETAS`], the lowest and highest share of
/// Schelleng's `F_max` ([`SchellengWindow::max_force_n`] with the model's coefficients)
/// that hold Helmholtz motion once it is going, or none where no force held it.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredWindows {
    shares: [[[[Option<(f64, f64)>; MEASURED_BETAS.len()]; STRINGS]; InstrumentKind::COUNT];
        TunedModel::COUNT],
}

impl MeasuredWindows {
    /// Reads the file's text: the header, then one line a (model, instrument, string,
    /// beta), every one present once.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut lines = text.lines();
        if lines.next().map(str::trim) != Some(MEASURED_WINDOW_HEADER) {
            return Err(format!(
                "the measured window must begin with '{MEASURED_WINDOW_HEADER}'"
            ));
        }
        let mut shares =
            [[[[None; MEASURED_BETAS.len()]; STRINGS]; InstrumentKind::COUNT]; TunedModel::COUNT];
        let mut seen =
            [[[[false; MEASURED_BETAS.len()]; STRINGS]; InstrumentKind::COUNT]; TunedModel::COUNT];
        for (n, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
            let bad = |what: &str| format!("measured window, line {}: {what}", n + 2);
            let f: Vec<&str> = line.split(',').map(str::trim).collect();
            if f.len() < 6 {
                return Err(bad("fewer than six fields"));
            }
            let model = TunedModel::from_name(f[0]).ok_or_else(|| bad("unknown model"))?;
            let kind = InstrumentKind::from_name(f[1]).ok_or_else(|| bad("unknown instrument"))?;
            let string: usize = f[2]
                .parse()
                .ok()
                .filter(|&s| s < STRINGS)
                .ok_or_else(|| bad("string not 0-3"))?;
            let beta: f64 = f[3].parse().map_err(|_| bad("beta not a number"))?;
            let b = MEASURED_BETAS
                .iter()
                .position(|&g| (g - beta).abs() < 1e-9)
                .ok_or_else(|| bad("beta not one of the measured ones"))?;
            let window = match (f[4], f[5]) {
                ("", "") => None,
                (lo, hi) => {
                    let lo: f64 = lo.parse().map_err(|_| bad("low share not a number"))?;
                    let hi: f64 = hi.parse().map_err(|_| bad("high share not a number"))?;
                    if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
                        return Err(bad("shares must satisfy 0 < low <= high"));
                    }
                    Some((lo, hi))
                }
            };
            let slot = &mut seen[model.row()][kind.index()][string][b];
            if *slot {
                return Err(bad("a row given twice"));
            }
            *slot = true;
            shares[model.row()][kind.index()][string][b] = window;
        }
        if seen.iter().flatten().flatten().flatten().any(|s| !s) {
            return Err("the measured window lacks a (model, instrument, string, beta)".into());
        }
        Ok(Self { shares })
    }

    /// The lowest and highest share of `F_max` that hold the motion on string `string`
    /// of `kind` bowed at `beta` with `model`: between two measured positions
    /// interpolated in the logarithms of beta and of the shares; beyond them, the nearest
    /// one's. `None` where the nearest measured position found no window (or where one of
    /// the two around `beta` found none).
    pub fn shares(
        &self,
        model: TunedModel,
        kind: InstrumentKind,
        string: usize,
        beta: f64,
    ) -> Option<(f64, f64)> {
        let row = &self.shares[model.row()][kind.index()][string.min(STRINGS - 1)];
        let last = MEASURED_BETAS.len() - 1;
        if !(beta > MEASURED_BETAS[0]) {
            return row[0];
        }
        if beta >= MEASURED_BETAS[last] {
            return row[last];
        }
        let k = MEASURED_BETAS.iter().rposition(|&g| g <= beta).unwrap_or(0);
        if beta == MEASURED_BETAS[k] {
            return row[k];
        }
        let (a, b) = (row[k]?, row[k + 1]?);
        let t = (beta / MEASURED_BETAS[k]).ln() / (MEASURED_BETAS[k + 1] / MEASURED_BETAS[k]).ln();
        let mix = |x: f64, y: f64| (x.ln() * (1.0 - t) + y.ln() * t).exp();
        Some((mix(a.0, b.0), mix(a.1, b.1)))
    }
}

/// The shipped measured window (`assets/measured-window.csv`), parsed on first use; the
/// editor reads it, the audio thread never does.
pub fn measured() -> &'static MeasuredWindows {
    static TABLE: OnceLock<MeasuredWindows> = OnceLock::new();
    TABLE.get_or_init(|| {
        MeasuredWindows::parse(include_str!("../../assets/measured-window.csv"))
            .expect("the shipped measured window parses (tested)")
    })
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

    /// A measured window's text with every row `low, high` but the ones `set` gives.
    fn windows_text(set: &[(&str, &str, usize, f64, &str)]) -> String {
        let mut text = format!("{MEASURED_WINDOW_HEADER}\n");
        for model in TunedModel::all() {
            for kind in InstrumentKind::ALL {
                for string in 0..STRINGS {
                    for beta in MEASURED_BETAS {
                        let shares = set
                            .iter()
                            .find(|r| {
                                (r.0, r.1, r.2, r.3) == (model.name(), kind.name(), string, beta)
                            })
                            .map_or("0.1,0.5", |r| r.4);
                        text += &format!(
                            "{},{},{string},{beta},{shares},,\n",
                            model.name(),
                            kind.name()
                        );
                    }
                }
            }
        }
        text
    }

    #[test]
    fn the_shipped_measured_window_parses() {
        // What it holds is tested against the model in lab/tests/measured_window.rs.
        let text = include_str!("../../assets/measured-window.csv");
        assert_eq!(MeasuredWindows::parse(text).as_ref(), Ok(measured()));
    }

    #[test]
    fn the_measured_window_interpolates_in_log_beta_and_keeps_the_nearest_beyond() {
        let text = windows_text(&[
            ("hyperbolic", "cello", 2, 0.12, "0.02,0.25"),
            ("hyperbolic", "cello", 2, 0.15, "0.08,1"),
            ("hyperbolic", "cello", 2, 0.18, ","),
        ]);
        let m = MeasuredWindows::parse(&text).unwrap();
        let law = TunedModel::Point(crate::dsp::friction::FrictionModel::Hyperbolic);
        let at = |beta: f64| m.shares(law, InstrumentKind::Cello, 2, beta);
        assert_eq!(at(0.12), Some((0.02, 0.25)));
        // The geometric middle of 0.12 and 0.15 takes the geometric middle of the shares.
        let (lo, hi) = at((0.12f64 * 0.15).sqrt()).unwrap();
        assert!(
            (lo - 0.04).abs() < 1e-12 && (hi - 0.5).abs() < 1e-12,
            "{lo} {hi}"
        );
        // Beyond the grid the nearest row; toward a row with no window, none.
        assert_eq!(at(0.02), Some((0.1, 0.5)));
        assert_eq!(at(0.3), None);
        assert_eq!(at(0.16), None);
        // At a measured position, that row, whatever its neighbour holds.
        assert_eq!(at(0.15), Some((0.08, 1.0)));
    }

    #[test]
    fn a_broken_measured_window_is_refused_with_its_line() {
        let good = windows_text(&[]);
        assert!(MeasuredWindows::parse(&good).is_ok());
        let missing: String = good.lines().take(10).map(|l| format!("{l}\n")).collect();
        assert!(MeasuredWindows::parse(&missing)
            .unwrap_err()
            .contains("lacks"));
        let twice = format!("{good}hyperbolic,cello,2,0.12,0.1,0.5,,\n");
        assert!(MeasuredWindows::parse(&twice)
            .unwrap_err()
            .contains("twice"));
        for bad in [
            "hyperbolic,cello,2,0.12,0.5,0.1,,",
            "hyperbolic,cello,2,0.1,0.1,0.5,,",
            "nobody,cello,2,0.12,0.1,0.5,,",
            "hyperbolic,cello,7,0.12,0.1,0.5,,",
            "hyperbolic,cello,2,0.12,x,0.5,,",
        ] {
            let text = good.replacen("hyperbolic,cello,2,0.12,0.1,0.5,,", bad, 1);
            let err = MeasuredWindows::parse(&text).unwrap_err();
            assert!(err.contains("line"), "{bad}: {err}");
        }
        assert!(MeasuredWindows::parse("").is_err());
    }
}
