//! The gesture: what the player's controllers ask of the bow and the finger: dynamics (with
//! the window guard), the finger vibrato with its drift, and the factors the stroke and
//! the dynamics put on the bow each sample.

use super::midi::RPN_NULL;
use super::*;
use crate::dsp::fingering::DYNAMICS_INTONATION_STEP;

/// The dynamics' range: expression 0 (CC11, CC2 or channel pressure at 0) plays the bow
/// this many dB below expression 1 (the default, and the parameters' own bow). The
/// output falls by about nine tenths of the bow's fall (a slower bow's corners are
/// rounder: 30-33 dB on every violin, viola and cello note of the point laws, by the
/// dynamics sweep, `lab/tests/dynamics_sweep.rs`), a cellist's pp to ff.
pub const DYNAMICS_RANGE_DB: f64 = 35.0;
/// With the window guard the bow position is the parameter's times `scale^-x` (the
/// dynamics' bow scale): the bow sits at the parameter's place at full expression and
/// drifts away from the bridge as the dynamics fall, 2^(35/60) = 1.50 times farther at
/// the softest (-35 dB: `x = log10(2) / 3`), as players bow nearer the fingerboard for
/// piano and nearer the bridge for forte.
pub const DYNAMICS_DRIFT_EXPONENT: f64 = std::f64::consts::LOG10_2 / 3.0;
/// Paper B's thermal bow sticks and slips only above a bow speed: slower, the rosin heats
/// too little in a slip to drop its friction and the string slides (docs/testing.md,
/// "Dynamics"). With the window guard the dynamics take the thermal bow down to this
/// fraction of the parameters' speed and force at most, per instrument (in
/// [`InstrumentKind::ALL`]'s order: violin, viola, cello, double bass; measured by the
/// dynamics sweep, `lab/tests/dynamics_sweep.rs`, and checked by
/// `the_thermal_bow_keeps_sticking_at_its_slowest_dynamics`); below it the dynamics move
/// only the bow's position, as they do for the point laws.
pub const THERMAL_SLOWEST_SCALE: [f64; InstrumentKind::COUNT] = [0.6, 0.6, 0.5, 0.5];
/// Paper A's Stribeck curve `mu_d + (mu_s - mu_d) exp(-(v / v_s)^2)` (the static,
/// LuGre and elasto-plastic laws; `v_s` = 0.1 m/s) is flat at rest: at a slip speed of
/// 0.3 `v_s` it has fallen by only 9 % of `mu_s - mu_d`. In Helmholtz motion the string
/// slips at `v_b (1 - beta) / beta`, so a bow slow enough slips too gently for the
/// friction to let go cleanly, and the string slides or rattles (docs/testing.md,
/// "Dynamics"). With the window guard the dynamics take these laws' bow down to this
/// fraction of the parameters' bow at most (speed, force and the drift from the bridge
/// alike: drifting farther would slow the slip again), per instrument in
/// [`InstrumentKind::ALL`]'s order. Measured by the dynamics sweep with the dynamics
/// settled before the note: the violin and viola speak on every note from 0.047 (a slip
/// of about 3 cm/s at the default bow, 0.3 `v_s`), the cello from 0.056 and the double
/// bass, never on every note, on most from 0.07; checked by
/// `the_stribeck_laws_keep_helmholtz_motion_at_their_slowest_dynamics`. The hyperbolic
/// curve falls steepest at rest and has no floor.
pub const STRIBECK_SLOWEST_SCALE: [f64; InstrumentKind::COUNT] = [0.047, 0.047, 0.056, 0.07];
/// In a slip the friction is a damper on the string at the bow: `F mu'(v)`, negative
/// where the curve falls, in parallel with the string's own `2 Z0` (the two halves'
/// impedances). Paper A's Stribeck curve falls steepest near `v_s`
/// (`|mu'| = 2 (mu_s - mu_d) (v / v_s^2) exp(-(v / v_s)^2)`, at most 0.86 `(mu_s - mu_d) / v_s`),
/// and the guard's force, falling with the speed, brings the Helmholtz slip speed
/// `v_b (1 - beta) / beta` there at the middle dynamics: at CC11 53-74 the parameters'
/// defaults give `F |mu'| = 0.38-0.51` of `2 Z0`, and a third to a half of the violin's,
/// viola's and cello's notes turn raucous. With the window guard the force of these laws
/// is held down so that `F |mu'|` stays under this share of `2 Z0` (the string weighting
/// makes `F / Z0` the same on every string: the reference string's `2 Z0` stands for all).
/// Measured (`mid_dynamics_force_map` in `lab/tests/dynamics_sweep.rs`: 13 notes an
/// instrument bowed directly at CC11 53-74's speed and distance with a share of the
/// guard's force): at 0.35 of it (`F |mu'|` 0.14-0.18 of `2 Z0`) all the violin's,
/// viola's and cello's notes but one at most play Helmholtz motion at every level, with
/// the static and the LuGre law; at 0.7 (0.27-0.36) up to 3 of 13 are raucous or slip
/// twice a period; the double bass's 9-13 at 0.35 against 4-11 at the guard's force. The
/// speed and the distance from the bridge, which set the amplitude, are not changed.
/// Friedlander's construction
/// gives one crossing of the load line while `F |mu'| < 2 Z0`; the model's strings, with
/// their losses and the bridge's reflection arriving within the slip, let go well before.
/// The hyperbolic curve, steepest at rest, reaches 0.17 at most at the defaults, and
/// takes its own bound ([`HYPERBOLIC_SLIP_DAMPING`]).
pub const STRIBECK_SLIP_DAMPING: f64 = 0.15;
/// The hyperbolic curve `mu_d + (mu_s - mu_d) v0 / (v0 + |v|)` falls steepest at rest
/// (`|mu'| = (mu_s - mu_d) v0 / (v0 + v)^2`), so the slip's negative damping `F |mu'|`
/// (see [`STRIBECK_SLIP_DAMPING`]) at the guard's force, proportional to the speed, grows
/// as the dynamics fall, from 0.05 of `2 Z0` at full expression to 0.17 at CC11 64, and
/// falls again below (0.07 at CC11 0, where the slip is slowest). With the window guard
/// the hyperbolic law's force is held so that `F |mu'|` stays under this share of `2 Z0`:
/// 0.40 of the speed's share at CC11 64, 0.59 at 21, 0.96 at 0. Measured
/// (`mid_dynamics_force_map` in `lab/tests/dynamics_sweep.rs`, `LAW=hyperbolic STEP=1`:
/// every semitone of three octaves from each instrument's lowest string, bowed directly
/// at CC11 0-106's speed and distance with 0.35-2 times the speed's share of the force,
/// 888 (note, level) pairs at each share): at CC11 21-85 the violin's, viola's and cello's
/// notes play Helmholtz motion most often at 0.35-0.7 of it (35-37 of 37 a level against
/// 27-37 at 1), at CC11 0 at 0.7-1.4 (the cello's 21 of 37 at 0.35), the double bass's
/// less clearly either way. Read off those counts between the shares measured, bounds
/// of 0.06-0.08 put about 840 of the 888 pairs in Helmholtz motion against 804 without
/// a bound (0.05: 833, 0.1: 831, 0.15: 807); every instrument gains.
pub const HYPERBOLIC_SLIP_DAMPING: f64 = 0.07;
/// Time constant of the dynamics' smoothing, s (no zipper noise from 7-bit steps).
pub const DYNAMICS_SMOOTHING_S: f64 = 0.01;
/// Vibrato depth at the mod wheel's top, cents (peak, either side: players' wide vibrato).
pub const MAX_VIBRATO_CENTS: f64 = 30.0;
/// Vibrato rate, Hz (string players: 5-7 Hz).
pub const VIBRATO_RATE_HZ: f64 = 5.5;
/// The vibrato rate's range (the Vibrato Rate parameter, and CC19 across it), Hz.
pub const VIBRATO_RATE_MIN_HZ: f64 = 3.0;
pub const VIBRATO_RATE_MAX_HZ: f64 = 9.0;
/// A player's vibrato is not a machine's: its rate and depth wander by up to this
/// fraction either way, slowly ([`VIBRATO_DRIFT_S`]), from a fixed-seed random walk (the
/// same input gives the same output).
pub const VIBRATO_RATE_DRIFT: f64 = 0.03;
pub const VIBRATO_DEPTH_DRIFT: f64 = 0.04;
/// How often the drift picks a new direction, s (it glides there over the same time).
pub const VIBRATO_DRIFT_S: f64 = 0.4;
/// The vibrato starts this long after a note lands, s...
pub const VIBRATO_DELAY_S: f64 = 0.15;
/// ... and fades in over this long, s.
pub const VIBRATO_FADE_S: f64 = 0.3;
/// Samples between two vibrato updates of the finger (a retune of the sounding strings):
/// 1.3 ms at 48 kHz, steps of at most 1.4 cents at the widest vibrato.
const VIBRATO_EVERY: u32 = 64;

/// A legato note softer than this (MIDI 64) slides the finger (portamento).
pub const PORTAMENTO_BELOW_VELOCITY: f64 = 64.0 / 127.0;
/// Default finger glide time, s.
pub const GLIDE_S_DEFAULT: f64 = 0.12;

/// What the player's controllers ask of the bow and the finger (the performance layer):
/// dynamics (CC11 expression, CC2 breath, channel pressure) scale the bow's velocity and
/// force together, which keeps the bow at the same place in Schelleng's window (both
/// limits are proportional to the bow velocity) while the amplitude follows the velocity;
/// the mod wheel (CC1) sets the depth of a finger vibrato.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Gesture {
    /// The bow scale the asked expression (0..=1) gives: `10^(-range (1 - e) / 20)`.
    pub(super) target: f64,
    /// The bow's present scale (smoothed toward `target`).
    pub(super) bow_scale: f64,
    /// The window guard's bow at this scale ([`guarded_bow`]).
    pub(super) guarded: GuardedBow,
    pub(super) smoothing: f64,
    /// Vibrato depth, cents.
    pub(super) vibrato_cents: f64,
    /// The MIDI pitch bend, semitones (the vibrato is added to it).
    pub(super) bend_semitones: f64,
    /// The pitch-bend wheel, -1..=1.
    pub(super) wheel_position: f64,
    /// The bend range MIDI RPN 0 set, semitones (overrides the setup's).
    pub(super) rpn_bend_range: Option<f64>,
    /// The registered parameter number CC101/CC100 selected ([`RPN_NULL`]: none).
    pub(super) rpn: (u8, u8),
    /// CC65 (portamento) down.
    pub(super) portamento_pedal: bool,
    /// The vibrato's present offset, semitones.
    pub(super) vibrato_now: f64,
    pub(super) phase: f64,
    pub(super) phase_step: f64,
    /// The rate CC19 set, Hz (over the setup's until that changes).
    pub(super) cc_rate_hz: Option<f64>,
    /// Drift of rate and depth: now, target (fractions), updates to the next target, and
    /// the random state.
    pub(super) drift: [f64; 2],
    pub(super) drift_target: [f64; 2],
    pub(super) drift_countdown: u32,
    pub(super) seed: u64,
    /// Samples since the last note landed.
    pub(super) since_note: u64,
    pub(super) countdown: u32,
    /// The expression the engines' intonation was last told, and the guard's bow scale
    /// last looked at for it ([`Performer::shape`]).
    pub(super) intonation_expression: f64,
    pub(super) intonation_scale: f64,
    /// The guard's Stribeck force shares for the law and instrument played.
    pub(super) force_shares: ForceShares,
}

/// [`THERMAL_SLOWEST_SCALE`] for `kind`.
pub fn thermal_slowest_scale(kind: InstrumentKind) -> f64 {
    THERMAL_SLOWEST_SCALE[kind.index()]
}

/// The slowest share of the parameters' bow the Dynamics Guard plays on `kind` with the
/// point law `law` (`None`: paper B's thermal bow): [`THERMAL_SLOWEST_SCALE`],
/// [`STRIBECK_SLOWEST_SCALE`], or none for the hyperbolic law.
pub fn slowest_bow_scale(law: Option<FrictionModel>, kind: InstrumentKind) -> Option<f64> {
    match law {
        None => Some(thermal_slowest_scale(kind)),
        Some(FrictionModel::Hyperbolic) => None,
        Some(_) => Some(STRIBECK_SLOWEST_SCALE[kind.index()]),
    }
}

/// The factors the Dynamics Guard puts on the parameters' bow: speed, force and distance
/// from the bridge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuardedBow {
    pub speed: f64,
    pub force: f64,
    pub away: f64,
}

impl GuardedBow {
    /// The parameters' own bow (full expression).
    pub const FULL: Self = Self {
        speed: 1.0,
        force: 1.0,
        away: 1.0,
    };
}

/// The slip speeds over which a Stribeck law's slip damping is taken, as a share of the
/// Helmholtz slip speed: from this share of it up to it (the largest `|mu'|` over them).
/// Taken at the Helmholtz speed alone, the bound lets go above CC11 74 (the slip passes
/// `v_s` there) and the guard's force leaps from 0.23 `F_max` at CC11 74 to 0.57 at 85,
/// where the performer's attack leaves the static, LuGre and elasto-plastic laws' notes
/// in a short slip (0.62-0.71 beta, one a period, 10-25 cents sharp; docs/testing.md,
/// "Dynamics"); with half that force none does (`short_slip_map` with `FORCE=0.5` in
/// `lab/tests/dynamics_sweep.rs`). From 0.7 of the speed the bound holds the force to
/// 0.31 of the speed's at CC11 85 and lets go at CC11 95, so that the force rises between
/// two of the intonation table's soft rows (CC11 85 and 95), which interpolates the pitch
/// between them; below CC11 53 (a slip slower than `v_s / sqrt(2)`, the curve's
/// steepest) it changes nothing.
pub const STRIBECK_SLIP_SPAN: f64 = 0.7;

/// The slip's negative damping `F |mu'(v_slip)|` over the reference string's `2 Z0` with
/// point law `law` at the parameters' defaults, the bow at the guard's `speed` (and its
/// force proportional to it) and drift `away`: the Helmholtz slip speed `v_b (1 - beta) /
/// beta` on the law's curve (paper A's Stribeck curve for the static, LuGre and
/// elasto-plastic laws, its steepest over [`STRIBECK_SLIP_SPAN`] of that speed up to it).
/// The string weighting makes `F / Z0` the same on every string.
pub fn slip_damping(law: FrictionModel, speed: f64, away: f64) -> f64 {
    let bow = BowControl::default();
    let beta = (bow.position_beta * away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA);
    let v_slip = bow.velocity_m_per_s * speed * (1.0 - beta) / beta;
    let slope = match law {
        FrictionModel::Hyperbolic => {
            let friction = crate::dsp::friction::HyperbolicFriction::default();
            let (v0, fall) = (friction.v0_m_per_s, friction.mu_s - friction.mu_d);
            fall * v0 / ((v0 + v_slip) * (v0 + v_slip))
        }
        _ => {
            let friction = crate::dsp::friction::stribeck::StribeckFriction::default();
            let (v_s, fall) = (friction.stribeck_m_per_s, friction.mu_s - friction.mu_d);
            // `x exp(-x^2)` rises to x = 1 / sqrt(2) and falls after: its largest over
            // `[span x, x]` is at one end or at that peak.
            let x = v_slip / v_s;
            let steepest = std::f64::consts::FRAC_1_SQRT_2;
            let at = if x <= steepest {
                x
            } else {
                (STRIBECK_SLIP_SPAN * x).max(steepest)
            };
            2.0 * fall * at * (-at * at).exp() / v_s
        }
    };
    bow.force_n * speed * slope / (2.0 * crate::dsp::vocabulary::WEIGHT_REFERENCE_Z0)
}

/// The share of the guard's force (`speed` times the parameters' force) point law `law`
/// plays at the guard's `speed` and drift `away`: the most that keeps its
/// [`slip_damping`] under its bound ([`HYPERBOLIC_SLIP_DAMPING`],
/// [`STRIBECK_SLIP_DAMPING`]).
fn slip_force_share(law: FrictionModel, speed: f64, away: f64) -> f64 {
    let bound = match law {
        FrictionModel::Hyperbolic => HYPERBOLIC_SLIP_DAMPING,
        _ => STRIBECK_SLIP_DAMPING,
    };
    let damping = slip_damping(law, speed, away);
    if damping > bound {
        bound / damping
    } else {
        1.0
    }
}

/// The expression levels between which the guard's force share for the Stribeck laws
/// goes on lines ([`stribeck_force_share`]): the intonation table's soft levels
/// ([`crate::dsp::intonation::SOFT_EXPRESSIONS`]) that fall on a twelfth of the
/// expression, and full expression. The table's row at 17/24 tunes the pitch only: the
/// force is not worked out there.
const FORCE_LEVELS: [f64; 11] = {
    let soft = crate::dsp::intonation::SOFT_EXPRESSIONS;
    let mut levels = [1.0; 11];
    let (mut i, mut n) = (0, 0);
    while i < soft.len() {
        let twelfths = soft[i] * 12.0;
        if (twelfths - (twelfths + 0.5) as u32 as f64).abs() < 1e-9 {
            levels[n] = soft[i];
            n += 1;
        }
        i += 1;
    }
    // Every place but the last holds a twelfth; the last stays at full expression.
    assert!(n == levels.len() - 1);
    levels
};

/// The share of the guard's force a Stribeck law (`law`) plays on `kind` at the dynamics'
/// bow scale `scale`: [`slip_force_share`] at [`FORCE_LEVELS`], interpolated linearly in
/// the expression between them, as the intonation table interpolates the pitch. Where the
/// bound lets go (CC11 85 to 95) its own force rises faster than a line; played there,
/// the static law's notes sat 5-11 cents over the pitch the rows interpolate, and at CC11
/// 88-92 that force (about half the speed's) puts the cello's and double bass's lowest
/// notes into raucous motion at whichever level it falls. The force therefore goes on a
/// line from CC11 85 to 95, and the table's row at 17/24 (CC11 90) is fitted at the
/// line's force: it tunes the pitch, not the force (docs/testing.md, "Dynamics").
fn stribeck_force_share(law: FrictionModel, kind: InstrumentKind, scale: f64) -> f64 {
    share_between_levels(expression_at(scale), |i| {
        stribeck_share_at(law, kind, FORCE_LEVELS[i])
    })
}

/// [`slip_force_share`] of Stribeck law `law` on `kind` at expression `e`, as the guard
/// plays it there.
fn stribeck_share_at(law: FrictionModel, kind: InstrumentKind, e: f64) -> f64 {
    match speed_and_away(Some(law), kind, bow_scale_at(e)) {
        (speed, _) if speed >= 1.0 => 1.0,
        (speed, away) => slip_force_share(law, speed, away),
    }
}

/// The share at `expression` on the line between the two [`FORCE_LEVELS`] either side,
/// with `share_at(i)` the share at level `i` (only those two are asked for).
fn share_between_levels(expression: f64, share_at: impl Fn(usize) -> f64) -> f64 {
    for i in 1..FORCE_LEVELS.len() {
        let (below, level) = (FORCE_LEVELS[i - 1], FORCE_LEVELS[i]);
        if level >= expression {
            let share_below = share_at(i - 1);
            let t = (expression - below) / (level - below);
            return share_below + t * (share_at(i) - share_below);
        }
    }
    1.0
}

/// A performer's Stribeck force shares at [`FORCE_LEVELS`] for the law and instrument it
/// plays, worked out once for them: while the dynamics glide the guard's bow is asked for
/// every sample, and each level's share costs a few `powf` and `exp`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ForceShares {
    of: Option<(FrictionModel, InstrumentKind)>,
    shares: [f64; FORCE_LEVELS.len()],
}

impl ForceShares {
    pub(super) const EMPTY: Self = Self {
        of: None,
        shares: [1.0; FORCE_LEVELS.len()],
    };

    /// The shares of `law` on `kind`, worked out if they are not those held.
    fn of(&mut self, law: FrictionModel, kind: InstrumentKind) -> &[f64; FORCE_LEVELS.len()] {
        if self.of != Some((law, kind)) {
            for (share, &e) in self.shares.iter_mut().zip(&FORCE_LEVELS) {
                *share = stribeck_share_at(law, kind, e);
            }
            self.of = Some((law, kind));
        }
        &self.shares
    }
}

/// The dynamics' bow scale at expression `e` (0..=1): `10^(-range (1 - e) / 20)`.
pub fn bow_scale_at(e: f64) -> f64 {
    10f64.powf(-DYNAMICS_RANGE_DB * (1.0 - e.clamp(0.0, 1.0)) / 20.0)
}

/// The expression (0..=1) whose bow scale is `scale` ([`bow_scale_at`]'s inverse).
fn expression_at(scale: f64) -> f64 {
    (1.0 + 20.0 * scale.log10() / DYNAMICS_RANGE_DB).clamp(0.0, 1.0)
}

/// The guard's factors on the parameters' speed and on the bow's distance from the
/// bridge at the dynamics' bow scale `scale` ([`guarded_bow`]).
fn speed_and_away(law: Option<FrictionModel>, kind: InstrumentKind, scale: f64) -> (f64, f64) {
    let slowest = slowest_bow_scale(law, kind);
    let speed = slowest.map_or(scale, |s| scale.max(s));
    let drift_from = if law.is_some() { speed } else { scale };
    let away = if drift_from == 1.0 {
        1.0
    } else {
        drift_from.powf(-DYNAMICS_DRIFT_EXPONENT)
    };
    (speed, away)
}

/// The bow the Dynamics Guard plays at the dynamics' bow scale `scale` (0..=1) with
/// `law` (`None`: paper B's thermal bow) on `kind`: the factor on the parameters' speed
/// and force (no lower than [`slowest_bow_scale`]; a Stribeck law's force held under
/// [`STRIBECK_SLIP_DAMPING`], the hyperbolic law's under [`HYPERBOLIC_SLIP_DAMPING`]) and
/// the one on the bow's distance from
/// the bridge (`s^-`[`DYNAMICS_DRIFT_EXPONENT`]; the thermal bow's drifts on below its
/// slowest speed, the Stribeck laws' stops there).
pub fn guarded_bow(law: Option<FrictionModel>, kind: InstrumentKind, scale: f64) -> GuardedBow {
    guarded_bow_with(law, kind, scale, |law| {
        stribeck_force_share(law, kind, scale)
    })
}

/// [`guarded_bow`], with a Stribeck law's force share from `stribeck_share`.
#[inline]
fn guarded_bow_with(
    law: Option<FrictionModel>,
    kind: InstrumentKind,
    scale: f64,
    stribeck_share: impl FnOnce(FrictionModel) -> f64,
) -> GuardedBow {
    let (speed, away) = speed_and_away(law, kind, scale);
    if away == 1.0 {
        return GuardedBow {
            speed,
            force: speed,
            away,
        };
    }
    let share = match law {
        None => 1.0,
        Some(FrictionModel::Hyperbolic) => slip_force_share(FrictionModel::Hyperbolic, speed, away),
        Some(law) => stribeck_share(law),
    };
    GuardedBow {
        speed,
        force: speed * share,
        away,
    }
}

impl Gesture {
    pub(super) fn new(sample_rate_hz: f64) -> Self {
        Self {
            target: 1.0,
            bow_scale: 1.0,
            guarded: GuardedBow::FULL,
            smoothing: 1.0 - (-1.0 / (DYNAMICS_SMOOTHING_S * sample_rate_hz)).exp(),
            vibrato_cents: 0.0,
            bend_semitones: 0.0,
            wheel_position: 0.0,
            rpn_bend_range: None,
            rpn: (RPN_NULL, RPN_NULL),
            portamento_pedal: false,
            vibrato_now: 0.0,
            phase: 0.0,
            phase_step: VIBRATO_RATE_HZ / sample_rate_hz,
            cc_rate_hz: None,
            drift: [0.0; 2],
            drift_target: [0.0; 2],
            drift_countdown: 0,
            seed: 0x9e37_79b9_7f4a_7c15,
            since_note: 0,
            countdown: 0,
            intonation_expression: 1.0,
            intonation_scale: 1.0,
            force_shares: ForceShares::EMPTY,
        }
    }

    pub(super) fn set_expression(&mut self, e: f64) {
        self.target = bow_scale_at(e);
    }
}

impl Performer {
    /// The vibrato's offset now, semitones: a sine at [`VIBRATO_RATE_HZ`], silent for
    /// [`VIBRATO_DELAY_S`] after a note lands, then faded in over [`VIBRATO_FADE_S`].
    pub(super) fn vibrato_semitones(&self) -> f64 {
        let t = self.gesture.since_note as f64 / self.sample_rate_hz - VIBRATO_DELAY_S;
        let fade = (t / VIBRATO_FADE_S).clamp(0.0, 1.0);
        let depth = self.gesture.vibrato_cents * (1.0 + self.gesture.drift[1]);
        fade * depth / 100.0 * (2.0 * std::f64::consts::PI * self.gesture.phase).sin()
    }

    /// The vibrato rate now, Hz: CC19's if it moved last, else the setup's.
    pub fn vibrato_rate_hz(&self) -> f64 {
        midi_over_setup(
            self.gesture.cc_rate_hz,
            self.setup.vibrato_rate_hz,
            VIBRATO_RATE_HZ,
            VIBRATO_RATE_MIN_HZ..=VIBRATO_RATE_MAX_HZ,
        )
    }

    /// One vibrato update of the drift (every [`VIBRATO_EVERY`] samples): each wander glides
    /// toward its target, and a new target is drawn every [`VIBRATO_DRIFT_S`].
    pub(super) fn tick_drift(&mut self) {
        let fs = self.sample_rate_hz;
        let g = &mut self.gesture;
        let updates = (VIBRATO_DRIFT_S * fs / VIBRATO_EVERY as f64).max(1.0);
        if g.drift_countdown == 0 {
            g.drift_countdown = updates as u32;
            for (k, limit) in [VIBRATO_RATE_DRIFT, VIBRATO_DEPTH_DRIFT]
                .into_iter()
                .enumerate()
            {
                // xorshift64*: a uniform draw in -1..1.
                g.seed ^= g.seed >> 12;
                g.seed ^= g.seed << 25;
                g.seed ^= g.seed >> 27;
                let r =
                    (g.seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
                g.drift_target[k] = limit * (2.0 * r - 1.0);
            }
        }
        g.drift_countdown -= 1;
        for k in 0..2 {
            g.drift[k] += (g.drift_target[k] - g.drift[k]) / updates;
        }
        let rate = self.vibrato_rate_hz() * (1.0 + self.gesture.drift[0]);
        self.gesture.phase_step = rate / fs;
    }

    /// Advances the gesture one sample and returns the bow it shapes: the direct bow
    /// controllers in place of the parameters they hold, the stroke (its direction and
    /// attack), then the dynamics. With the mod wheel and the dynamics at
    /// rest and a down stroke under way it costs a few comparisons.
    #[inline]
    pub(super) fn shape(&mut self, bow: BowControl) -> BowControl {
        if self.gesture.vibrato_cents > 0.0 || self.gesture.vibrato_now != 0.0 {
            self.tick_vibrato();
        }
        let bow = self.direct.apply(bow);
        let (speed, landing) = if self.stroke.is_settled() {
            (self.stroke.direction(), 1.0)
        } else {
            self.stroke.tick()
        };
        let g = &mut self.gesture;
        if g.bow_scale != g.target {
            g.bow_scale += g.smoothing * (g.target - g.bow_scale);
            if (g.bow_scale - g.target).abs() < 1e-9 {
                g.bow_scale = g.target;
            }
            // The guard's bow follows the scale: worked out once per change of the
            // scale, not per sample while it rests (a vibrato ticks this path every
            // sample).
            let scale = g.bow_scale;
            self.gesture.guarded = self.guarded_bow(scale);
        }
        // With the guard the force follows the velocity (held lower where a Stribeck
        // law's slip would rattle) and the bow drifts from the bridge as the dynamics
        // fall; without it only the velocity follows.
        let (velocity_scale, force_scale, away) = if self.setup.dynamics_guard {
            let g = self.gesture.guarded;
            (g.speed, g.force, g.away)
        } else {
            (self.gesture.bow_scale, 1.0, 1.0)
        };
        let mut out = if velocity_scale == 1.0 && speed == 1.0 && landing == 1.0 && away == 1.0 {
            bow
        } else {
            BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * velocity_scale * speed,
                force_n: bow.force_n * force_scale * landing,
                position_beta: (bow.position_beta * away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
            }
        };
        if let Some(catch) = &mut self.catch {
            let asked = bow.force_n * force_scale;
            match catch.force(
                asked,
                bow.velocity_m_per_s * velocity_scale,
                out.position_beta,
            ) {
                Some(f) => out.force_n = out.force_n.max(f),
                None => self.catch = None,
            }
        }
        // Steady from here on until a controller, a pressure or a note: the next samples
        // only multiply (the same bits: `speed` is +-1, so the order of the products does
        // not round differently).
        let g = &self.gesture;
        let steady = g.vibrato_cents == 0.0
            && g.vibrato_now == 0.0
            && g.bow_scale == g.target
            && self.direct.is_idle()
            && self.stroke.is_settled()
            && self.catch.is_none();
        self.steady = steady.then_some((velocity_scale * speed, force_scale, away));
        // The intonation follows the guard's bow (the table is fitted with it); without
        // the guard it stays at full expression's. Looked at only when that bow's scale
        // changes (a vibrato runs this path every sample with the dynamics at rest).
        let scale = if self.setup.dynamics_guard {
            self.gesture.bow_scale
        } else {
            1.0
        };
        if scale != self.gesture.intonation_scale {
            self.gesture.intonation_scale = scale;
            self.follow_dynamics(scale);
        }
        out
    }

    /// The law whose slowest bow and drift the guard plays the source with (`None`:
    /// paper B's thermal bow; a rubbed source takes the hyperbolic law's: no floor).
    fn bow_law(&self) -> Option<FrictionModel> {
        match self.source {
            Source::Thermal(_) => None,
            Source::Strings => Some(self.setup.point_law.unwrap_or(FrictionModel::Hyperbolic)),
            Source::Rubbed(_) => Some(FrictionModel::Hyperbolic),
        }
    }

    /// A separate note's bow lands at the dynamics asked, not on the way there: the
    /// smoothing is for a bow on the string (no zipper noise), and a player who lifts the
    /// bow sets it down at the new dynamic. (A controller sent with the note would
    /// otherwise bow its first 40 ms or so at the dynamics before it.)
    pub(super) fn land_dynamics(&mut self) {
        let target = self.gesture.target;
        if self.gesture.bow_scale != target {
            self.gesture.bow_scale = target;
            self.gesture.guarded = self.guarded_bow(target);
            // The note lands tuned for the bow it is played with.
            if self.setup.dynamics_guard {
                self.gesture.intonation_scale = target;
                self.follow_dynamics(target);
            }
        }
    }

    /// The source's slowest scale of the parameters' bow ([`slowest_bow_scale`]), below
    /// which its string slides; `None` for the hyperbolic law and the rubbed sources.
    fn slowest_bow_scale(&self) -> Option<f64> {
        slowest_bow_scale(self.bow_law(), self.setup.instrument)
    }

    /// [`guarded_bow`] for the source at the dynamics' bow scale `scale`. A rubbed object
    /// is no string: the slip's damping bound, set for the strings at the parameters'
    /// defaults, does not apply, and its force follows the speed.
    pub(super) fn guarded_bow(&mut self, scale: f64) -> GuardedBow {
        let (law, kind) = (self.bow_law(), self.setup.instrument);
        let shares = &mut self.gesture.force_shares;
        let guarded = guarded_bow_with(law, kind, scale, |law| {
            let shares = shares.of(law, kind);
            share_between_levels(expression_at(scale), |i| shares[i])
        });
        match self.source {
            Source::Rubbed(_) => GuardedBow {
                force: guarded.speed,
                ..guarded
            },
            _ => guarded,
        }
    }

    /// The dynamics' factor on the bow's speed at the dynamics' scale `scale`: with the
    /// guard, no lower than the source's slowest bow scale.
    fn dynamics_velocity_scale(&self, scale: f64) -> f64 {
        if self.setup.dynamics_guard {
            speed_and_away(self.bow_law(), self.setup.instrument, scale).0
        } else {
            scale
        }
    }

    /// The least share of the asked bow a soft note's gentle start may set out at
    /// ([`super::stroke::Stroke::limit_onset`]): where the dynamics' bow times it reaches
    /// the source's slowest bow scale (none at all once the dynamics are there); the point
    /// laws' sets out as low as the velocity asks.
    pub(super) fn onset_floor(&self) -> f64 {
        self.slowest_bow_scale().map_or(0.0, |slowest| {
            let scale = self.dynamics_velocity_scale(self.gesture.target);
            (slowest / scale.max(f64::MIN_POSITIVE)).min(1.0)
        })
    }

    /// Tells the engines the expression the guard's bow `scale` plays (0..=1, so their
    /// intonation follows it): every [`DYNAMICS_INTONATION_STEP`] of a move, and where the
    /// dynamics come to rest.
    fn follow_dynamics(&mut self, scale: f64) {
        let expression = expression_at(scale);
        let sent = self.gesture.intonation_expression;
        let settled = self.gesture.bow_scale == self.gesture.target;
        if (expression - sent).abs() >= DYNAMICS_INTONATION_STEP || (settled && expression != sent)
        {
            self.gesture.intonation_expression = expression;
            for engine in self.engines() {
                engine.set_dynamics(expression);
            }
        }
    }

    /// One sample of the vibrato: its clock runs while the mod wheel is up (so the onset
    /// delay counts from the note or from the wheel, whichever is later), and the finger
    /// moves every [`VIBRATO_EVERY`] samples.
    pub(super) fn tick_vibrato(&mut self) {
        let g = &mut self.gesture;
        g.since_note = g.since_note.saturating_add(1);
        g.phase += g.phase_step;
        if g.phase >= 1.0 {
            g.phase -= 1.0;
        }
        if g.countdown == 0 {
            g.countdown = VIBRATO_EVERY;
            self.tick_drift();
            let now = if self.gesture.vibrato_cents > 0.0 {
                self.vibrato_semitones()
            } else {
                0.0
            };
            self.gesture.vibrato_now = now;
            let bend = self.gesture.bend_semitones + now;
            // Only what sounds moves its finger; a silent engine takes the vibrato at the
            // first update after its note lands (the vibrato starts later still).
            for engine in self.engines().filter(|e| e.is_sounding()) {
                engine.set_pitch_bend(bend);
            }
        }
        self.gesture.countdown -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::contact::ContactSample;
    use crate::measure::regime::{classify_regime, Regime};
    use crate::performer::testing::*;

    #[test]
    fn the_bow_as_played_follows_the_dynamics_and_is_none_when_lifted() {
        let mut p = cello();
        assert_eq!(p.bowed_bow(), None);
        p.set_controller(11, 0.5);
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        for _ in 0..(0.5 * FS) as usize {
            p.tick(bow);
        }
        let (v, f) = p.bowed_bow().unwrap();
        // Half expression is half the range down on the speed, and the guard's share of
        // it on the force, lighter there for the default (hyperbolic) law: its slip's
        // damping bound (smoothing and the attack have settled after 0.5 s; 1e-6 is f32
        // rounding).
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB * 0.5 / 20.0);
        let guard = guarded_bow(
            Some(FrictionModel::Hyperbolic),
            InstrumentKind::Cello,
            scale,
        );
        assert!(guard.force < 0.5 * scale, "{guard:?}");
        assert!(((v as f64).abs() / 0.1 - scale).abs() < 1e-6, "{v}");
        assert!((f as f64 / 1.0 - guard.force).abs() < 1e-6, "{f}");
        p.note_off(50);
        assert_eq!(p.bowed_bow(), None);
    }

    /// Bows cello D3 at the defaults with the expression at `e` from the start; returns
    /// the RMS over 1.5..2 s and the regime of its last 8 periods on the probe.
    fn bowed_at(e: f32) -> (f64, Option<Regime>) {
        bowed_note_at(50, e)
    }

    /// [`bowed_at`] for `note` on the cello.
    fn bowed_note_at(note: u8, e: f32) -> (f64, Option<Regime>) {
        let mut p = cello();
        p.set_controller(11, e);
        p.note_on(note, 0.8);
        played(
            &mut p,
            &Setup::default(),
            note,
            BowControl::default(),
            2.0,
            1.5,
        )
    }

    /// `p`'s `note` (already on) with `bow` for `seconds`, `setup` configured every 256
    /// samples as the plugin's blocks do: the RMS from `rms_from_s` to the end and the
    /// regime of the last 8 periods on the probe.
    fn played(
        p: &mut Performer,
        setup: &Setup,
        note: u8,
        bow: BowControl,
        seconds: f64,
        rms_from_s: f64,
    ) -> (f64, Option<Regime>) {
        let (audio, probe) = bowed(p, setup, bow, seconds, 0.0);
        let n = probe.len();
        let tail = &audio[(rms_from_s * FS) as usize..];
        let rms = (tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64).sqrt();
        let f0 = midi_to_hz(note as f64);
        let window = (8.0 * FS / f0) as usize;
        (
            rms,
            classify_regime(&probe[n - window..], FS as f32, f0 as f32),
        )
    }

    /// `p` (its note on) bowed with `bow` for `seconds`, `setup` configured every 256
    /// samples as the plugin's blocks do: the output and the probe at the bow, sample by
    /// sample, from `from_s` to the end.
    fn bowed(
        p: &mut Performer,
        setup: &Setup,
        bow: BowControl,
        seconds: f64,
        from_s: f64,
    ) -> (Vec<f64>, Vec<ContactSample>) {
        let n = (seconds * FS) as usize;
        let from = (from_s * FS) as usize;
        let mut audio = Vec::with_capacity(n.saturating_sub(from));
        let mut probe = Vec::with_capacity(n.saturating_sub(from));
        for i in 0..n {
            if i % 256 == 0 {
                p.configure(setup);
            }
            let frame = p.tick(bow);
            if i >= from {
                audio.push(frame.audio);
                probe.push(ContactSample::new(&frame, &p.bow()));
            }
        }
        (audio, probe)
    }

    /// [`bowed`]'s probe over the whole time.
    fn probed(
        p: &mut Performer,
        setup: &Setup,
        bow: BowControl,
        seconds: f64,
    ) -> Vec<ContactSample> {
        bowed(p, setup, bow, seconds, 0.0).1
    }

    #[test]
    fn without_the_window_guard_a_soft_dynamic_under_a_heavy_bow_turns_raucous() {
        // Expression 0.25 is 26 dB down: with the guard the force follows the velocity
        // (Helmholtz, the test below); without it a bow 20x slower under the full 1 N
        // presses about four times Schelleng's F_max for cello D3 and loses Helmholtz
        // motion: either more than one slip per period, or (with the bow hair yielding,
        // which at this slow bow takes up much of the force's swing) one short slip whose
        // slip fraction is far from beta (Raman: it equals beta; the map's 15 %).
        let setup = Setup {
            dynamics_guard: false,
            ..Setup::default()
        };
        let mut p = cello_with(&setup);
        p.set_controller(11, 0.25);
        p.note_on(50, 0.8);
        let probe = probed(&mut p, &setup, BowControl::default(), 2.0);
        let n = probe.len();
        let played = p.bow();
        assert_eq!(played.force_n, 1.0, "the force is the parameter's");
        assert_eq!(played.position_beta, 0.1, "no drift without the guard");
        let f0 = midi_to_hz(50.0);
        let window = 8 * (FS / f0) as usize;
        let tail = &probe[n - window..];
        let regime = classify_regime(tail, FS as f32, f0 as f32);
        let v: Vec<f64> = tail.iter().map(|s| s.string_velocity as f64).collect();
        let v_b = played.velocity_m_per_s;
        // 0.05 v_b as the playing-space map measures a cell (lab/src/playing_space.rs). It
        // sets only the strict slip fraction, unread here: the half-jump one decides.
        let stats = crate::analysis::slip_stats(&v, v_b, FS, f0, 0.05 * v_b);
        let beta = played.position_beta;
        let helmholtz =
            regime == Some(Regime::Helmholtz) && (stats.slip_fraction - beta).abs() <= 0.15 * beta;
        println!(
            "{regime:?}, slip fraction {:.3} (beta {beta})",
            stats.slip_fraction
        );
        assert!(!helmholtz, "{regime:?}, {stats:?}");
    }

    /// Paper B's thermal model on `kind`: [`note_at`].
    fn thermal_note_at(kind: InstrumentKind, note: u8, e: f32) -> (f64, Option<Regime>) {
        note_at(kind, None, note, e)
    }

    /// `note` on `kind` bowed with the point law `law` (`None`: paper B's thermal model)
    /// at the defaults with the expression at `e`, sent just before the note (which lands
    /// at it), or, with `e` negative, the bow scaled by `-e` from full expression, around
    /// the guard; the RMS over 1.2..1.6 s and the regime of its last 8 periods.
    fn note_at(
        kind: InstrumentKind,
        law: Option<FrictionModel>,
        note: u8,
        e: f32,
    ) -> (f64, Option<Regime>) {
        let d = BowControl::default();
        if e < 0.0 {
            let scale = -e as f64;
            let bow = BowControl {
                velocity_m_per_s: d.velocity_m_per_s * scale,
                force_n: d.force_n * scale,
                ..d
            };
            note_bowed(kind, law, note, 1.0, bow)
        } else {
            note_bowed(kind, law, note, e, d)
        }
    }

    /// [`note_at`] at expression `e` (0..=1) with the parameters' bow `bow`.
    fn note_bowed(
        kind: InstrumentKind,
        law: Option<FrictionModel>,
        note: u8,
        e: f32,
        bow: BowControl,
    ) -> (f64, Option<Regime>) {
        let (mut p, setup) = note_on_at(kind, law, note, e);
        played(&mut p, &setup, note, bow, 1.6, 1.2)
    }

    /// A performer for `kind` with point law `law` (`None`: paper B's thermal model) at
    /// the defaults, the expression at `e`, and `note` on at velocity 0.8 (the
    /// performer's accent and catch); with its setup.
    fn note_on_at(
        kind: InstrumentKind,
        law: Option<FrictionModel>,
        note: u8,
        e: f32,
    ) -> (Performer, Setup) {
        let setup = Setup {
            instrument: kind,
            point_law: law,
            ..Setup::default()
        };
        let mut p = Performer::new(kind);
        p.activate(&setup, FS).unwrap();
        p.configure(&setup);
        p.set_controller(11, e);
        p.note_on(note, 0.8);
        (p, setup)
    }

    #[test]
    fn the_force_levels_are_the_intonation_tables_twelfths_and_full_expression() {
        // The table's levels on a twelfth: 0, then every twelfth from a quarter (its
        // 17/24 row is not one).
        let expected: Vec<f64> = std::iter::once(0.0)
            .chain((3..12).map(|k| k as f64 / 12.0))
            .chain(std::iter::once(1.0))
            .collect();
        for (level, want) in FORCE_LEVELS.iter().zip(&expected) {
            assert!((level - want).abs() < 1e-15, "{level} against {want}");
        }
        assert_eq!(FORCE_LEVELS.len(), expected.len());
    }

    #[test]
    fn the_performers_kept_force_shares_give_the_guards_bow_to_the_bit() {
        // The shares a performer keeps for its law and instrument give the bow the guard
        // works out afresh, exactly, across the dynamics, on every law and instrument and
        // after the law is switched on the same performer.
        for kind in InstrumentKind::ALL {
            let mut p = Performer::new(kind);
            let setup = |law| Setup {
                instrument: kind,
                point_law: Some(law),
                ..Setup::default()
            };
            p.activate(&setup(FrictionModel::Hyperbolic), FS).unwrap();
            for law in FrictionModel::ALL
                .into_iter()
                .chain([FrictionModel::Stribeck])
            {
                p.configure(&setup(law));
                for k in 0..=240 {
                    let scale = bow_scale_at(k as f64 / 240.0);
                    assert_eq!(
                        p.guarded_bow(scale),
                        guarded_bow(Some(law), kind, scale),
                        "{kind:?}, {}, scale {scale}",
                        law.name()
                    );
                }
            }
        }
    }

    #[test]
    fn a_law_or_instrument_chosen_at_rest_dynamics_plays_its_own_guarded_bow() {
        // The guard's bow belongs to the law and the instrument (the Stribeck laws' bow
        // stops at their slowest speed, the hyperbolic law's does not; each instrument
        // has its own floor): chosen while the dynamics rest at CC11 0, the new law's or
        // instrument's guarded speed and drift are played from the next sample, as by a
        // performer set up with them from the start; so is the guard turned off.
        let bow = BowControl::default();
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB / 20.0);
        let start = Setup {
            instrument: InstrumentKind::Cello,
            point_law: Some(FrictionModel::Hyperbolic),
            ..Setup::default()
        };
        let switches = [
            Setup {
                point_law: Some(FrictionModel::Stribeck),
                ..start
            },
            Setup {
                instrument: InstrumentKind::DoubleBass,
                point_law: Some(FrictionModel::LuGre),
                ..start
            },
            Setup {
                dynamics_guard: false,
                ..start
            },
        ];
        for switched in switches {
            let mut p = Performer::new(start.instrument);
            p.activate(&start, FS).unwrap();
            p.configure(&start);
            p.set_controller(11, 0.0);
            p.note_on(50, 0.5);
            for _ in 0..(0.3 * FS) as usize {
                p.tick(bow);
            }
            p.configure(&switched);
            p.tick(bow);
            let wanted = if switched.dynamics_guard {
                guarded_bow(switched.point_law, switched.instrument, scale)
            } else {
                // Without the guard only the speed follows the dynamics.
                GuardedBow {
                    speed: scale,
                    force: 1.0,
                    away: 1.0,
                }
            };
            let played = p.bow();
            // The stroke is settled (speed +-1): the speed is the guard's to rounding.
            assert!(
                (played.velocity_m_per_s.abs() - bow.velocity_m_per_s * wanted.speed).abs() < 1e-12,
                "{switched:?}: speed {} against {}",
                played.velocity_m_per_s,
                bow.velocity_m_per_s * wanted.speed
            );
            let beta = (bow.position_beta * wanted.away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA);
            assert!((played.position_beta - beta).abs() < 1e-12, "{switched:?}");
        }
    }

    #[test]
    fn the_thermal_bow_keeps_sticking_at_its_slowest_dynamics() {
        // Below its slowest speed paper B's rosin heats too little to stick and slip: the
        // cello's D3 bowed at 0.35 of the default bow (speed and force) slides.
        let (_, slow) = thermal_note_at(InstrumentKind::Cello, 50, -0.35);
        assert_eq!(slow, Some(Regime::Sliding));
        // With the guard, every instrument's lowest and highest open strings stick and
        // slip in Helmholtz motion at the softest expression (the bow at its slowest,
        // drifted 1.5 times from the bridge) and where the speed stops falling (the bow at
        // its slowest, nearest the bridge: the least heat), and the softest is the
        // quieter.
        for kind in InstrumentKind::ALL {
            let slowest = thermal_slowest_scale(kind);
            let floor_e = (1.0 + 20.0 * slowest.log10() / DYNAMICS_RANGE_DB) as f32;
            let open = kind.open_notes();
            for note in [open[0], open[open.len() - 1]] {
                let (soft, soft_regime) = thermal_note_at(kind, note, 0.0);
                let (floor, floor_regime) = thermal_note_at(kind, note, floor_e - 0.01);
                assert_eq!(
                    soft_regime,
                    Some(Regime::Helmholtz),
                    "{kind:?} {note} softest"
                );
                assert_eq!(
                    floor_regime,
                    Some(Regime::Helmholtz),
                    "{kind:?} {note} at {floor_e}"
                );
                assert!(soft < floor, "{kind:?} {note}: {soft} against {floor}");
            }
        }
    }

    #[test]
    fn a_separate_note_lands_at_the_dynamics_sent_with_it() {
        // CC11 0 just before the note: the bow never moves faster than the softest
        // dynamics' speed (0.018 of the parameters'; 1e-9: rounding), where the
        // dynamics' smoothing from full expression would bow the first 40 ms or so fast.
        let mut p = cello();
        p.set_controller(11, 0.0);
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        let softest = bow.velocity_m_per_s * 10f64.powf(-DYNAMICS_RANGE_DB / 20.0);
        let fastest = (0..(0.05 * FS) as usize)
            .map(|_| {
                p.tick(bow);
                p.bow().velocity_m_per_s.abs()
            })
            .fold(0.0f64, f64::max);
        assert!(fastest > 0.0, "the note is bowed");
        assert!(
            fastest <= softest * (1.0 + 1e-9),
            "{fastest} against {softest}"
        );
    }

    #[test]
    fn the_stribeck_laws_keep_helmholtz_motion_at_their_slowest_dynamics() {
        // Paper A's Stribeck curve is flat at rest: bowed at the dynamics' softest scale
        // (0.018 of the parameters' speed and force, 35 dB down) the string slips too
        // slowly for the friction to let go, and the cello's D3 does not play Helmholtz
        // motion.
        let softest = -(10f64.powf(-DYNAMICS_RANGE_DB / 20.0) as f32);
        let (_, slow) = note_at(
            InstrumentKind::Cello,
            Some(FrictionModel::Stribeck),
            50,
            softest,
        );
        assert_ne!(slow, Some(Regime::Helmholtz));
        // With the guard the bow stops at the law's slowest: at expression 0, sent with
        // the note, the violin's, viola's and cello's lowest and highest open
        // strings play Helmholtz motion with each of the three laws. (The double bass
        // misses on some notes at every soft level, docs/testing.md: not asserted.)
        for kind in [
            InstrumentKind::Violin,
            InstrumentKind::Viola,
            InstrumentKind::Cello,
        ] {
            let open = kind.open_notes();
            for law in [
                FrictionModel::Stribeck,
                FrictionModel::LuGre,
                FrictionModel::ElastoPlastic,
            ] {
                for note in [open[0], open[open.len() - 1]] {
                    let (_, regime) = note_at(kind, Some(law), note, 0.0);
                    assert_eq!(regime, Some(Regime::Helmholtz), "{kind:?} {law:?} {note}");
                }
            }
        }
    }

    #[test]
    fn the_stribeck_laws_keep_helmholtz_motion_at_the_middle_dynamics() {
        // At CC11 64 the guard's bow (0.136 of the parameters' speed, 1.22 times farther
        // from the bridge) slips at about v_s, where paper A's Stribeck curve falls
        // steepest. With the force falling only as fast as the speed the violin's C#6,
        // the viola's D#3 and the cello's D#2 are raucous, with the static and the LuGre
        // law alike; with the force held under the slip's damping bound they play
        // Helmholtz motion.
        let e = 64.0 / 127.0;
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB * (1.0 - e) / 20.0);
        for (kind, note) in [
            (InstrumentKind::Violin, 85),
            (InstrumentKind::Viola, 51),
            (InstrumentKind::Cello, 39),
        ] {
            for law in [FrictionModel::Stribeck, FrictionModel::LuGre] {
                let g = guarded_bow(Some(law), kind, scale);
                assert!(g.force < g.speed, "{kind:?} {law:?}: {g:?}");
                // The guard's speed and distance with the force proportional to the
                // speed, bowed directly at full expression.
                let d = BowControl::default();
                let proportional = BowControl {
                    velocity_m_per_s: d.velocity_m_per_s * g.speed,
                    force_n: d.force_n * g.speed,
                    position_beta: d.position_beta * g.away,
                };
                let (_, before) = note_bowed(kind, Some(law), note, 1.0, proportional);
                assert_ne!(before, Some(Regime::Helmholtz), "{kind:?} {law:?} {note}");
                let (_, guarded) = note_at(kind, Some(law), note, e as f32);
                assert_eq!(guarded, Some(Regime::Helmholtz), "{kind:?} {law:?} {note}");
            }
        }
    }

    /// `note` on `kind` with point law `law` at expression `e` (sent before the note,
    /// velocity 0.8: the performer's accent and catch) and the parameters' bow `bow`:
    /// the slip fraction over beta as played and the regime, over the last 8 periods of
    /// 1.6 s.
    fn slip_over_beta(
        kind: InstrumentKind,
        law: FrictionModel,
        note: u8,
        e: f32,
        bow: BowControl,
    ) -> (f64, Option<Regime>) {
        let (mut p, setup) = note_on_at(kind, Some(law), note, e);
        let probe = probed(&mut p, &setup, bow, 1.6);
        let played = p.bow();
        let f0 = midi_to_hz(note as f64);
        let tail = &probe[probe.len() - (8.0 * FS / f0) as usize..];
        let v: Vec<f64> = tail.iter().map(|s| s.string_velocity as f64).collect();
        let v_b = played.velocity_m_per_s.abs();
        // 0.05 v_b as the playing-space map measures a cell (lab/src/playing_space.rs).
        let stats = crate::analysis::slip_stats(&v, v_b, FS, f0, 0.05 * v_b);
        (
            stats.slip_fraction / played.position_beta,
            classify_regime(tail, FS as f32, f0 as f32),
        )
    }

    #[test]
    fn the_stribeck_laws_slip_for_the_whole_beta_from_a_players_attack_at_cc11_85() {
        // At CC11 85 the Helmholtz slip passes 2 v_s, past the Stribeck curve's steep
        // part, and the slip's damping at that speed alone no longer holds the force:
        // with the force the speed alone gives, the performer's attack leaves some of
        // the LuGre law's notes in one short slip a period (0.62-0.71 beta,
        // docs/testing.md, "Dynamics"); taken over the slip's speeds from
        // STRIBECK_SLIP_SPAN of it, the bound holds the force lighter and every note
        // of the violin's, viola's and cello's 13 slips for beta (short: under 0.85 of
        // it, the map's criterion being 15 %).
        let e = 85.0 / 127.0;
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB * (1.0 - e) / 20.0);
        let law = FrictionModel::LuGre;
        let d = BowControl::default();
        let (mut held_short, mut unheld_short) = (Vec::new(), Vec::new());
        for kind in [
            InstrumentKind::Violin,
            InstrumentKind::Viola,
            InstrumentKind::Cello,
        ] {
            let g = guarded_bow(Some(law), kind, scale);
            assert!(g.force < 0.6 * g.speed, "{kind:?}: {g:?}");
            // The parameters' force raised so that the guard plays the speed's force.
            let unheld = BowControl {
                force_n: d.force_n * g.speed / g.force,
                ..d
            };
            let (low, _) = kind.note_range();
            for note in (low..=low + 36).step_by(3) {
                let (held, _) = slip_over_beta(kind, law, note, e as f32, d);
                let (short, _) = slip_over_beta(kind, law, note, e as f32, unheld);
                println!("{kind:?} {note}: {held:.3} beta held, {short:.3} at the speed's force");
                if held < 0.85 {
                    held_short.push((kind, note));
                }
                if short < 0.85 {
                    unheld_short.push((kind, note));
                }
            }
        }
        assert!(held_short.is_empty(), "{held_short:?}");
        // 10 of the 39 slip short at the speed's force on the machine this was measured
        // on; 6 asked, as a short slip is a regime the attack picks, which an FMA-less
        // machine's rounding may tip on a few notes.
        assert!(unheld_short.len() >= 6, "{unheld_short:?}");
    }

    #[test]
    fn the_static_laws_notes_sound_at_their_pitch_at_cc11_90_where_the_force_lets_go() {
        // Between CC11 85 and 95 the guard's force rises from 0.31 of the speed's to all
        // of it, and the static law's bowed pitch does not follow a line: with the
        // intonation table's rows at 85 and 95 alone, 15 of these 39 notes sat within
        // 5 cents at CC11 90 (most 5-19 cents sharp; docs/testing.md, "Dynamics"). With
        // the row at 17/24 they sound at their pitch. 5 cents: a player's "in tune as
        // played". 38 of 39 measured (the cello's A2 slips twice a period; the dynamics
        // sweep, at note velocity 100 rather than 0.8, 36); 35 asked, as the static
        // law's notes here tip between one and two slips a period with a few cents'
        // change of tuning, which an FMA-less machine's rounding may bring.
        let e = 90.0 / 127.0;
        let law = FrictionModel::Stribeck;
        let mut off = Vec::new();
        for kind in [
            InstrumentKind::Violin,
            InstrumentKind::Viola,
            InstrumentKind::Cello,
        ] {
            let (low, _) = kind.note_range();
            for note in (low..=low + 36).step_by(3) {
                let (mut p, setup) = note_on_at(kind, Some(law), note, e as f32);
                let (audio, probe) = bowed(&mut p, &setup, BowControl::default(), 1.6, 0.8);
                let f0 = midi_to_hz(note as f64);
                let c = crate::analysis::cents(
                    crate::analysis::peak_frequency_hz(&audio, FS, f0, 100.0),
                    f0,
                );
                let regime = classify_regime(&probe, FS as f32, f0 as f32);
                println!("{kind:?} {note}: {c:+.1} cents, {regime:?}");
                if !(c.abs() <= 5.0 && regime == Some(Regime::Helmholtz)) {
                    off.push((kind, note, c, regime));
                }
            }
        }
        assert!(off.len() <= 4, "{} of 39 off: {off:?}", off.len());
    }

    #[test]
    fn a_rubbed_objects_force_follows_the_speed_at_the_middle_dynamics() {
        // The strings' slip-damping bound is not the wine glass's: at half expression its
        // bow's force falls as its speed does (smoothing and the attack settled after
        // 0.5 s; 1e-6 is f32 rounding).
        let setup = Setup {
            rubbed: Some(crate::dsp::rubbed::RubbedPreset::WineGlass),
            ..Setup::default()
        };
        let mut p = Performer::new(setup.instrument);
        p.activate(&setup, FS).unwrap();
        p.configure(&setup);
        p.set_controller(11, 0.5);
        p.note_on(60, 0.8);
        let bow = BowControl::default();
        for _ in 0..(0.5 * FS) as usize {
            p.tick(bow);
        }
        let (v, f) = p.bowed_bow().expect("the object is bowed");
        let speed = (v as f64).abs() / bow.velocity_m_per_s;
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB * 0.5 / 20.0);
        assert!((speed - scale).abs() < 1e-6, "{speed}");
        assert!((f as f64 / bow.force_n - speed).abs() < 1e-6, "{f} at {v}");
    }

    #[test]
    fn the_hyperbolic_law_keeps_helmholtz_motion_at_the_middle_dynamics() {
        // At CC11 21 and 64 the guard's bow slips at 0.2 and 1 times the hyperbolic
        // curve's v0, where it falls steeply: with the force falling only as fast as the
        // speed these notes slip twice a period (the cello's F#2 at CC11 64 rattles);
        // with the force held under the slip's damping bound they play Helmholtz
        // motion. (Of 31 such notes tried at these two levels, 20 missed with the
        // speed's force and 1 with the guard's.) At full expression and at CC11 0
        // (where the slip is slowest and the friction's fall over it least) the force
        // stays as the speed's, or within 5 % of it.
        let law = Some(FrictionModel::Hyperbolic);
        let scale_at = |cc: f64| 10f64.powf(-DYNAMICS_RANGE_DB * (1.0 - cc / 127.0) / 20.0);
        for kind in InstrumentKind::ALL {
            assert_eq!(guarded_bow(law, kind, 1.0), GuardedBow::FULL);
            let softest = guarded_bow(law, kind, scale_at(0.0));
            assert!(
                softest.force >= 0.95 * softest.speed,
                "{kind:?}: {softest:?}"
            );
        }
        for (kind, note, cc) in [
            (InstrumentKind::Violin, 79, 21.0),
            (InstrumentKind::Violin, 88, 64.0),
            (InstrumentKind::Viola, 69, 21.0),
            (InstrumentKind::Viola, 62, 64.0),
            (InstrumentKind::Cello, 66, 21.0),
            (InstrumentKind::Cello, 42, 64.0),
        ] {
            let g = guarded_bow(law, kind, scale_at(cc));
            assert!(g.force < 0.7 * g.speed, "{kind:?}: {g:?}");
            let d = BowControl::default();
            let proportional = BowControl {
                velocity_m_per_s: d.velocity_m_per_s * g.speed,
                force_n: d.force_n * g.speed,
                position_beta: d.position_beta * g.away,
            };
            let (_, before) = note_bowed(kind, law, note, 1.0, proportional);
            assert_ne!(before, Some(Regime::Helmholtz), "{kind:?} {note}");
            let (_, guarded) = note_at(kind, law, note, (cc / 127.0) as f32);
            assert_eq!(guarded, Some(Regime::Helmholtz), "{kind:?} {note}");
        }
    }

    /// A soft note's gentle start (velocity under 64: the bow sets out slower and
    /// lighter) takes paper B's thermal bow no lower than its slowest scale, where its
    /// rosin still sticks and slips: at the softest expression and velocity 30, each
    /// instrument's highest open string a fifth up speaks (Helmholtz motion from then on)
    /// within [`super::super::stroke::ONSET_RISE_S`], before the gentle start has risen
    /// two thirds of the way (measured 64-161 ms; set out at 0.33 of the bow, as the point
    /// laws' is, they slid for 318-853 ms first).
    #[test]
    fn a_soft_thermal_note_speaks_within_its_gentle_starts_rise() {
        use crate::measure::regime::helmholtz_since;
        for kind in InstrumentKind::ALL {
            let setup = Setup {
                instrument: kind,
                point_law: None,
                ..Setup::default()
            };
            let note = kind.open_notes()[3] + 7;
            let mut p = Performer::new(kind);
            p.activate(&setup, FS).unwrap();
            // As the plugin does: the block's setup before its events.
            p.configure(&setup);
            p.set_controller(11, 0.0);
            p.note_on(note, 30.0 / 127.0);
            let bow = BowControl::default();
            let probe: Vec<ContactSample> = (0..(0.6 * FS) as usize)
                .map(|i| {
                    if i % 256 == 0 {
                        p.configure(&setup);
                    }
                    let frame = p.tick(bow);
                    ContactSample::new(&frame, &p.bow())
                })
                .collect();
            let f0 = midi_to_hz(note as f64) as f32;
            let speaks = helmholtz_since(&probe, FS as f32, f0).map(|k| k as f64 / FS);
            assert!(
                speaks.is_some_and(|s| s < super::super::stroke::ONSET_RISE_S),
                "{kind:?} {note}: speaks at {speaks:?} s"
            );
        }
    }

    #[test]
    fn with_the_window_guard_soft_dynamics_move_the_bow_from_the_bridge() {
        let mut p = cello();
        p.set_controller(11, 0.0);
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        for _ in 0..(0.5 * FS) as usize {
            p.tick(bow);
        }
        // The softest: the bow scale 10^(-range / 20), so the bow sits
        // scale^(-log10(2) / 3) = 2^(range / 60) times farther from the bridge (1e-6: the
        // smoothing's last step and rounding).
        assert!(
            (p.bow().position_beta / 0.1 - 2f64.powf(DYNAMICS_RANGE_DB / 60.0)).abs() < 1e-6,
            "{:?}",
            p.bow()
        );
        p.set_controller(11, 1.0);
        for _ in 0..(0.5 * FS) as usize {
            p.tick(bow);
        }
        assert_eq!(
            p.bow().position_beta,
            0.1,
            "full expression: the parameter's place"
        );
    }

    #[test]
    fn dynamics_raise_the_level_monotonically_and_keep_helmholtz_motion() {
        // The cello's D string, D3 to A3, at four levels: velocity and force scale
        // together, so the bow keeps its place in the window. Which limit cycle an attack
        // falls into is chaotic (a note's neighbour, or the same note a few cents
        // retuned, can settle in double slips for seconds: docs/playing-space.md), so the
        // test asks what the dynamics sweep measures across the range, most pairs in
        // Helmholtz motion (there, 78-89 of 91 for this law), not every one.
        let mut helmholtz = 0;
        let mut pairs = 0;
        for note in 50..=57u8 {
            let mut last = 0.0;
            for e in [0.25, 0.5, 0.75, 1.0] {
                let (rms, regime) = bowed_note_at(note, e);
                println!("note {note}, expression {e}: RMS {rms:.5}, {regime:?}");
                assert!(
                    rms > last,
                    "note {note}, expression {e}: RMS {rms} not above {last}"
                );
                last = rms;
                pairs += 1;
                helmholtz += usize::from(regime == Some(Regime::Helmholtz));
            }
        }
        // At least seven in eight: the sweep's share for this law, less a pair for the
        // smaller sample.
        assert!(
            8 * helmholtz >= 7 * pairs,
            "{helmholtz} of {pairs} in Helmholtz motion"
        );
        // The amplitude follows the bow velocity (Raman): expression 0.5 plays half the
        // range below full, within 3 dB (a slower bow rounds the corners more: the
        // output falls by about nine tenths of the bow's fall).
        let ratio_db = 20.0 * (bowed_at(0.5).0 / bowed_at(1.0).0).log10();
        assert!(
            (ratio_db + DYNAMICS_RANGE_DB / 2.0).abs() < 3.0,
            "{ratio_db:.1} dB"
        );
    }

    #[test]
    fn with_the_guard_the_intonation_follows_the_dynamics_and_without_it_stays_at_full() {
        use crate::dsp::intonation::{shipped, TunedModel};
        // F#3 on the cello's D string, 4 semitones up, hyperbolic law.
        let (note, string, semitones) = (54u8, 2usize, 4.0);
        let row = TunedModel::Point(FrictionModel::Hyperbolic).row();
        let table = shipped();
        for guard in [true, false] {
            let setup = Setup {
                dynamics_guard: guard,
                ..Setup::default()
            };
            let mut p = cello_with(&setup);
            p.set_controller(11, 1.0 / 3.0);
            p.note_on(note, 0.8);
            let bow = BowControl::default();
            for _ in 0..FS as usize {
                p.tick(bow);
            }
            let expression = if guard { 1.0 / 3.0 } else { 1.0 };
            let moved =
                table.correction_at(row, InstrumentKind::Cello, string, semitones, expression)
                    - table.correction_cents(row, InstrumentKind::Cello, string, semitones);
            let played = p.strings().string(string).fundamental_hz();
            let mut full = cello_with(&setup);
            full.note_on(note, 0.8);
            full.tick(bow);
            let at_full = full.strings().string(string).fundamental_hz();
            // The string is stopped lower by the table's extra correction at a third of
            // the range (the dynamics rest there after 1 s; 0.01 cents: the smoothing's
            // last step, which lands within 1e-9 of the target scale).
            let cents = 1200.0 * (played / at_full).log2();
            assert!(
                (cents + moved).abs() < 0.01,
                "guard {guard}: {cents} against {moved}"
            );
        }
    }

    /// Plays D3 for 3 s with the mod wheel up under `setup`, after `controllers`; returns
    /// the finger's offset in cents every sample.
    fn vibrato_cents(setup: &Setup, controllers: &[(u8, f32)]) -> Vec<f64> {
        let mut p = cello();
        p.configure(setup);
        p.set_controller(1, 1.0);
        for &(cc, v) in controllers {
            p.set_controller(cc, v);
        }
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        let centre = p.strings().string(string).fundamental_hz();
        (0..(3.0 * FS) as usize)
            .map(|_| {
                p.tick(bow);
                1200.0 * (p.strings().string(string).fundamental_hz() / centre).log2()
            })
            .collect()
    }

    /// The finger's offset after the vibrato's fade-in, and the samples where it crosses
    /// zero upward.
    fn steady_and_upward_crossings(cents: &[f64]) -> (&[f64], Vec<usize>) {
        let steady = &cents[((VIBRATO_DELAY_S + VIBRATO_FADE_S) * FS) as usize + 64..];
        let ups = steady
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
            .map(|(i, _)| i)
            .collect();
        (steady, ups)
    }

    /// Depth (largest offset, cents) and rate (upward zero crossings, Hz) after the fade-in.
    fn depth_and_rate(cents: &[f64]) -> (f64, f64) {
        let (steady, ups) = steady_and_upward_crossings(cents);
        let depth = steady.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let rate = (ups.len() - 1) as f64 * FS / (ups[ups.len() - 1] - ups[0]) as f64;
        (depth, rate)
    }

    #[test]
    fn the_mod_wheel_vibrato_moves_the_finger_at_its_rate_and_depth() {
        let cents = vibrato_cents(&Setup::default(), &[]);
        // Silent through the onset delay.
        let delay = (VIBRATO_DELAY_S * FS) as usize;
        // 1e-6 cents: rounding; the finger has not moved.
        assert!(cents[..delay - 64].iter().all(|c| c.abs() < 1e-6));
        // After the fade-in: depth and rate within 5 % of the setting (the drift wanders
        // by at most 4 % and 3 %).
        let (depth, rate) = depth_and_rate(&cents);
        println!("vibrato depth {depth:.2} cents, rate {rate:.3} Hz");
        assert!(
            (depth / MAX_VIBRATO_CENTS - 1.0).abs() < 0.05,
            "depth {depth}"
        );
        assert!((rate / VIBRATO_RATE_HZ - 1.0).abs() < 0.05, "rate {rate}");
    }

    #[test]
    fn the_vibrato_rate_follows_its_parameter_and_cc19_and_drifts_a_little() {
        let setup = Setup {
            vibrato_rate_hz: 7.0,
            ..Setup::default()
        };
        let (_, rate) = depth_and_rate(&vibrato_cents(&setup, &[]));
        // 5 %, as above: the drift moves the rate by at most 3 %.
        assert!((rate / 7.0 - 1.0).abs() < 0.05, "parameter: {rate}");
        // CC19 at 0: the slowest rate.
        let (_, rate) = depth_and_rate(&vibrato_cents(&setup, &[(19, 0.0)]));
        // 5 %, as above.
        assert!(
            (rate / VIBRATO_RATE_MIN_HZ - 1.0).abs() < 0.05,
            "CC19: {rate}"
        );
        // The drift: successive cycles are not all the same length, and none strays
        // further than the drift allows (3 %, plus 2 % for cycles counted to a sample
        // and the finger's 64-sample steps).
        let cents = vibrato_cents(&Setup::default(), &[]);
        let (_, ups) = steady_and_upward_crossings(&cents);
        let periods: Vec<f64> = ups.windows(2).map(|w| (w[1] - w[0]) as f64 / FS).collect();
        let nominal = 1.0 / VIBRATO_RATE_HZ;
        assert!(
            periods.iter().all(|t| (t / nominal - 1.0).abs() < 0.05),
            "{periods:?}"
        );
        let spread = periods.iter().fold(0.0f64, |m, t| m.max(*t))
            - periods.iter().fold(1.0f64, |m, t| m.min(*t));
        assert!(spread > 64.0 / FS, "no drift: {periods:?}");
    }

    #[test]
    fn without_controllers_a_down_stroke_settles_on_the_parameters_own_bow() {
        let mut p = cello();
        p.note_on(50, 0.5);
        let bow = BowControl {
            velocity_m_per_s: -0.37,
            force_n: 2.5,
            position_beta: 0.13,
        };
        // The attack: from rest to the asked speed, the force landing as asked (no accent
        // at half velocity).
        p.tick(bow);
        // One sample into the stroke's linear ramp from rest (35 ms at velocity 0.5):
        // 0.37 m/s / 1660, about 2e-4 m/s.
        assert!(p.bow().velocity_m_per_s.abs() < 0.01 && p.bow().force_n == bow.force_n);
        let attack = (stroke::ATTACK_SLOWEST_S * FS) as usize;
        for _ in 0..attack {
            p.tick(bow);
        }
        for _ in 0..1000 {
            p.tick(bow);
            assert_eq!(p.bow(), bow);
        }
    }
}
