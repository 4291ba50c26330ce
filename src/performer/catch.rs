//! The catch: a separate note asked for in the lower half of Schelleng's window lands
//! pressed into its upper half until the string is caught in Helmholtz motion, then eases
//! to the asked force.
//!
//! **Why.** Below the window's middle Helmholtz motion is stable once it is there, but an
//! attack rarely finds it: the string falls into double or irregular slipping, which the
//! light force holds as well. On the playing-space map (docs/playing-space.md), bowed at
//! `F_max / 2` until the slips come once a period and then lowered, two thirds to three
//! quarters of the point laws' `2 F_min` cells keep one slip a period, where a landing at
//! those forces finds it in none. A player does the same: the bow bites the string at the
//! start of a note and the arm then lightens it (the pre-pressure of a forte attack,
//! Guettler and Askenfelt's attacks, literature-values.md §1.6).
//!
//! **What.** For a separate note of velocity above mezzo (where the landing accent starts,
//! [`super::stroke`]) asked lighter than the catching force (against `F_max` at the asked
//! bow speed and position), the force is raised to the catching force, [`CATCH_LEVEL`] of
//! `F_max` ([`LIGHT_CATCH_LEVEL`] where only light notes are caught; at most the force
//! parameter's top), and held there until [`SlipWatch`] hears
//! [`crate::measure::regime::HELMHOLTZ_SPANS`] spans of one slip a period (or for
//! [`CATCH_HOLD_MAX_S`] at most), then falls geometrically to the asked force over
//! [`CATCH_FALL_S`]. On the hyperbolic, LuGre and elasto-plastic laws every such note is
//! caught, the defaults (`F_max / 2`) too: pressed harder, the string finds one slip a
//! period sooner (a bite, as a player's martelé). The static (Stribeck) law and paper B's
//! thermal bow catch at `F_max / 2`, and only notes lighter than [`CATCH_BELOW_DEFAULTS`]
//! of where their defaults sit: caught harder, a static-law note was found to stay 32
//! cents flat after the catch (docs/playing-space.md, "The performer's catch"). The window
//! is the one the editor draws ([`SchellengWindow::for_model`]), in the force parameter's
//! units: `F_max = 2 Z v_b / (beta (mu_s - mu_d))` with the string's `Z0` (over its String
//! Weight when that is on) and the model's friction coefficients. Helmholtz motion's amplitude is `v_b / beta`
//! whatever the force, so a note the catch brings into that motion sounds as loud as one
//! that found it alone.

use crate::dsp::friction::FrictionModel;
use crate::dsp::vocabulary::{BowControl, InstrumentKind, MAX_WEIGHTED_FORCE_N};
use crate::measure::contact::ContactSample;
use crate::measure::regime::SlipWatch;
use crate::measure::window::SchellengWindow;

/// Whether a separate note of velocity `velocity` (0..=1, a
/// [`super::stroke::velocity_step`]) is caught: above mezzo, where the landing accent
/// starts.
pub fn catches(velocity: f64) -> bool {
    velocity > 64.0 / 127.0
}

/// The force every note is caught with ([`CatchRule::Every`]), a fraction of the window's
/// `F_max`. Of 0.5, 0.65, 0.75, 0.8 and 0.85, 0.75-0.85 make the most cells of the map
/// speak within 50 ms, and 0.8 keeps the window's Helmholtz motion (docs/playing-space.md,
/// "The performer's catch").
pub const CATCH_LEVEL: f64 = 0.8;
/// The force light notes are caught with ([`CatchRule::Light`]), a fraction of `F_max`: of
/// 0.35, 0.5 and 0.7 it catches the most notes in one slip a period.
pub const LIGHT_CATCH_LEVEL: f64 = 0.5;
/// [`CatchRule::Light`] catches a note where its asked force lies lower in the window
/// than this share of where the model's defaults sit (the default bow with String Weight
/// on: `F_max / 2` for paper A's laws, `F_max / 6.7` for paper B's,
/// [`CatchRule::engage_ratio`]): the defaults themselves are not caught.
pub const CATCH_BELOW_DEFAULTS: f64 = 0.9;

/// The longest the catching force is held, s (the map's).
pub const CATCH_HOLD_MAX_S: f64 = 0.24;
/// How long the force takes to fall to the asked one once caught, s (the map's).
pub const CATCH_FALL_S: f64 = 0.06;

/// Which notes a model's bow catches, and how hard.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CatchRule {
    /// Every note asked lighter than [`CATCH_LEVEL`] of `F_max`, at that force.
    Every,
    /// Notes lighter than [`CATCH_BELOW_DEFAULTS`] of where the defaults sit, at
    /// [`LIGHT_CATCH_LEVEL`]; on paper B's thermal bow (`thermal`) or a point law.
    Light { thermal: bool },
}

impl CatchRule {
    /// The rule for a point law (`Some`) or paper B's thermal bow (`None`).
    pub fn for_law(point_law: Option<FrictionModel>) -> Self {
        match point_law {
            None => CatchRule::Light { thermal: true },
            Some(FrictionModel::Stribeck) => CatchRule::Light { thermal: false },
            Some(_) => CatchRule::Every,
        }
    }

    /// The catching force over `F_max`.
    pub fn level(self) -> f64 {
        match self {
            CatchRule::Every => CATCH_LEVEL,
            CatchRule::Light { .. } => LIGHT_CATCH_LEVEL,
        }
    }

    /// The asked force over `F_max` below which a note is caught: the catching force
    /// itself, or where the default bow sits in the model's window with String Weight on
    /// (the same on every string: both scale with `Z0`), times [`CATCH_BELOW_DEFAULTS`].
    pub fn engage_ratio(self) -> f64 {
        let thermal = match self {
            CatchRule::Every => return CATCH_LEVEL,
            CatchRule::Light { thermal } => thermal,
        };
        let bow = BowControl::default();
        let window =
            SchellengWindow::for_model(InstrumentKind::Violin, 0, bow.position_beta, thermal, true);
        CATCH_BELOW_DEFAULTS * bow.force_n / window.max_force_n(bow.velocity_m_per_s)
    }
}

/// A catch in progress (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Catch {
    /// The note's window as the plugin bows it (its `beta` is the bow's, sample by sample).
    window: SchellengWindow,
    /// The catching force over `F_max`.
    level: f64,
    /// The asked force over `F_max` below which the note is caught.
    engage_ratio: f64,
    watch: SlipWatch,
    /// Samples of holding left; once 0 the force falls.
    hold_left: u32,
    /// How far the fall has gone (0..=1), and its step per sample.
    fall: f64,
    fall_step: f64,
    /// Whether the first bow has been looked at (a note already near the window's top is
    /// not caught at all).
    engaged: bool,
}

impl Catch {
    /// A catch for a note of fundamental `f0_hz` at `sample_rate_hz` in `window`
    /// ([`SchellengWindow::for_model`]) by `rule`; `None` for values that are not finite
    /// and positive.
    pub fn new(
        window: SchellengWindow,
        rule: CatchRule,
        f0_hz: f64,
        sample_rate_hz: f64,
    ) -> Option<Self> {
        let usable = |x: f64| x.is_finite() && x > 0.0;
        if !(usable(window.max_force_n(1.0)) && usable(f0_hz) && usable(sample_rate_hz)) {
            return None;
        }
        Some(Self {
            window,
            level: rule.level(),
            engage_ratio: rule.engage_ratio(),
            watch: SlipWatch::new(sample_rate_hz as f32, f0_hz as f32),
            hold_left: (CATCH_HOLD_MAX_S * sample_rate_hz).round() as u32,
            fall: 0.0,
            fall_step: 1.0 / (CATCH_FALL_S * sample_rate_hz).max(1.0),
            engaged: false,
        })
    }

    /// The force to play this sample for an asked force `force_n` with the bow at
    /// `speed_m_per_s` and `beta` (the asked bow, not its attack's ramp), or `None` once
    /// the catch is over (then it stays over).
    #[inline]
    pub fn force(&mut self, force_n: f64, speed_m_per_s: f64, beta: f64) -> Option<f64> {
        let level = self.level
            * SchellengWindow {
                beta,
                ..self.window
            }
            .max_force_n(speed_m_per_s);
        // Never more than the force parameter's top, as String Weight never bows harder.
        let top = level.min(MAX_WEIGHTED_FORCE_N);
        if !self.engaged {
            self.engaged = true;
            if !(level.is_finite() && force_n < self.engage_ratio / self.level * level) {
                self.hold_left = 0;
                self.fall = 1.0;
                return None;
            }
        }
        if self.hold_left > 0 {
            self.hold_left -= 1;
            return Some(top.max(force_n));
        }
        self.fall += self.fall_step;
        if self.fall >= 1.0 || !(top > force_n && force_n > 0.0) {
            return None;
        }
        Some(top * (force_n / top).powf(self.fall))
    }

    /// Listens to the string (the contact probe of the sample just played, with the bow
    /// that played it): once the slips come once a period the hold ends.
    #[inline]
    pub fn observe(&mut self, contact: &ContactSample) {
        if self.hold_left > 0 && self.watch.observe(contact) {
            self.hold_left = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 48_000.0;

    /// A contact sample of a bow at 0.1 m/s: sticking, or slipping at `v` m/s.
    fn sample(v: Option<f64>) -> ContactSample {
        let s = v.unwrap_or(0.1) as f32;
        ContactSample {
            string_velocity: s,
            relative_velocity: s - 0.1,
            mu: 0.3,
        }
    }

    /// Cello D's window for paper A's laws, unweighted: `F_max` 5.06 N at 0.1 m/s and beta
    /// 0.1.
    fn d3() -> SchellengWindow {
        SchellengWindow::for_model(InstrumentKind::Cello, 2, 0.1, false, false)
    }

    fn catch() -> Catch {
        Catch::new(d3(), CatchRule::Every, 146.83, FS).unwrap()
    }

    /// [`CATCH_LEVEL`] of `F_max` at 0.1 m/s and beta 0.1.
    fn catching() -> f64 {
        CATCH_LEVEL * d3().max_force_n(0.1)
    }

    /// The defaults sit at `F_max / 2` of paper A's laws (String Weight against 0.2
    /// kg/s, `mu_s - mu_d` 0.2) and at `F_max / 6.7` of paper B's (1 kg/s, 0.3); the
    /// hyperbolic, LuGre and elasto-plastic laws catch every note lighter than the
    /// catching force.
    #[test]
    fn the_defaults_sit_where_the_models_weighting_puts_them() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        let light = |law| CatchRule::for_law(law).engage_ratio();
        assert!(close(light(Some(FrictionModel::Stribeck)), 0.9 * 0.5));
        assert!(close(light(None), 0.9 * 0.15));
        for law in [
            FrictionModel::Hyperbolic,
            FrictionModel::LuGre,
            FrictionModel::ElastoPlastic,
        ] {
            assert_eq!(CatchRule::for_law(Some(law)), CatchRule::Every);
        }
        assert!(close(CatchRule::Every.engage_ratio(), CATCH_LEVEL));
    }

    #[test]
    fn a_note_asked_at_the_catching_force_or_above_is_not_caught() {
        let mut c = catch();
        assert_eq!(c.force(catching(), 0.1, 0.1), None);
        assert_eq!(c.force(0.1, 0.1, 0.1), None, "once over, it stays over");
    }

    /// The defaults (`F_max / 2` on paper A's laws) are caught by [`CatchRule::Every`]; on
    /// paper B's thermal bow a note at its defaults is not.
    #[test]
    fn the_defaults_are_caught_where_every_note_is() {
        let mut point = catch();
        assert_eq!(
            point.force(0.5 * d3().max_force_n(0.1), 0.1, 0.1),
            Some(catching())
        );
        let thermal_window = SchellengWindow::for_model(InstrumentKind::Cello, 2, 0.1, true, true);
        let mut thermal = Catch::new(thermal_window, CatchRule::for_law(None), 146.83, FS).unwrap();
        let defaults = BowControl::default();
        assert_eq!(
            thermal.force(
                defaults.force_n,
                defaults.velocity_m_per_s,
                defaults.position_beta
            ),
            None
        );
    }

    /// A light note is pressed at the catching force until one slip a period has repeated
    /// four times, then falls to the asked force in [`CATCH_FALL_S`], never below it.
    #[test]
    fn a_light_note_is_held_at_the_catching_force_until_helmholtz_motion_then_eased() {
        let mut c = catch();
        let period = (FS / 146.83).round() as usize;
        let mut forces = Vec::new();
        // Slips a period apart, each of a tenth of the period: the fifth (four spans)
        // begins at sample 4 periods.
        for i in 0..=4 * period {
            forces.push(c.force(0.2, 0.1, 0.1).unwrap());
            let slipping = i % period < period / 10;
            c.observe(&sample(slipping.then_some(-0.9)));
        }
        assert!(
            forces.iter().all(|&f| f == catching()),
            "held at the catching force"
        );
        let fall = (CATCH_FALL_S * FS) as usize;
        let rest: Vec<f64> = (0..2 * fall)
            .map_while(|_| c.force(0.2, 0.1, 0.1))
            .collect();
        assert!(
            rest.len() + 1 >= fall && rest.len() <= fall,
            "{}",
            rest.len()
        );
        assert!(rest.windows(2).all(|w| w[1] < w[0] && w[1] > 0.2));
    }

    /// A string that never settles is let go after [`CATCH_HOLD_MAX_S`].
    #[test]
    fn a_string_that_never_settles_is_let_go_after_the_longest_hold() {
        let mut c = catch();
        let period = (FS / 146.83).round() as usize;
        let hold = (CATCH_HOLD_MAX_S * FS) as usize;
        for i in 0..hold {
            assert_eq!(c.force(0.2, 0.1, 0.1), Some(catching()), "sample {i}");
            // Two slips a period.
            let slipping = i % (period / 2) < period / 20;
            c.observe(&sample(slipping.then_some(-0.9)));
        }
        assert!(c.force(0.2, 0.1, 0.1).unwrap() < catching());
    }

    /// A window whose `F_max / 2` lies above the force parameter's top (paper B's Figure
    /// 6 bow, unweighted on the cello's C string: 13.6 N) catches at the top, 10 N.
    #[test]
    fn the_catch_never_presses_harder_than_the_force_parameters_top() {
        let fig6 = SchellengWindow::for_model(InstrumentKind::Cello, 0, 0.07, true, false);
        let mut c = Catch::new(fig6, CatchRule::for_law(None), 65.4, FS).unwrap();
        assert_eq!(c.force(3.0, 0.15, 0.07), Some(MAX_WEIGHTED_FORCE_N));
    }

    #[test]
    fn bad_values_make_no_catch() {
        let nan = SchellengWindow {
            z0_kg_per_s: f64::NAN,
            ..d3()
        };
        assert!(Catch::new(nan, CatchRule::Every, 100.0, FS).is_none());
        assert!(Catch::new(d3(), CatchRule::Every, 0.0, FS).is_none());
        assert!(Catch::new(d3(), CatchRule::Every, 100.0, -1.0).is_none());
        let mut c = catch();
        assert_eq!(c.force(0.2, 0.1, 0.0), None, "beta 0: no window to aim at");
    }
}
