//! Bow strokes and attacks: which way the bow moves for each note, and how it starts.
//!
//! A *separate* note (one that lands while no key is held) starts a new stroke: the bow
//! starts from rest, in the direction the [`StrokeMode`] gives (alternating down and up by
//! default, as string players play détaché), and accelerates to the asked speed. A note
//! that lands while another is held is *legato*: the stroke goes on, same direction, no
//! new attack. When a new stroke starts while the string still rings, the bow passes
//! through zero velocity with its force on: the bow change's own transient, made by the
//! string.
//!
//! The note velocity sets the attack: how fast the bow reaches its speed (geometrically
//! from [`ATTACK_SLOWEST_S`] at velocity 0 to [`ATTACK_FASTEST_S`] at 127), a landing
//! accent (extra force, up to [`ACCENT_MAX`] of the bow force at velocity 127, none at
//! 64 and below, decaying over [`ACCENT_S`]: the bite of a martelé), and below 64 a gentle
//! start: a soft note sets out with a slower and lighter bow, both rising to the asked
//! bow over [`ONSET_RISE_S`], as a player's piano entry. Speed and force rise together, so
//! the bow keeps its place in Schelleng's window (both of its limits are proportional to
//! the bow speed) while the level follows the speed (Helmholtz amplitude `v_b / beta`).
//! The bow only ever speeds up toward the asked bow: a bow that slows down under a string
//! still carrying a louder motion makes extra slips, so a hard note gets its bite from
//! the landing accent and the fast ramp, never from a speed above the asked one. Guettler's attack diagram
//! (bow force against bow acceleration from rest) marks which pairs give Helmholtz motion
//! from the first slip. Measured on this model (cello D3, hyperbolic law, beta 0.1,
//! 0.1 m/s, forces 0.2-4.5 N, accelerations 0.25-32 m/s^2 and a bow landing at speed,
//! at 48 and 192 kHz) no pair settles in under about 50 ms, and the settling time jumps
//! between neighbouring pairs: the diagram has no clean region to aim at here, so the
//! velocity maps to the acceleration by feel, harder is faster (docs/playing-space.md).
//! Above mezzo a bow asked lighter than the defaults sit in Schelleng's window also
//! catches the string first ([`super::catch`]).
//!
//! ```
//! use colophony::performer::stroke::{Stroke, StrokeMode};
//! let mut stroke = Stroke::new(48_000.0);
//! stroke.start(StrokeMode::Alternate, 1.0); // a separate note, hardest attack
//! let first = stroke.tick();
//! for _ in 0..48_000 {
//!     stroke.tick();
//! }
//! let (speed, force) = stroke.tick();
//! assert!(first.0.abs() < 0.01 && speed == 1.0 && force == 1.0);
//! stroke.start(StrokeMode::Alternate, 1.0); // the next separate note: up-bow
//! for _ in 0..48_000 {
//!     stroke.tick();
//! }
//! assert_eq!(stroke.tick().0, -1.0);
//! ```

use crate::dsp::bounce::{BounceParams, BouncingBow};

/// The direction of each new stroke.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StrokeMode {
    /// Down, up, down...: each separate note reverses the bow (the default).
    #[default]
    Alternate,
    /// Every stroke in the bow velocity parameter's own direction.
    Down,
    /// Every stroke against the bow velocity parameter's direction.
    Up,
}

/// Time to full bow speed at note velocity 127, s (a = 10 m/s^2 at 0.1 m/s).
pub const ATTACK_FASTEST_S: f64 = 0.01;
/// Time to full bow speed at note velocity 0, s (a = 0.8 m/s^2 at 0.1 m/s).
pub const ATTACK_SLOWEST_S: f64 = 0.12;
/// Landing accent at velocity 127: extra force, a fraction of the bow force.
pub const ACCENT_MAX: f64 = 0.5;
/// Decay time of the landing accent, s.
pub const ACCENT_S: f64 = 0.04;
/// The gentle start's depth: a note of velocity `v` (0..=1) below 64/127 sets out at
/// `2^(ONSET_OCTAVES_PER_VELOCITY (v - 64/127))` of the asked bow speed and force: x0.12
/// (-18.2 dB) at velocity 0, x0.33 (-9.7 dB) at 30, x1 from 64 up.
pub const ONSET_OCTAVES_PER_VELOCITY: f64 = 6.0;
/// Time constant of the gentle start's rise to the asked bow, s.
pub const ONSET_RISE_S: f64 = 0.2;

/// The note velocity as a MIDI 7-bit step, 0..=1: the plugin receives velocities as f32
/// from CLAP, VST3 and MIDI files; stepping them makes every path play the same attack.
pub fn velocity_step(velocity: f32) -> f64 {
    if !velocity.is_finite() {
        return 1.0;
    }
    ((velocity as f64).clamp(0.0, 1.0) * 127.0).round() / 127.0
}

/// The stroke in progress (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    sample_rate_hz: f64,
    /// +1 down (the parameter's direction), -1 up.
    direction: f64,
    /// Bow speed as a signed fraction of the asked speed.
    speed: f64,
    /// Change of `speed` per sample while accelerating.
    step: f64,
    /// Extra force, a fraction of the bow force, and its decay per sample.
    accent: f64,
    accent_decay: f64,
    /// The gentle start's departure from 1 (on bow speed and force alike; 0 or below), and
    /// its decay per sample.
    onset: f64,
    onset_decay: f64,
    /// Whether a stroke has started since activation (the first is down).
    started: bool,
    /// Tremolo: samples per stroke (0: none), samples left of this one, and the speed's
    /// step per sample through a reversal.
    tremolo_samples: u32,
    tremolo_left: u32,
    tremolo_step: f64,
    /// Spiccato: the bow bouncing on the string, its force over [`BOUNCE_REFERENCE_N`]
    /// multiplying the asked force.
    bounce: Option<BouncingBow>,
    /// Sautillé: the hand's push on the bouncing bow at its peak, N (0: not driven), once
    /// a stroke, and the bounce frequency it was set up for.
    drive_n: f64,
    drive_hz: f64,
    /// The velocity (0..=1) the last stroke started with.
    velocity: f64,
}

/// The bouncing bow's pull toward the string, N: half a violin bow's 60 g weight at the
/// contact, the hand holding none of it (a choice).
pub const SPICCATO_PULL_N: f64 = 0.3;
/// How high the bow is dropped at velocity 127, m (lower as the square of the velocity).
pub const SPICCATO_DROP_M: f64 = 0.015;
/// The bouncing bow's force that plays the asked bow force, N.
pub const BOUNCE_REFERENCE_N: f64 = 1.0;

/// The bounce frequencies a sautillé can use, Hz: where along the bow Askenfelt and
/// Guettler measured a violin bow bouncing (8-20 Hz, [`crate::dsp::bounce`]).
pub const SAUTILLE_BOUNCE_HZ: std::ops::RangeInclusive<f64> = 8.0..=20.0;
/// At velocity 1 the hand's push would swing the hair's force this many times the pull
/// each way, if the hair stayed on the string (a choice: it leaves the string for part of
/// each stroke from velocity 0.67 up).
pub const SAUTILLE_LIFT: f64 = 1.5;

/// A tremolo reversal takes this share of a stroke: the bow slows, stops and speeds up
/// the other way over it, and travels at the asked speed for the rest.
pub const TREMOLO_REVERSAL_SHARE: f64 = 0.3;

impl Stroke {
    /// At rest before any note: the bow moves as the parameters say (speed 1, down).
    pub fn new(sample_rate_hz: f64) -> Self {
        let fs = super::usable_rate(sample_rate_hz);
        Self {
            sample_rate_hz: fs,
            direction: 1.0,
            speed: 1.0,
            step: 0.0,
            accent: 0.0,
            accent_decay: (-1.0 / (ACCENT_S * fs)).exp(),
            onset: 0.0,
            onset_decay: (-1.0 / (ONSET_RISE_S * fs)).exp(),
            started: false,
            tremolo_samples: 0,
            tremolo_left: 0,
            tremolo_step: 0.0,
            bounce: None,
            drive_n: 0.0,
            drive_hz: 0.0,
            velocity: 0.8,
        }
    }

    /// Spiccato (`true`): the stroke just started lands the bow on the string as if
    /// dropped from a height its velocity `velocity` (0..=1) sets (the drop before the
    /// note, so the note lands on time), and it bounces
    /// ([`crate::dsp::bounce`]) until the next stroke; `false`: the bow stays on.
    pub fn set_spiccato(&mut self, spiccato: bool, velocity: f64) {
        if !spiccato {
            // A driven bounce (sautillé) is [`Stroke::set_sautille`]'s to end.
            if self.drive_n == 0.0 {
                self.bounce = None;
            }
            return;
        }
        self.drive_n = 0.0;
        self.bounce = Some({
            let mut bow = BouncingBow::new(
                BounceParams::default(),
                SPICCATO_PULL_N,
                self.sample_rate_hz,
            );
            let v = velocity.clamp(0.1, 1.0);
            bow.land_from(SPICCATO_DROP_M * v * v);
            bow
        });
    }

    /// Sautillé (`Some((stroke_s, velocity))`): the bow reverses every `stroke_s` seconds,
    /// as in tremolo, and the hand drives its bounce once a stroke ([`BouncingBow::driven`]):
    /// it bounces at `1 / stroke_s` (held within [`SAUTILLE_BOUNCE_HZ`], the bow's measured
    /// range), highest at each turn and pressing hardest mid-stroke. The velocity (0..=1)
    /// sets the push: at 1 the hair's force would swing [`SAUTILLE_LIFT`] times the pull
    /// each way if the hair stayed on, so it leaves the string for part of each stroke;
    /// below `1 / SAUTILLE_LIFT` the hair stays on and only its force swings. `None` ends
    /// it (and the tremolo).
    pub fn set_sautille(&mut self, sautille: Option<(f64, f64)>) {
        let Some((stroke_s, velocity)) = sautille.filter(|(s, _)| s.is_finite() && *s > 0.0) else {
            if self.drive_n != 0.0 {
                self.drive_n = 0.0;
                self.bounce = None;
                self.set_tremolo(None);
            }
            return;
        };
        self.set_tremolo(Some(stroke_s));
        let hz = (1.0 / stroke_s).clamp(*SAUTILLE_BOUNCE_HZ.start(), *SAUTILLE_BOUNCE_HZ.end());
        let params = BounceParams {
            bounce_hz: hz,
            ..BounceParams::default()
        };
        // The hair's force per newton of push in the linear (never leaving) motion:
        // |k + i c w| |H|.
        let (m, k) = (params.mass_kg, params.stiffness_n_per_m());
        let c = 2.0 * params.damping_ratio() * (k * m).sqrt();
        let w = 2.0 * std::f64::consts::PI / stroke_s;
        let gain = k.hypot(c * w) / (k - m * w * w).hypot(c * w);
        let push = velocity.clamp(0.0, 1.0) * SAUTILLE_LIFT * SPICCATO_PULL_N / gain;
        if self.drive_n == 0.0 || self.drive_hz != hz || self.bounce.is_none() {
            self.bounce = Some(BouncingBow::driven(
                params,
                SPICCATO_PULL_N,
                push,
                1.0 / stroke_s,
                self.sample_rate_hz,
            ));
            self.drive_hz = hz;
        }
        // A push of 0 is no drive: keep a hair's breadth of one so the bow stays driven.
        self.drive_n = push.max(1e-9);
    }

    /// Tremolo: the bow reverses every `stroke_s` seconds (each reversal through
    /// [`TREMOLO_REVERSAL_SHARE`] of a stroke) until called with `None`. Counted from now;
    /// a stroke length already under way is kept.
    pub fn set_tremolo(&mut self, stroke_s: Option<f64>) {
        match stroke_s.filter(|s| s.is_finite() && *s > 0.0) {
            Some(s) => {
                let samples = (s * self.sample_rate_hz)
                    .round()
                    .clamp(2.0, u32::MAX as f64) as u32;
                if samples != self.tremolo_samples {
                    self.tremolo_samples = samples;
                    self.tremolo_left = samples;
                    // A reversal goes from +1 to -1: twice the speed in its share.
                    self.tremolo_step = 2.0 / (TREMOLO_REVERSAL_SHARE * samples as f64).max(1.0);
                }
            }
            None => {
                self.tremolo_samples = 0;
                self.tremolo_left = 0;
            }
        }
    }

    /// A separate note with velocity `velocity` (a [`velocity_step`]): a new stroke from
    /// rest in the direction `mode` gives.
    pub fn start(&mut self, mode: StrokeMode, velocity: f64) {
        self.direction = match mode {
            StrokeMode::Alternate if self.started => -self.direction,
            StrokeMode::Alternate | StrokeMode::Down => 1.0,
            StrokeMode::Up => -1.0,
        };
        self.started = true;
        self.tremolo_left = self.tremolo_samples;
        let v = velocity.clamp(0.0, 1.0);
        self.velocity = v;
        let attack_s = ATTACK_SLOWEST_S * (ATTACK_FASTEST_S / ATTACK_SLOWEST_S).powf(v);
        self.step = 1.0 / (attack_s * self.sample_rate_hz).max(1.0);
        self.speed = 0.0;
        let mezzo = 64.0 / 127.0;
        self.accent = ACCENT_MAX * ((v - mezzo) / (1.0 - mezzo)).max(0.0);
        self.onset = (ONSET_OCTAVES_PER_VELOCITY * (v - mezzo)).min(0.0).exp2() - 1.0;
    }

    /// Keeps the stroke's gentle start from setting out below `floor` (0..=1) of the asked
    /// bow: for a contact that stops sticking under a bow speed (paper B's thermal bow,
    /// [`super::gesture::THERMAL_SLOWEST_SCALE`]). A floor of 1 leaves no gentle start.
    pub fn limit_onset(&mut self, floor: f64) {
        self.onset = self.onset.max(floor.clamp(0.0, 1.0) - 1.0);
    }

    /// The velocity (0..=1) the last stroke started with.
    pub fn velocity(&self) -> f64 {
        self.velocity
    }

    /// The bow direction of the stroke in progress (+1 down, -1 up).
    pub fn direction(&self) -> f64 {
        self.direction
    }

    /// Advances one sample; returns (the factor on the asked bow velocity, the factor on
    /// the asked force). Three comparisons once the attack is over.
    #[inline]
    pub fn tick(&mut self) -> (f64, f64) {
        if self.tremolo_samples != 0 {
            self.tremolo_tick();
        }
        let (speed, mut force) = self.tick_ramp();
        if let Some(bow) = &mut self.bounce {
            let contact = if self.drive_n != 0.0 {
                // The stroke's phase, 0 where the bow's speed crosses zero in its turn (half
                // way through the reversal), where the bow is highest.
                let phase = 1.0
                    - self.tremolo_left as f64 / self.tremolo_samples.max(1) as f64
                    - 0.5 * TREMOLO_REVERSAL_SHARE;
                bow.tick_pushed(self.drive_n * (std::f64::consts::TAU * phase).sin())
            } else {
                bow.tick()
            };
            force *= contact / BOUNCE_REFERENCE_N;
        }
        if self.onset == 0.0 {
            return (speed, force);
        }
        self.onset *= self.onset_decay;
        // A thousandth of the bow (0.01 dB): done, after at most 1.32 s, and this sample
        // already plays the asked bow (the settled stroke's factors, exactly).
        if self.onset.abs() < 1e-3 {
            self.onset = 0.0;
            return (speed, force);
        }
        let level = 1.0 + self.onset;
        (speed * level, force * level)
    }

    /// One sample of tremolo: at each stroke's end the bow turns, at the reversal's rate
    /// (or the attack's, if faster).
    #[cold]
    fn tremolo_tick(&mut self) {
        self.tremolo_left = self.tremolo_left.saturating_sub(1);
        if self.tremolo_left == 0 {
            self.tremolo_left = self.tremolo_samples;
            self.direction = -self.direction;
            self.step = self.step.max(self.tremolo_step);
        }
    }

    /// The ramp to full speed and the landing accent, one sample.
    #[inline]
    fn tick_ramp(&mut self) -> (f64, f64) {
        let target = self.direction;
        if self.speed != target {
            self.speed = if target > 0.0 {
                (self.speed + self.step).min(target)
            } else {
                (self.speed - self.step).max(target)
            };
        }
        if self.accent != 0.0 {
            self.accent *= self.accent_decay;
            // A thousandth of the force (0.01 dB): done, after about 0.25 s.
            if self.accent < 1e-3 {
                self.accent = 0.0;
            }
        }
        (self.speed, 1.0 + self.accent)
    }

    /// Whether the attack is over (full speed in the stroke's direction, no accent):
    /// [`Stroke::tick`] would return `(direction, 1)` and change nothing.
    #[inline]
    pub fn is_settled(&self) -> bool {
        self.speed == self.direction
            && self.accent == 0.0
            && self.onset == 0.0
            && self.tremolo_samples == 0
            && self.bounce.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 48_000.0;

    #[test]
    fn alternate_strokes_reverse_and_one_way_strokes_keep_their_direction() {
        let mut s = Stroke::new(FS);
        let mut directions = Vec::new();
        for _ in 0..4 {
            s.start(StrokeMode::Alternate, 0.5);
            directions.push(s.direction());
        }
        assert_eq!(directions, [1.0, -1.0, 1.0, -1.0]);
        for mode in [StrokeMode::Down, StrokeMode::Up] {
            let want = if mode == StrokeMode::Down { 1.0 } else { -1.0 };
            for _ in 0..3 {
                s.start(mode, 0.5);
                assert_eq!(s.direction(), want);
            }
        }
    }

    #[test]
    fn a_harder_note_reaches_full_speed_sooner_and_lands_with_more_force() {
        // Samples to full speed and the first sample's force factor, per velocity.
        // The ramp alone (the onset level is the next test's).
        let attack = |velocity: f64| {
            let mut s = Stroke::new(FS);
            s.start(StrokeMode::Down, velocity);
            let force = s.tick_ramp().1;
            let mut n = 1;
            while s.tick_ramp().0 < 1.0 {
                n += 1;
            }
            (n as f64 / FS, force)
        };
        let (slow, soft) = attack(0.0);
        let (mid, mid_force) = attack(0.5);
        let (fast, hard) = attack(1.0);
        // To within a sample of the documented times.
        assert!((slow - ATTACK_SLOWEST_S).abs() <= 2.0 / FS, "{slow}");
        assert!((fast - ATTACK_FASTEST_S).abs() <= 2.0 / FS, "{fast}");
        assert!(slow > mid && mid > fast);
        assert_eq!((soft, mid_force), (1.0, 1.0));
        // The accent decays over 40 ms (`ACCENT_S`): by the first sample it has lost 1/1920
        // of itself.
        assert!((hard - (1.0 + ACCENT_MAX)).abs() < 0.01, "{hard}");
    }

    #[test]
    fn a_soft_note_starts_slower_and_lighter_together_then_rises_and_never_overshoots() {
        // The stroke's factors `t` seconds after the landing, and the same stroke's without
        // its gentle start (the ramp and the accent alone).
        let at = |velocity: f64, t: f64| {
            let mut s = Stroke::new(FS);
            s.start(StrokeMode::Down, velocity);
            let mut plain = s;
            plain.onset = 0.0;
            let (mut out, mut without) = ((0.0, 0.0), (0.0, 0.0));
            for _ in 0..(t * FS) as usize {
                out = s.tick();
                without = plain.tick();
            }
            (out, without)
        };
        for velocity in [0.0, 30.0 / 127.0, 64.0 / 127.0, 120.0 / 127.0, 1.0] {
            for t in [0.005, 0.02, 0.08, 0.3] {
                let ((speed, force), (ramp, landing)) = at(velocity, t);
                // Speed and force carry the same level, so the bow keeps its place in
                // Schelleng's window (1e-12: rounding of two products) ...
                assert!(
                    (speed / ramp - force / landing).abs() < 1e-12,
                    "{velocity} at {t} s"
                );
                // ... and the bow never runs faster than the ramp asks.
                assert!(speed <= ramp, "{velocity} at {t} s");
            }
        }
        // At 0.15 s every ramp is over; the level is the gentle start's, risen by
        // exp(-0.15 s / ONSET_RISE_S) of its depth.
        let level = |velocity: f64| at(velocity, 0.15).0 .0;
        let left = (-0.15 / ONSET_RISE_S).exp();
        for velocity in [0.0, 30.0 / 127.0] {
            let depth = (ONSET_OCTAVES_PER_VELOCITY * (velocity - 64.0 / 127.0)).exp2() - 1.0;
            // 1e-3: the rise is applied per sample; a sample's offset is 0.01 % of it.
            assert!(
                (level(velocity) - (1.0 + depth * left)).abs() < 1e-3,
                "{velocity}"
            );
        }
        assert!(level(30.0 / 127.0) < level(50.0 / 127.0));
        assert_eq!(level(64.0 / 127.0), 1.0);
        assert_eq!(level(1.0), 1.0);
        // Risen: after 1.4 s (velocity 0's depth falls under a thousandth after
        // ONSET_RISE_S ln(753), 1.32 s) the stroke plays the asked bow exactly.
        let mut s = Stroke::new(FS);
        s.start(StrokeMode::Down, 0.0);
        for _ in 0..(1.4 * FS) as usize {
            s.tick();
        }
        assert!(s.is_settled());
        assert_eq!(s.tick(), (1.0, 1.0));
    }

    #[test]
    fn a_limited_gentle_start_sets_out_no_lower_than_its_floor() {
        // After the ramp (velocity 30: 0.1 s at most), the level of the gentle start
        // limited to `floor` against the unlimited one, at 0.11 s.
        let level = |floor: Option<f64>| {
            let mut s = Stroke::new(FS);
            s.start(StrokeMode::Down, 30.0 / 127.0);
            if let Some(floor) = floor {
                s.limit_onset(floor);
            }
            let mut out = (0.0, 0.0);
            for _ in 0..(0.11 * FS) as usize {
                out = s.tick();
            }
            out.0
        };
        let left = (-0.11 / ONSET_RISE_S).exp();
        let free = level(None);
        // 0.33 of the bow at velocity 30 is under a floor of 0.6: the limited start sets
        // out at 0.6 and rises from there (1e-3: the rise applied per sample).
        assert!(((level(Some(0.6)) - (1.0 - 0.4 * left)).abs()) < 1e-3);
        assert!(level(Some(0.6)) > free);
        // A floor under the start's own depth changes nothing; a floor of 1 (or above,
        // clamped) leaves no gentle start at all.
        assert_eq!(level(Some(0.1)), free);
        assert_eq!(level(Some(1.0)), 1.0);
        assert_eq!(level(Some(7.0)), 1.0);
    }

    #[test]
    fn velocities_step_to_midi_resolution_and_bad_values_are_safe() {
        assert_eq!(velocity_step(64.0 / 127.0), 64.0 / 127.0);
        assert_eq!(velocity_step((64.0f64 / 127.0) as f32), 64.0 / 127.0);
        assert_eq!(velocity_step(2.0), 1.0);
        assert_eq!(velocity_step(-1.0), 0.0);
        assert_eq!(velocity_step(f32::NAN), 1.0);
        let mut s = Stroke::new(f64::NAN);
        s.start(StrokeMode::Alternate, 1.0);
        for _ in 0..10_000 {
            let (v, f) = s.tick();
            assert!(v.is_finite() && f.is_finite());
        }
    }
}
