//! The regime the string is in, read from the live contact samples.
//!
//! Schelleng's diagram names what a bowed string does at a given force and velocity;
//! [`classify_regime`] names what the simulation actually does, from the samples the editor
//! already copies out of the [`crate::editor::live::Scope`] ring, so the side panel can show it
//! beside the regime the Schelleng window predicts. [`SlipWatch`] reads slips the same way
//! one sample at a time, for the performer's attack on the audio thread.
//!
//! **How.** A sample slips where the string moves away from the bow:
//! `|v_s - v_b| > SLIP_FRACTION_OF_BOW * |v_b|`. A slip starts where a sticking sample is
//! followed by a slipping one, and counts if the run of slipping samples reaches
//! `SLIP_PEAK_OF_BOW * |v_b|` (shallower runs are ripples, not slips). Motion is
//! periodic with `n` slips per period when, for every slip onset `t_i`, the onset `n`
//! slips later, `t_(i+n)`, comes one period later: all the
//! spans `t_(i+n) - t_i` agree to [`PERIOD_JITTER`] and their median lies within
//! [`PERIOD_RANGE`] of the note's period. The smallest such `n` is the number of slips per
//! period (1: Raman's Helmholtz motion); if none fits, the slips are irregular: raucous.
//!
//! | regime | what the samples show |
//! |---|---|
//! | [`Regime::Silent`] | no friction (bow lifted, or no note), or bow and string at rest |
//! | [`Regime::Sliding`] | the bow moves but the string never sticks to it |
//! | [`Regime::Helmholtz`] | one slip per period, periodic |
//! | [`Regime::MultipleSlips`] | 2 or more slips per period, periodic |
//! | [`Regime::Raucous`] | slips at irregular intervals (aperiodic) |
//!
//! What the waveguide cello's D3 does at 0.1 m/s and beta 0.1 (window 0.040 .. 5.06 N;
//! the tests below render it): 0.005 N slides without sticking (the string barely moves:
//! no stick-slip below the lower edge, which the model shows as near silence rather than
//! a real bow's surface noise); 0.04 N, the lower edge, slips four times a period, 0.1 N
//! three times and 0.3 N twice; 1 and 3 N are Helmholtz motion; 5 N (the upper edge) and
//! above is raucous.
//!
//! ```
//! use colophony::measure::contact::ContactSample;
//! use colophony::measure::regime::{classify_regime, Regime};
//! let silence = vec![ContactSample::default(); 4096];
//! assert_eq!(classify_regime(&silence, 48_000.0, 146.8), Some(Regime::Silent));
//! ```

use super::contact::ContactSample;
use crate::dsp::vocabulary::INTERNAL_RATE_HZ;

/// A sample slips where the relative velocity exceeds this fraction of the bow velocity.
/// Sticking is `v_s = v_b` exactly for the point laws and within a creep far below `v_b` for
/// the bristle laws and the thermal bow's compliant hair; a Helmholtz slip moves the string
/// at `v_b / beta >= 2 v_b` against the bow. Half the bow velocity lies between the two.
pub const SLIP_FRACTION_OF_BOW: f32 = 0.5;
/// A run of slipping samples counts as a slip only if its relative velocity reaches this
/// multiple of the bow velocity somewhere. A Helmholtz slip reaches `v_b (1 - beta) / beta`,
/// 9 `v_b` at beta 0.1; a finite-width bow's precursor (the string dipping for a few
/// samples while the corner crosses the bow, paper B's partial slipping) and a bristle
/// law's creep stay below `v_b`.
pub const SLIP_PEAK_OF_BOW: f32 = 1.0;
/// Velocities below this count as rest, m/s: 60 dB below the ~1 m/s slip of a default
/// note, and above the ripple the model leaves on a resting string.
pub const MOTION_FLOOR_M_PER_S: f32 = 1e-3;
/// Friction below this fraction of the bow force counts as no contact (bow lifted, or no
/// note): a bow on the string rubs with `mu` of 0.2 .. 0.8.
pub const CONTACT_MU_FLOOR: f32 = 1e-3;
/// Largest spread of the one-period spans, as a fraction of the period: the onsets are
/// found to a sample and repeat to a sample in steady motion; 3 % (half a semitone) leaves
/// room for a bow force or pitch bend moving while the window is analysed.
pub const PERIOD_JITTER: f32 = 0.03;
/// The measured period may differ from the note's by this factor either way: the pitch
/// bend (2 semitones, 12 %) plus bow-force flattening.
pub const PERIOD_RANGE: f32 = 1.25;
/// Most slips per period recognised as periodic multiple slipping.
pub const MAX_SLIPS_PER_PERIOD: usize = 8;
/// Fewest periods of the note a window must hold to be classified (two spans of the
/// pattern must be seen).
pub const MIN_PERIODS: f32 = 2.5;

/// What the string does at the bow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// No friction (bow lifted or no note), or bow and string at rest.
    Silent,
    /// The bow slides over a string that never sticks to it.
    Sliding,
    /// One slip per period (Raman's Helmholtz motion).
    Helmholtz,
    /// This many slips (2 or more) per period, periodic.
    MultipleSlips(u8),
    /// Slips at irregular intervals.
    Raucous,
}

impl Regime {
    /// A short description for the editor.
    pub fn describe(self) -> String {
        match self {
            Regime::Silent => "silent".into(),
            Regime::Sliding => "sliding (the string never sticks)".into(),
            Regime::Helmholtz => "Helmholtz motion (1 slip per period)".into(),
            Regime::MultipleSlips(n) => format!("multiple slips ({n} per period)"),
            Regime::Raucous => "raucous (irregular slips)".into(),
        }
    }
}

/// Classifies `samples` (oldest first, at `sample_rate` Hz) of a note whose fundamental is
/// `f0_hz`. `None` if they span fewer than [`MIN_PERIODS`] periods.
pub fn classify_regime(samples: &[ContactSample], sample_rate: f32, f0_hz: f32) -> Option<Regime> {
    if !(sample_rate > 0.0 && f0_hz > 0.0) {
        return None;
    }
    let period = sample_rate / f0_hz;
    if (samples.len() as f32) < MIN_PERIODS * period {
        return None;
    }
    let in_contact = samples.iter().any(|s| s.mu.abs() > CONTACT_MU_FLOOR);
    let bow_moving = samples
        .iter()
        .any(|s| bow_velocity(s).abs() > MOTION_FLOOR_M_PER_S);
    let string_moving = samples
        .iter()
        .any(|s| s.string_velocity.abs() > MOTION_FLOOR_M_PER_S);
    if !in_contact || !(bow_moving || string_moving) {
        return Some(Regime::Silent);
    }
    let slipping = |s: &ContactSample| is_slipping(s, SLIP_FRACTION_OF_BOW);
    if samples.iter().all(slipping) {
        return Some(Regime::Sliding);
    }
    let onsets = slip_onsets(samples);
    Some(
        (1..=MAX_SLIPS_PER_PERIOD)
            .find(|&n| repeats_every_period(&onsets, n, period, sample_rate))
            .map_or(Regime::Raucous, |n| match n {
                1 => Regime::Helmholtz,
                n => Regime::MultipleSlips(n as u8),
            }),
    )
}

/// The bow velocity a contact sample was taken at, m/s.
fn bow_velocity(s: &ContactSample) -> f32 {
    s.string_velocity - s.relative_velocity
}

/// Whether the string moves against the bow by more than `fraction` of the bow velocity
/// (and more than [`MOTION_FLOOR_M_PER_S`]).
fn is_slipping(s: &ContactSample, fraction: f32) -> bool {
    s.relative_velocity.abs() > (fraction * bow_velocity(s).abs()).max(MOTION_FLOOR_M_PER_S)
}

/// The samples where slips begin (see the module doc): a sticking sample followed by a
/// slipping one, counted when the run of slipping samples reaches [`SLIP_PEAK_OF_BOW`]
/// times the bow velocity (shallower runs are ripples).
pub fn slip_onsets(samples: &[ContactSample]) -> Vec<usize> {
    let slipping = |s: &ContactSample| is_slipping(s, SLIP_FRACTION_OF_BOW);
    samples
        .windows(2)
        .enumerate()
        .filter(|(_, w)| !slipping(&w[0]) && slipping(&w[1]))
        .map(|(i, _)| i + 1)
        .filter(|&i| {
            samples[i..]
                .iter()
                .take_while(|s| slipping(s))
                .any(|s| is_slipping(s, SLIP_PEAK_OF_BOW))
        })
        .collect()
}

/// Where Helmholtz motion is established in `samples` (at `sample_rate` Hz, a note whose
/// fundamental is `f0_hz`): the first slip onset from which every slip to the end comes
/// one period after the one before, `None` if there is no such run of at least two
/// periods. The period is the median of the last three spans between slips, within [`PERIOD_RANGE`] of the note's; a span counts as one period within
/// [`PERIOD_JITTER`] of it (or two samples of the model, as [`classify_regime`] allows).
/// A note *speaks* at that sample: how long its attack took.
pub fn helmholtz_since(samples: &[ContactSample], sample_rate: f32, f0_hz: f32) -> Option<usize> {
    if !(sample_rate > 0.0 && f0_hz > 0.0) {
        return None;
    }
    let onsets = slip_onsets(samples);
    let spans: Vec<f32> = onsets.windows(2).map(|w| (w[1] - w[0]) as f32).collect();
    if spans.len() < 2 {
        return None;
    }
    let mut tail: Vec<f32> = spans[spans.len().saturating_sub(3)..].to_vec();
    tail.sort_by(f32::total_cmp);
    let period = tail[tail.len() / 2];
    let expected = sample_rate / f0_hz;
    if !(expected / PERIOD_RANGE..=expected * PERIOD_RANGE).contains(&period) {
        return None;
    }
    let tolerance = span_tolerance(period, sample_rate);
    let first_steady = spans
        .iter()
        .rposition(|s| (s - period).abs() > tolerance)
        .map_or(0, |i| i + 1);
    // The motion must still be going at the end: no more than a period and a half since
    // the last slip.
    let last = *onsets.last()?;
    let quiet_tail = (samples.len() - last) as f32 > 1.5 * period;
    (spans.len() - first_steady >= 2 && !quiet_tail).then(|| onsets[first_steady])
}

/// How far a span between slips may stray from a period of `period` samples and still
/// count as one: [`PERIOD_JITTER`] of it, or two samples of the model, each onset being
/// found to within one (the point strings run at 48 kHz whatever the host's rate and the
/// probe holds their last sample, so above 48 kHz an onset moves in steps of several host
/// samples).
fn span_tolerance(period: f32, sample_rate: f32) -> f32 {
    let model_sample = (sample_rate / INTERNAL_RATE_HZ as f32).max(1.0);
    (PERIOD_JITTER * period).max(2.0 * model_sample)
}

/// The slips of a string read as they happen, one contact sample at a time, by the rules
/// of [`slip_onsets`] and [`classify_regime`]: a slip starts where a sticking sample is
/// followed by a slipping one and counts once its run reaches [`SLIP_PEAK_OF_BOW`] times
/// the bow velocity; the string is in Helmholtz motion once the last [`HELMHOLTZ_SPANS`]
/// spans between slips each lie within [`span_tolerance`] of their median and that median
/// within [`PERIOD_RANGE`] of the note's period. No allocation: what the performer's
/// attack listens to on the audio thread (`crate::performer::catch`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipWatch {
    /// The note's period, samples.
    period: f32,
    sample_rate: f32,
    /// Samples seen.
    now: u32,
    /// Whether the last sample slipped, and whether its run has counted as a slip.
    slipping: bool,
    counted: bool,
    /// Where the run under way began.
    run_start: u32,
    /// The last slip onsets, oldest first, `seen` of them valid (at most the array's).
    onsets: [u32; HELMHOLTZ_SPANS + 1],
    seen: usize,
}

/// Spans between slips [`SlipWatch`] must see agree before it calls the motion Helmholtz:
/// four, as the playing-space map's catch asks of the classifier (four and a half periods).
pub const HELMHOLTZ_SPANS: usize = 4;

impl SlipWatch {
    /// A watch for a note of fundamental `f0_hz` sampled at `sample_rate` Hz (both finite
    /// and positive; otherwise it never reports Helmholtz motion).
    pub fn new(sample_rate: f32, f0_hz: f32) -> Self {
        let period = if sample_rate > 0.0 && f0_hz > 0.0 {
            sample_rate / f0_hz
        } else {
            f32::NAN
        };
        Self {
            period,
            sample_rate,
            now: 0,
            slipping: false,
            counted: false,
            run_start: 0,
            onsets: [0; HELMHOLTZ_SPANS + 1],
            seen: 0,
        }
    }

    /// Reads one contact sample; `true` while the motion is Helmholtz's (see the type).
    pub fn observe(&mut self, s: &ContactSample) -> bool {
        let slipping = is_slipping(s, SLIP_FRACTION_OF_BOW);
        if slipping && !self.slipping {
            self.run_start = self.now;
            self.counted = false;
        }
        self.slipping = slipping;
        let mut helmholtz = false;
        if slipping && !self.counted && is_slipping(s, SLIP_PEAK_OF_BOW) {
            self.counted = true;
            if self.seen == self.onsets.len() {
                self.onsets.copy_within(1.., 0);
                self.seen -= 1;
            }
            self.onsets[self.seen] = self.run_start;
            self.seen += 1;
            helmholtz = self.seen == self.onsets.len() && self.spans_agree();
        }
        self.now = self.now.saturating_add(1);
        helmholtz
    }

    /// Whether the held onsets' spans agree with each other and with the note's period.
    fn spans_agree(&self) -> bool {
        let mut spans = [0.0f32; HELMHOLTZ_SPANS];
        for (k, span) in spans.iter_mut().enumerate() {
            *span = (self.onsets[k + 1] - self.onsets[k]) as f32;
        }
        let mut sorted = spans;
        sorted.sort_by(f32::total_cmp);
        let median = sorted[sorted.len() / 2];
        let tolerance = span_tolerance(median, self.sample_rate);
        (self.period / PERIOD_RANGE..=self.period * PERIOD_RANGE).contains(&median)
            && spans.iter().all(|s| (s - median).abs() <= tolerance)
    }
}

/// Whether every onset is followed `n` onsets later by one a period later (see the module
/// doc), over at least two spans.
fn repeats_every_period(onsets: &[usize], n: usize, period: f32, sample_rate: f32) -> bool {
    if onsets.len() < n + 2 {
        return false;
    }
    let mut spans: Vec<f32> = onsets
        .iter()
        .zip(&onsets[n..])
        .map(|(a, b)| (b - a) as f32)
        .collect();
    spans.sort_by(f32::total_cmp);
    let median = spans[spans.len() / 2];
    let tolerance = span_tolerance(median, sample_rate);
    (period / PERIOD_RANGE..=period * PERIOD_RANGE).contains(&median)
        && spans.iter().all(|s| (s - median).abs() <= tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::bridge_data::shipped_bridge;
    use crate::dsp::friction::FrictionModel;
    use crate::dsp::instrument::Instrument;
    use crate::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
    use crate::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};

    const FS: f64 = 48_000.0;
    const D3: u8 = 50;
    /// Seconds bowed before the analysed window: past the 20 ms landing and the attack.
    const SETTLE_S: f64 = 1.0;
    /// Periods analysed, as the editor does.
    const PERIODS: f64 = 8.0;

    fn bow(force_n: f64) -> BowControl {
        BowControl {
            velocity_m_per_s: 0.1,
            force_n,
            position_beta: 0.1,
        }
    }

    /// The contact samples the plugin would write into the scope over the last
    /// [`PERIODS`] periods of D3, `tick` driving one instrument sample per call, as
    /// `Colophony::process` drives it.
    fn scope_window(
        mut tick: impl FnMut(usize) -> ContactSample,
        seconds: f64,
    ) -> Vec<ContactSample> {
        let total = (seconds * FS) as usize;
        let window = (PERIODS * FS / midi_to_hz(D3 as f64)).ceil() as usize;
        let samples: Vec<ContactSample> = (0..total).map(&mut tick).collect();
        samples[total - window..].to_vec()
    }

    /// Cello D3 on the waveguide string with `model`, bowed with `bow` for `SETTLE_S` plus
    /// the window (bow lifted at `release_s` if set).
    fn waveguide(
        model: FrictionModel,
        bow: BowControl,
        release_s: Option<f64>,
        bend_semitones: f64,
    ) -> Vec<ContactSample> {
        waveguide_settled(model, bow, release_s, bend_semitones, SETTLE_S)
    }

    /// [`waveguide`] after `settle_s` instead of `SETTLE_S`.
    fn waveguide_settled(
        model: FrictionModel,
        bow: BowControl,
        release_s: Option<f64>,
        bend_semitones: f64,
        settle_s: f64,
    ) -> Vec<ContactSample> {
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        cello.set_friction_model(model);
        cello.set_pitch_bend(bend_semitones);
        cello.note_on(D3);
        let release = release_s.map(|s| (s * FS) as usize);
        scope_window(
            |i| {
                if i % 256 == 0 {
                    cello.update_sleep();
                }
                if Some(i) == release {
                    cello.note_off(D3);
                }
                ContactSample::new(&cello.tick(bow), &bow)
            },
            settle_s + 0.2,
        )
    }

    fn detect(samples: &[ContactSample]) -> Option<Regime> {
        classify_regime(samples, FS as f32, midi_to_hz(D3 as f64) as f32)
    }

    fn hyperbolic(force_n: f64) -> Option<Regime> {
        detect(&waveguide(
            FrictionModel::Hyperbolic,
            bow(force_n),
            None,
            0.0,
        ))
    }

    #[test]
    fn cello_d3_inside_the_schelleng_window_is_helmholtz_motion() {
        // 1 N: inside 0.040 .. 5.06 N.
        assert_eq!(hyperbolic(1.0), Some(Regime::Helmholtz));
    }

    #[test]
    fn cello_d3_far_above_the_window_is_raucous() {
        // 10 N, the largest bow force, twice F_max.
        assert_eq!(hyperbolic(10.0), Some(Regime::Raucous));
    }

    #[test]
    fn cello_d3_at_the_lower_edge_of_the_window_slips_several_times_per_period() {
        // F_min is Schelleng's estimate: the model slips four times a period at it and
        // still three times at 2.5 F_min.
        for force_n in [0.04, 0.1] {
            let regime = hyperbolic(force_n);
            assert!(
                matches!(regime, Some(Regime::MultipleSlips(n)) if n >= 2),
                "{force_n} N: {regime:?}"
            );
        }
    }

    #[test]
    fn cello_d3_far_below_the_window_slides_without_sticking() {
        // 0.005 N, an eighth of F_min: the bow never catches the string.
        assert_eq!(hyperbolic(0.005), Some(Regime::Sliding));
    }

    #[test]
    fn a_lifted_bow_reads_silent_while_the_string_rings_on() {
        // Lifted at 1 s, 0.15 s before the window: the 20 ms lift ramp is over, the
        // string rings on.
        let samples = waveguide(FrictionModel::Hyperbolic, bow(1.0), Some(SETTLE_S), 0.0);
        // Bowed, the string at the bow jumps by v_b / beta = 1 m/s; 0.2 s of ringing at
        // Q1 500 (amplitude time constant 1.08 s) keeps over 0.8 of that.
        assert!(
            samples.iter().any(|s| s.string_velocity.abs() > 0.01),
            "the string rings"
        );
        assert_eq!(detect(&samples), Some(Regime::Silent));
    }

    #[test]
    fn before_any_note_the_scope_reads_silent() {
        // The plugin writes the strings' all-zero frames while nothing plays.
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        let samples = scope_window(
            |_| ContactSample::new(&cello.tick(bow(1.0)), &bow(1.0)),
            0.2,
        );
        assert_eq!(detect(&samples), Some(Regime::Silent));
    }

    #[test]
    fn helmholtz_motion_is_recognised_under_full_pitch_bend() {
        // The editor knows the note, not the bend: 2 semitones up and down.
        for bend in [2.0, -2.0] {
            let samples = waveguide(FrictionModel::Hyperbolic, bow(1.0), None, bend);
            assert_eq!(detect(&samples), Some(Regime::Helmholtz), "bend {bend}");
        }
    }

    #[test]
    fn bristle_creep_while_sticking_is_not_counted_as_slips() {
        // LuGre's bristles creep while the string sticks: counted from a 0.01 m/s
        // (0.1 v_b) threshold, this render slips nine times a period; from v_b / 2, once.
        // LuGre's cello D3 at 1 N double-slips for about 1.3 s after the bow lands (measured
        // in 0.1 s windows, with and without the bow hair) before it settles: 2 s.
        let samples = waveguide_settled(FrictionModel::LuGre, bow(1.0), None, 0.0, 2.0);
        assert_eq!(detect(&samples), Some(Regime::Helmholtz));
    }

    #[test]
    fn thermal_cello_d3_at_one_newton_is_helmholtz_motion() {
        // Paper B's bow: the middle node's velocity includes the hair's compliance.
        let bridge = shipped_bridge(InstrumentKind::Cello).modes;
        let mut cello = ThermalInstrument::new(
            InstrumentKind::Cello,
            &bridge,
            FS,
            ThermalSettings::default(),
        )
        .unwrap();
        cello.note_on(D3);
        let b = bow(1.0);
        let samples = scope_window(
            |i| {
                if i % 256 == 0 {
                    cello.update_sleep();
                }
                ContactSample::new(&cello.tick(b), &b)
            },
            SETTLE_S + 0.2,
        );
        assert_eq!(detect(&samples), Some(Regime::Helmholtz));
    }

    #[test]
    fn a_window_shorter_than_two_and_a_half_periods_is_not_classified() {
        let samples = vec![ContactSample::default(); 800];
        // D3: 327 samples a period, 2.45 periods.
        assert_eq!(detect(&samples), None);
        assert_eq!(classify_regime(&samples, 48_000.0, 0.0), None);
    }

    /// A synthetic stick-slip train: sticking at 0.1 m/s, slipping at -0.9 m/s for
    /// `slip_len` samples from each onset.
    fn train(onsets: &[usize], len: usize, slip_len: usize) -> Vec<ContactSample> {
        let mut out = vec![
            ContactSample {
                string_velocity: 0.1,
                relative_velocity: 0.0,
                mu: 0.3,
            };
            len
        ];
        for &t in onsets {
            for s in out.iter_mut().skip(t).take(slip_len) {
                *s = ContactSample {
                    string_velocity: -0.9,
                    relative_velocity: -1.0,
                    mu: 0.2,
                };
            }
        }
        out
    }

    #[test]
    fn slips_one_period_apart_but_jittered_beyond_three_percent_are_raucous() {
        // Period 327 samples; every other onset 20 samples (6 %) late.
        let onsets: Vec<usize> = (0..10)
            .map(|k| k * 327 + if k % 2 == 1 { 20 } else { 0 })
            .collect();
        assert_eq!(detect(&train(&onsets, 3300, 30)), Some(Regime::Raucous));
        let steady: Vec<usize> = (0..10).map(|k| k * 327).collect();
        assert_eq!(detect(&train(&steady, 3300, 30)), Some(Regime::Helmholtz));
    }

    #[test]
    fn two_slips_per_period_with_unequal_spacing_are_multiple_slips() {
        let onsets: Vec<usize> = (0..10).flat_map(|k| [k * 327, k * 327 + 100]).collect();
        assert_eq!(
            detect(&train(&onsets, 3300, 30)),
            Some(Regime::MultipleSlips(2))
        );
    }

    #[test]
    fn helmholtz_motion_is_established_at_the_first_slip_of_the_steady_run() {
        // Irregular slips (a raucous attack), then one slip every 327 samples from 1000.
        let mut onsets = vec![50, 200, 260, 600, 700];
        onsets.extend((0..8).map(|k| 1000 + k * 327));
        let samples = train(&onsets, 1000 + 8 * 327, 30);
        assert_eq!(helmholtz_since(&samples, FS as f32, 146.8), Some(1000));
        // Two slips a period to the end never establish Helmholtz motion at the note's
        // period ...
        let doubled: Vec<usize> = (0..10).flat_map(|k| [k * 327, k * 327 + 100]).collect();
        assert_eq!(
            helmholtz_since(&train(&doubled, 3300, 30), FS as f32, 146.8),
            None
        );
        // ... nor does motion that stopped: the last slip three periods before the end.
        let stopped: Vec<usize> = (0..6).map(|k| k * 327).collect();
        assert_eq!(
            helmholtz_since(&train(&stopped, 9 * 327, 30), FS as f32, 146.8),
            None
        );
    }
}
