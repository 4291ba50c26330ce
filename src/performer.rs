//! The performer: everything between the player's keys and the engines, free of any
//! plugin framework. The plugin, and any tool that wants to play what the plugin plays,
//! hand it a [`Setup`] per block, the notes, and a bow per sample.
//!
//! It owns:
//! - the engines ([`crate::dsp::engine::Engine`]): the waveguide strings (paper A's point
//!   laws), paper B's thermal instrument of each kind (with its modal bridge), the rubbed
//!   objects;
//! - the source the notes go to, and the switch between sources: held notes move to the
//!   new source (its bow lands over the usual ramp) while the old one rings on;
//! - the held keys, and the thermal bow's node count under `quality = auto`;
//! - the tail the host hears about ([`Status`]).
//!
//! ```
//! use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
//! use colophony::performer::{Performer, Setup};
//! let setup = Setup::default();
//! let mut performer = Performer::new(InstrumentKind::Cello);
//! performer.activate(&setup, 48_000.0).unwrap();
//! performer.configure(&setup);
//! performer.note_on(50, 0.8);
//! let bow = BowControl::default();
//! let peak = (0..9600).map(|_| performer.tick(bow).audio.abs()).fold(0.0, f64::max);
//! assert!(peak > 0.0);
//! ```

pub mod direct;
pub mod midi_map;
pub mod mpe;
pub mod stroke;

use crate::dsp::bridge_data::{self, BridgeModes};
use crate::dsp::engine::Engine;
use crate::dsp::friction::FrictionModel;
use crate::dsp::instrument::Instrument;
use crate::dsp::rubbed::{RubbedInstrument, RubbedPreset};
use crate::dsp::thermal::ThermalString;
use crate::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
use crate::dsp::vocabulary::{
    midi_to_hz, BowControl, Frame, InstrumentKind, MAX_BEND_RANGE_SEMITONES, MAX_NOTE_BETA,
    MIN_NOTE_BETA, PITCH_BEND_SEMITONES,
};
use crate::quality::{self, Quality};
use direct::DirectBow;
use midi_map::{MidiMap, Target};
use mpe::{Handled, Mpe, NoteState};
use stroke::{Stroke, StrokeMode};

/// `sample_rate_hz` if it is a usable rate (finite, positive), else 48 kHz: the gesture
/// clocks never divide by a bad rate.
fn usable_rate(sample_rate_hz: f64) -> f64 {
    if sample_rate_hz.is_finite() && sample_rate_hz > 0.0 {
        sample_rate_hz
    } else {
        48_000.0
    }
}

/// A setting MIDI may hold over the setup's: `midi` if set, else `setup`, clamped to
/// `range` (`default` for a NaN).
fn midi_over_setup(
    midi: Option<f64>,
    setup: f64,
    default: f64,
    range: std::ops::RangeInclusive<f64>,
) -> f64 {
    let value = midi.unwrap_or(setup);
    if value.is_nan() {
        return default;
    }
    value.clamp(*range.start(), *range.end())
}

/// The pitch-bend wheel's position, -1..=1, for a MIDI pitch-bend value `value` (0 =
/// down, 0.5 = centre, 1 = up, as nice-plug delivers it); a NaN is the centre.
pub fn wheel_position(value: f32) -> f64 {
    if value.is_nan() {
        return 0.0;
    }
    ((value as f64 - 0.5) * 2.0).clamp(-1.0, 1.0)
}

/// The dynamics' range: expression 0 (CC11, CC2 or channel pressure at 0) plays the bow
/// this many dB below expression 1 (the default, and the parameters' own bow).
pub const DYNAMICS_RANGE_DB: f64 = 30.0;
/// With the window guard the bow position is the parameter's times `scale^-x` (the
/// dynamics' bow scale): the bow sits at the parameter's place at full expression and
/// drifts away from the bridge as the dynamics fall, 2^(1/2) = 1.41 times farther at the
/// softest (-30 dB: `x = log10(2) / 3`), as players bow nearer the fingerboard for
/// piano and nearer the bridge for forte.
pub const DYNAMICS_DRIFT_EXPONENT: f64 = std::f64::consts::LOG10_2 / 3.0;
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

/// MIDI's null registered parameter number (CC101 and CC100 at 127).
const RPN_NULL: u8 = 127;

/// Samples between two tail estimates (see [`Performer::status`]).
const TAIL_EVERY: usize = 2048;

/// The thermal bow's node count: fixed, or chosen per note (`quality = auto`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ThermalNodes {
    Fixed(usize),
    Auto,
}

/// What the player has set, read once per block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    pub instrument: InstrumentKind,
    /// The point law for the strings (and the rubbed objects); `None` plays paper B's
    /// thermal model (the rubbed objects keep the last point law).
    pub point_law: Option<FrictionModel>,
    /// A rubbed object instead of the strings.
    pub rubbed: Option<RubbedPreset>,
    /// Newton tolerance of the bristle laws, m/s.
    pub newton_tolerance_m_per_s: f64,
    /// Reference pitch A4, Hz.
    pub reference_hz: f64,
    /// The string notes go to (0 = lowest), `None` for the usual choice.
    pub preferred_string: Option<usize>,
    pub thermal_nodes: ThermalNodes,
    /// Bow hair width, m (thermal model).
    pub bow_width_m: f64,
    /// Bow position, for the automatic node count at a note-on.
    pub bow_position_beta: f64,
    /// The direction of each new bow stroke.
    pub bow_strokes: StrokeMode,
    /// Semitones the pitch-bend wheel bends at its ends (0..=12; MIDI RPN 0 overrides it).
    pub bend_range_semitones: f64,
    /// How long a finger glide (portamento) takes, s.
    pub glide_s: f64,
    /// Vibrato rate, Hz ([`VIBRATO_RATE_MIN_HZ`]..=[`VIBRATO_RATE_MAX_HZ`]).
    pub vibrato_rate_hz: f64,
    /// The window guard (on by default): the dynamics scale the bow's velocity and force
    /// together and move it from the bridge as they fall, so the bow keeps its place in
    /// Schelleng's window. Off, they scale the velocity alone: a soft dynamic under the
    /// parameters' force presses a slow bow too hard (raucous).
    pub dynamics_guard: bool,
    /// The strings weighted (on by default): the point-bow strings are bowed with the
    /// force times their impedance over [`crate::dsp::vocabulary::WEIGHT_REFERENCE_Z0`],
    /// so one force keeps its place in every string's window. Off, every string gets the
    /// force as set. Paper B's thermal model is weighted against its own reference
    /// ([`crate::dsp::thermal_instrument::THERMAL_WEIGHT_REFERENCE_Z0`]); the rubbed
    /// objects take the force as set.
    pub string_weight: bool,
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            instrument: InstrumentKind::Cello,
            point_law: Some(FrictionModel::Hyperbolic),
            rubbed: None,
            newton_tolerance_m_per_s: Quality::Good.newton_tolerance_m_per_s(),
            reference_hz: crate::dsp::vocabulary::REFERENCE_HZ_DEFAULT,
            preferred_string: None,
            thermal_nodes: ThermalNodes::Fixed(quality::GOOD_NODES),
            bow_width_m: 0.01,
            bow_position_beta: 0.1,
            bow_strokes: StrokeMode::Alternate,
            bend_range_semitones: PITCH_BEND_SEMITONES,
            glide_s: GLIDE_S_DEFAULT,
            vibrato_rate_hz: VIBRATO_RATE_HZ,
            dynamics_guard: true,
            string_weight: true,
        }
    }
}

/// What the notes play: the waveguide strings, paper B's thermal instrument of one kind
/// (index into [`InstrumentKind::ALL`]), or a rubbed object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    Strings,
    Thermal(usize),
    Rubbed(RubbedPreset),
}

impl Source {
    /// The source a setup asks for.
    pub fn of(setup: &Setup) -> Self {
        match (setup.rubbed, setup.point_law) {
            (Some(preset), _) => Source::Rubbed(preset),
            (None, Some(_)) => Source::Strings,
            (None, None) => {
                let k = InstrumentKind::ALL
                    .iter()
                    .position(|x| *x == setup.instrument);
                Source::Thermal(k.unwrap_or(0))
            }
        }
    }
}

/// What the host should hear about a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// A bow or an exciter is on.
    KeepAlive,
    /// Lifted strings or objects ring out for this many more samples.
    Tail(u32),
    /// Silent.
    Normal,
}

/// See the module documentation.
pub struct Performer {
    /// Which controller moves what ([`midi_map`]).
    midi_map: MidiMap,
    instrument: Instrument,
    /// Paper B's instrument, one per kind (violin, viola, cello), allocated in
    /// [`Performer::activate`]: switching kind or model lets the one switched away from
    /// ring on.
    thermal: Vec<ThermalInstrument>,
    rubbed: RubbedInstrument,
    source: Source,
    /// Held notes, so a source switch can move them to the new source.
    held: [bool; 128],
    /// The last note the strings took.
    last_note: Option<u8>,
    /// The thermal node count `quality = auto` chose at the last note-on.
    auto_nodes: usize,
    sample_rate_hz: f64,
    /// The last tail estimate (samples left) and the samples processed since it: the
    /// estimate walks every delay line, so it is renewed only every [`TAIL_EVERY`] samples.
    tail: Option<(f64, usize)>,
    setup: Setup,
    gesture: Gesture,
    stroke: Stroke,
    /// The bow controls MIDI controllers hold (CC21-23).
    direct: DirectBow,
    /// Bridges the player chose for the thermal instrument of each kind.
    user_bridges: [Option<BridgeModes>; 3],
    /// Whether any engine besides the waveguide strings sounds: they wake only at a note
    /// the performer hands them and sleep only at a block's `update_sleep`, so this is
    /// renewed there and the per-sample loop skips them with one test.
    others_awake: bool,
    /// While the gesture is steady (see [`Performer::shape`]): the factors on the bow's
    /// velocity, force and position, applied without the gesture's per-sample checks.
    steady: Option<(f64, f64, f64)>,
    /// Whether [`Performer::configure`] has run since the engines were built.
    configured: bool,
    /// The bow of the last sample, as played (after the stroke and the dynamics).
    bow_now: BowControl,
    /// MPE zones and channel expression ([`mpe`]).
    mpe: Mpe,
    /// Per key: the channel it was played on, the string it went to, and its own note
    /// expressions.
    notes: [NoteSlot; 128],
}

/// What the performer remembers of a key's note for its per-note expression.
#[derive(Debug, Clone, Copy, Default)]
struct NoteSlot {
    channel: u8,
    string: Option<u8>,
    state: NoteState,
}

/// What the player's controllers ask of the bow and the finger (the performance layer):
/// dynamics (CC11 expression, CC2 breath, channel pressure) scale the bow's velocity and
/// force together, which keeps the bow at the same place in Schelleng's window (both
/// limits are proportional to the bow velocity) while the amplitude follows the velocity;
/// the mod wheel (CC1) sets the depth of a finger vibrato.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gesture {
    /// The bow scale the asked expression (0..=1) gives: `10^(-range (1 - e) / 20)`.
    target: f64,
    /// The bow's present scale (smoothed toward `target`).
    scale: f64,
    /// The window guard's drift of the bow position at this scale:
    /// `scale^-`[`DYNAMICS_DRIFT_EXPONENT`] (1 at full scale).
    away: f64,
    smoothing: f64,
    /// Vibrato depth, cents.
    vibrato_cents: f64,
    /// The MIDI pitch bend, semitones (the vibrato is added to it).
    bend: f64,
    /// The pitch-bend wheel, -1..=1.
    wheel: f64,
    /// The bend range MIDI RPN 0 set, semitones (overrides the setup's).
    rpn_bend_range: Option<f64>,
    /// The registered parameter number CC101/CC100 selected ([`RPN_NULL`]: none).
    rpn: (u8, u8),
    /// CC65 (portamento) down.
    portamento_pedal: bool,
    /// The vibrato's present offset, semitones.
    vibrato_now: f64,
    phase: f64,
    phase_step: f64,
    /// The rate CC19 set, Hz (over the setup's until that changes).
    cc_rate_hz: Option<f64>,
    /// Drift of rate and depth: now, target (fractions), updates to the next target, and
    /// the random state.
    drift: [f64; 2],
    drift_target: [f64; 2],
    drift_countdown: u32,
    seed: u64,
    /// Samples since the last note landed.
    since_note: u64,
    countdown: u32,
}

impl Gesture {
    fn new(sample_rate_hz: f64) -> Self {
        Self {
            target: 1.0,
            scale: 1.0,
            away: 1.0,
            smoothing: 1.0 - (-1.0 / (DYNAMICS_SMOOTHING_S * sample_rate_hz)).exp(),
            vibrato_cents: 0.0,
            bend: 0.0,
            wheel: 0.0,
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
        }
    }

    fn set_expression(&mut self, e: f64) {
        self.target = 10f64.powf(-DYNAMICS_RANGE_DB * (1.0 - e.clamp(0.0, 1.0)) / 20.0);
    }
}

impl Performer {
    /// A performer at 48 kHz with no thermal instrument yet (cheap: call
    /// [`Performer::activate`] before playing).
    pub fn new(kind: InstrumentKind) -> Self {
        Self {
            midi_map: MidiMap::default(),
            instrument: Instrument::new(kind, 48_000.0),
            thermal: Vec::new(),
            rubbed: RubbedInstrument::new(48_000.0),
            source: Source::Strings,
            held: [false; 128],
            last_note: None,
            auto_nodes: quality::GOOD_NODES,
            sample_rate_hz: 48_000.0,
            tail: None,
            setup: Setup {
                instrument: kind,
                ..Setup::default()
            },
            gesture: Gesture::new(48_000.0),
            stroke: Stroke::new(48_000.0),
            direct: DirectBow::new(48_000.0),
            user_bridges: [None, None, None],
            others_awake: false,
            steady: None,
            configured: false,
            bow_now: BowControl::default(),
            mpe: Mpe::default(),
            notes: [NoteSlot::default(); 128],
        }
    }

    /// Plays `kind` on `bridge` (a fitted or measured modal bridge,
    /// [`crate::dsp::bridge_data`]) instead of the shipped one: paper B's thermal
    /// instrument on the bridge itself, the point-bow instrument with the bridge's passive
    /// reduction as its body ([`crate::dsp::body::body_from_bridge`]). `None` goes back to
    /// the shipped bridge and the generic body. Takes effect at the next
    /// [`Performer::activate`] (it builds the engines: not for the audio thread).
    pub fn set_user_bridge(&mut self, kind: InstrumentKind, bridge: Option<BridgeModes>) {
        if let Some(k) = InstrumentKind::ALL.iter().position(|&x| x == kind) {
            self.user_bridges[k] = bridge;
        }
    }

    /// Allocates every engine for `sample_rate_hz`; nothing allocates after this.
    pub fn activate(&mut self, setup: &Setup, sample_rate_hz: f64) -> Result<(), String> {
        self.setup = *setup;
        let fs = sample_rate_hz;
        self.instrument = Instrument::new(setup.instrument, fs);
        // The point-bow strings play a chosen bridge as their body: its passive
        // reduction to the bowing direction's strongest modes.
        for (k, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            if let Some(user) = &self.user_bridges[k] {
                let (modes, _) = crate::dsp::body::body_from_bridge(&user.modes);
                self.instrument.set_body(kind, Some(&modes));
            }
        }
        let settings = self.thermal_settings();
        self.thermal.clear();
        for (k, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            let shipped;
            let bridge = match (&self.user_bridges[k], kind) {
                (Some(user), _) => user,
                (None, InstrumentKind::Cello) => {
                    shipped = bridge_data::shipped_cello_bridge();
                    &shipped
                }
                (None, InstrumentKind::Viola) => {
                    shipped = bridge_data::shipped_viola_bridge();
                    &shipped
                }
                (None, InstrumentKind::Violin) => {
                    shipped = bridge_data::shipped_violin_bridge();
                    &shipped
                }
            };
            let engine = ThermalInstrument::new(kind, &bridge.modes, fs, settings)
                .map_err(|e| format!("cannot build the thermal {}: {e}", kind.name()))?;
            self.thermal.push(engine);
        }
        self.rubbed = RubbedInstrument::new(fs);
        self.source = Source::Strings;
        self.held = [false; 128];
        self.sample_rate_hz = fs;
        self.tail = None;
        self.gesture = Gesture::new(fs);
        self.stroke = Stroke::new(fs);
        self.direct = DirectBow::new(fs);
        self.steady = None;
        self.configured = false;
        Ok(())
    }

    /// Applies a block's setup: instrument, laws, tolerances, tuning, string choice, the
    /// thermal bow's settings and the source; then what is quiet sleeps.
    pub fn configure(&mut self, setup: &Setup) {
        // The same setup as the last block: every setting below would be a no-op (the
        // strings' kind is the one condition that waits on the engines' state).
        if self.configured && *setup == self.setup && self.instrument.kind() == setup.instrument {
            for engine in self.engines() {
                engine.update_sleep();
            }
            self.refresh_others();
            return;
        }
        self.configured = true;
        if setup.vibrato_rate_hz != self.setup.vibrato_rate_hz {
            self.gesture.cc_rate_hz = None;
        }
        let range_was = self.bend_range();
        self.setup = *setup;
        if self.bend_range() != range_was {
            self.set_bend(self.gesture.wheel * self.bend_range());
        }
        let wanted = Source::of(setup);
        // The waveguide strings change instrument at once (silenced) only while they are
        // what the notes play; ringing on behind another source, they finish first.
        if wanted == Source::Strings || !self.instrument.is_sounding() {
            self.instrument.set_kind(setup.instrument);
        }
        // The rubbed objects keep the last point law while the thermal model is chosen.
        if let Some(friction) = setup.point_law {
            self.instrument.set_friction_model(friction);
            self.rubbed.set_friction_model(friction);
        }
        self.instrument.set_string_weighting(setup.string_weight);
        self.instrument
            .set_newton_tolerance(setup.newton_tolerance_m_per_s);
        self.rubbed
            .set_newton_tolerance(setup.newton_tolerance_m_per_s);
        let settings = self.thermal_settings();
        for engine in self.engines() {
            engine.set_reference_pitch(setup.reference_hz);
            engine.set_preferred_string(setup.preferred_string);
        }
        for engine in &mut self.thermal {
            engine.set_string_weighting(setup.string_weight);
            engine.set_settings(settings);
        }
        self.apply_source(wanted);
        for engine in self.engines() {
            engine.update_sleep();
        }
        self.refresh_others();
    }

    /// Renews [`Performer::others_awake`].
    fn refresh_others(&mut self) {
        self.others_awake =
            self.thermal.iter().any(|e| e.is_sounding()) || self.rubbed.is_sounding();
    }

    /// Every engine.
    fn engines(&mut self) -> impl Iterator<Item = &mut dyn Engine> {
        std::iter::once(&mut self.instrument as &mut dyn Engine)
            .chain(self.thermal.iter_mut().map(|e| e as &mut dyn Engine))
            .chain(std::iter::once(&mut self.rubbed as &mut dyn Engine))
    }

    /// A key goes down with `velocity` (0..=1). A note that lands while no key is held
    /// starts a new bow stroke ([`stroke`]: direction by the setup's stroke mode, attack
    /// by the velocity); one that lands while another is held is legato (the stroke goes
    /// on; on the same string the finger moves and the bow stays on). A legato note below
    /// [`PORTAMENTO_BELOW_VELOCITY`], or any with CC65 down, glides the finger over the
    /// setup's glide time.
    pub fn note_on(&mut self, note: u8, velocity: f32) {
        self.note_on_channel(0, note, velocity);
    }

    /// A note on MIDI channel `channel` (0..=15): on an MPE member channel it takes that
    /// channel's bend, pressure and timbre as its own ([`mpe`]).
    pub fn note_on_channel(&mut self, channel: u8, note: u8, velocity: f32) {
        self.notes[note as usize & 127] = NoteSlot {
            channel: channel & 15,
            string: None,
            state: NoteState::default(),
        };
        self.steady = None;
        let separate = !self.held.iter().any(|&h| h);
        // Portamento: a legato note played softly, or any legato note with CC65 down,
        // slides the finger there on the waveguide strings.
        let glide = !separate
            && (self.gesture.portamento_pedal
                || stroke::velocity_step(velocity) < PORTAMENTO_BELOW_VELOCITY);
        self.land(note, glide.then_some(self.setup.glide_s));
        // A note the source refused moves no bow.
        if separate && self.held[note as usize & 127] {
            self.stroke
                .start(self.setup.bow_strokes, stroke::velocity_step(velocity));
        }
    }

    /// The note reaches the source (no new stroke); with `glide` (seconds), the strings
    /// (waveguide or thermal) slide the finger there.
    fn land(&mut self, note: u8, glide: Option<f64>) {
        // A bow lands: whatever tail was estimated no longer holds.
        self.tail = None;
        self.gesture.since_note = 0;
        let key = note as usize & 127;
        match self.source {
            // Notes the instrument cannot play are ignored.
            Source::Strings => {
                let landed = match glide {
                    Some(seconds) => self.instrument.note_on_gliding(note, seconds),
                    None => self.instrument.note_on(note),
                };
                if let Some(string) = landed {
                    self.held[key] = true;
                    self.last_note = Some(note);
                    self.notes[key].string = Some(string as u8);
                }
            }
            Source::Thermal(k) => {
                self.choose_auto_nodes(note);
                let settings = self.thermal_settings();
                if let Some(engine) = self.thermal.get_mut(k) {
                    // A new node count fades the instrument out and lands the note after.
                    engine.set_settings(settings);
                    let landed = match glide {
                        Some(seconds) => engine.note_on_gliding(note, seconds),
                        None => engine.note_on(note),
                    };
                    if let Some(string) = landed {
                        self.held[key] = true;
                        self.last_note = Some(note);
                        self.notes[key].string = Some(string as u8);
                    }
                }
            }
            Source::Rubbed(_) => {
                if !self.held[key] {
                    self.held[key] = true;
                    self.rubbed.note_on();
                }
            }
        }
        if let Some(string) = self.notes[key].string.filter(|_| self.held[key]) {
            self.share_the_bow(note, string);
        }
        self.express(note);
        self.refresh_others();
    }

    /// One bow touches at most two adjacent strings: a note landing on `string` lifts the
    /// bow from every other string more than one away (its note rings on, its key still
    /// down), as a chord played with one bow is rolled and its first notes left ringing.
    /// A double stop on neighbouring strings keeps both bowed.
    fn share_the_bow(&mut self, note: u8, string: u8) {
        for other in 0..128u8 {
            let slot = &mut self.notes[other as usize];
            let far = slot.string.is_some_and(|s| s.abs_diff(string) > 1);
            if other == note || !self.held[other as usize] || !far {
                continue;
            }
            slot.string = None;
            match self.source {
                Source::Strings => self.instrument.note_off(other),
                Source::Thermal(k) => {
                    if let Some(engine) = self.thermal.get_mut(k) {
                        engine.note_off(other);
                    }
                }
                Source::Rubbed(_) => {}
            }
        }
    }

    /// Gives `note`'s string the note's expression: its MPE channel's, with its own note
    /// expressions over it. Nothing for a note not held or on no string.
    fn express(&mut self, note: u8) {
        let key = note as usize & 127;
        let slot = self.notes[key];
        let (true, Some(string)) = (self.held[key], slot.string) else {
            return;
        };
        let expression = slot.state.over(self.mpe.expression(slot.channel));
        match self.source {
            Source::Strings => self
                .instrument
                .set_note_expression(string as usize, expression),
            Source::Thermal(k) => {
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.set_note_expression(string as usize, expression);
                }
            }
            Source::Rubbed(_) => {}
        }
    }

    /// Re-applies the expression of every held note on `channel` (`None`: every held
    /// note).
    fn express_channel(&mut self, channel: Option<u8>) {
        for note in 0..128u8 {
            let slot = &self.notes[note as usize];
            if self.held[note as usize] && channel.is_none_or(|c| c == slot.channel) {
                self.express(note);
            }
        }
    }

    /// The pitch-bend wheel (0..=1) on `channel`: an MPE member channel's bends its own
    /// notes, any other channel's every note ([`Performer::set_pitch_wheel`]).
    pub fn set_pitch_wheel_channel(&mut self, channel: u8, value: f32) {
        if self.mpe.pitch_bend(channel, wheel_position(value)) {
            self.express_channel(Some(channel));
        } else {
            self.set_pitch_wheel(value);
        }
    }

    /// Channel pressure (0..=1) on `channel`: an MPE member channel's presses its own
    /// notes' strings, any other's is the dynamics ([`Performer::set_pressure`]).
    pub fn set_pressure_channel(&mut self, channel: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        if self.mpe.pressure(channel, value as f64) {
            self.express_channel(Some(channel));
        } else {
            self.set_pressure(value);
        }
    }

    /// A controller (0..=1) on `channel`: the MPE Configuration Message, and CC74 or
    /// RPN 0 on a member channel, are MPE's ([`mpe`]); everything else is
    /// [`Performer::set_controller`]'s.
    pub fn set_controller_channel(&mut self, channel: u8, cc: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        match self.mpe.controller(channel, cc, value as f64) {
            Handled::Shared => self.set_controller(cc, value),
            Handled::Configured => self.express_channel(None),
            Handled::Expression => self.express_channel(None),
        }
    }

    /// A CLAP note expression: `note`'s tuning, semitones (its finger).
    pub fn set_note_tuning(&mut self, note: u8, semitones: f32) {
        if semitones.is_finite() {
            self.notes[note as usize & 127].state.tuning_semitones = semitones as f64;
            self.express(note);
        }
    }

    /// A CLAP note expression (or polyphonic aftertouch): `note`'s pressure, 0..=1 (its
    /// string's bow force, [`mpe::pressure_to_force_scale`]).
    pub fn set_note_pressure(&mut self, note: u8, pressure: f32) {
        if pressure.is_finite() {
            self.notes[note as usize & 127].state.pressure = Some(pressure as f64);
            self.express(note);
        }
    }

    /// A CLAP note expression: `note`'s brightness, 0..=1 (its string's bow position,
    /// [`mpe::timbre_to_position_scale`]).
    pub fn set_note_brightness(&mut self, note: u8, brightness: f32) {
        if brightness.is_finite() {
            self.notes[note as usize & 127].state.brightness = Some(brightness as f64);
            self.express(note);
        }
    }

    pub fn note_off(&mut self, note: u8) {
        let was_held = std::mem::replace(&mut self.held[note as usize & 127], false);
        match self.source {
            Source::Strings => self.instrument.note_off(note),
            Source::Thermal(k) => {
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.note_off(note);
                }
            }
            Source::Rubbed(_) if was_held => self.rubbed.note_off(),
            Source::Rubbed(_) => {}
        }
    }

    pub fn all_notes_off(&mut self) {
        self.held = [false; 128];
        for engine in self.engines() {
            engine.all_notes_off();
        }
    }

    /// The pitch-bend wheel at `value` (0..=1, 0.5 = centre, as nice-plug delivers it):
    /// bends by the bend range at its ends.
    pub fn set_pitch_wheel(&mut self, value: f32) {
        self.gesture.wheel = wheel_position(value);
        self.set_bend(self.gesture.wheel * self.bend_range());
    }

    /// The pitch-bend range, semitones: MIDI RPN 0's if one came, else the setup's
    /// (clamped to 0..=[`MAX_BEND_RANGE_SEMITONES`]).
    pub fn bend_range(&self) -> f64 {
        midi_over_setup(
            self.gesture.rpn_bend_range,
            self.setup.bend_range_semitones,
            PITCH_BEND_SEMITONES,
            0.0..=MAX_BEND_RANGE_SEMITONES,
        )
    }

    /// Pitch bend in semitones, for every engine with pitch (the vibrato adds to it).
    fn set_bend(&mut self, semitones: f64) {
        self.gesture.bend = semitones;
        self.bend_engines(semitones + self.gesture.vibrato_now);
    }

    fn bend_engines(&mut self, semitones: f64) {
        for engine in self.engines() {
            engine.set_pitch_bend(semitones);
        }
    }

    /// Controllers move what `map` says from now on ([`midi_map`]). Real-time safe.
    pub fn set_midi_map(&mut self, map: &MidiMap) {
        self.midi_map = *map;
    }

    /// A MIDI controller at `value` (0..=1, as nice-plug delivers it). CC101 and CC100
    /// select a registered parameter and CC6 / CC38 set it (RPN 0: the pitch-bend range,
    /// semitones and cents); every other controller does what the MIDI map says
    /// ([`midi_map`]; by default CC1 the vibrato depth, CC2 and CC11 the dynamics, CC19
    /// the vibrato rate, CC21-23 the bow's speed, force and position ([`direct`]), CC65
    /// portamento), or nothing.
    pub fn set_controller(&mut self, cc: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        self.steady = None;
        let v = (value as f64).clamp(0.0, 1.0);
        // The 7-bit value of a data byte.
        let byte = (v * 127.0).round() as u8;
        match cc {
            101 => return self.gesture.rpn.0 = byte,
            100 => return self.gesture.rpn.1 = byte,
            6 | 38 if self.gesture.rpn == (0, 0) => {
                let range = self.bend_range();
                let (semitones, cents) = (range.trunc(), (range.fract() * 100.0).round());
                let range = if cc == 6 {
                    byte as f64 + cents / 100.0
                } else {
                    semitones + byte.min(99) as f64 / 100.0
                };
                self.gesture.rpn_bend_range = Some(range.min(MAX_BEND_RANGE_SEMITONES));
                self.set_bend(self.gesture.wheel * self.bend_range());
                return;
            }
            _ => {}
        }
        let map = self.midi_map;
        for (target, x) in map.route(cc, v) {
            self.move_target(target, x);
        }
    }

    /// A mapped controller's value `x` (0..=1 of the target's range) lands on `target`.
    fn move_target(&mut self, target: Target, x: f64) {
        match target {
            Target::Dynamics => self.gesture.set_expression(x),
            Target::VibratoDepth => self.gesture.vibrato_cents = x * MAX_VIBRATO_CENTS,
            Target::VibratoRate => {
                self.gesture.cc_rate_hz =
                    Some(VIBRATO_RATE_MIN_HZ + x * (VIBRATO_RATE_MAX_HZ - VIBRATO_RATE_MIN_HZ))
            }
            Target::BowVelocity => {
                self.direct.set_controller(direct::CC_BOW_VELOCITY, x);
            }
            Target::BowForce => {
                self.direct.set_controller(direct::CC_BOW_FORCE, x);
            }
            Target::BowPosition => {
                self.direct.set_controller(direct::CC_BOW_POSITION, x);
            }
            Target::Portamento => self.gesture.portamento_pedal = (x * 127.0).round() >= 64.0,
            Target::Sustain => {
                let held = (x * 127.0).round() >= 64.0;
                for engine in self.engines() {
                    engine.set_fingers_held(held);
                }
            }
        }
    }

    /// Channel pressure (aftertouch), 0..=1: the dynamics, as CC11.
    pub fn set_pressure(&mut self, value: f32) {
        self.steady = None;
        if value.is_finite() {
            self.gesture.set_expression(value as f64);
        }
    }

    /// The vibrato's offset now, semitones: a sine at [`VIBRATO_RATE_HZ`], silent for
    /// [`VIBRATO_DELAY_S`] after a note lands, then faded in over [`VIBRATO_FADE_S`].
    fn vibrato_semitones(&self) -> f64 {
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
    fn advance_drift(&mut self) {
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
    fn shape(&mut self, bow: BowControl) -> BowControl {
        if self.gesture.vibrato_cents > 0.0 || self.gesture.vibrato_now != 0.0 {
            self.advance_vibrato();
        }
        let bow = self.direct.apply(bow);
        let (speed, landing) = if self.stroke.is_settled() {
            (self.stroke.direction(), 1.0)
        } else {
            self.stroke.tick()
        };
        let g = &mut self.gesture;
        if g.scale != g.target {
            g.scale += g.smoothing * (g.target - g.scale);
            if (g.scale - g.target).abs() < 1e-9 {
                g.scale = g.target;
            }
            // The guard's drift follows the scale: one power per change of the scale,
            // none per sample while it rests (a vibrato ticks this path every sample).
            g.away = if g.scale == 1.0 {
                1.0
            } else {
                g.scale.powf(-DYNAMICS_DRIFT_EXPONENT)
            };
        }
        // With the guard the force follows the velocity and the bow drifts from the
        // bridge as the dynamics fall; without it only the velocity follows.
        let (force_scale, away) = if self.setup.dynamics_guard {
            (g.scale, g.away)
        } else {
            (1.0, 1.0)
        };
        let out = if g.scale == 1.0 && speed == 1.0 && landing == 1.0 && away == 1.0 {
            bow
        } else {
            BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * g.scale * speed,
                force_n: bow.force_n * force_scale * landing,
                position_beta: (bow.position_beta * away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
            }
        };
        // Steady from here on until a controller, a pressure or a note: the next samples
        // only multiply (the same bits: `speed` is +-1, so the order of the products does
        // not round differently).
        let steady = g.vibrato_cents == 0.0
            && g.vibrato_now == 0.0
            && g.scale == g.target
            && self.direct.is_idle()
            && self.stroke.is_settled();
        self.steady = steady.then_some((g.scale * speed, force_scale, away));
        out
    }

    /// One sample of the vibrato: its clock runs while the mod wheel is up (so the onset
    /// delay counts from the note or from the wheel, whichever is later), and the finger
    /// moves every [`VIBRATO_EVERY`] samples.
    fn advance_vibrato(&mut self) {
        let g = &mut self.gesture;
        g.since_note = g.since_note.saturating_add(1);
        g.phase += g.phase_step;
        if g.phase >= 1.0 {
            g.phase -= 1.0;
        }
        if g.countdown == 0 {
            g.countdown = VIBRATO_EVERY;
            self.advance_drift();
            let now = if self.gesture.vibrato_cents > 0.0 {
                self.vibrato_semitones()
            } else {
                0.0
            };
            self.gesture.vibrato_now = now;
            let bend = self.gesture.bend + now;
            // Only what sounds moves its finger; a silent engine takes the vibrato at the
            // first update after its note lands (the vibrato starts later still).
            for engine in self.engines().filter(|e| e.is_sounding()) {
                engine.set_pitch_bend(bend);
            }
        }
        self.gesture.countdown -= 1;
    }

    /// Whether every engine is asleep: [`Performer::tick`] would give silence (a zero
    /// frame) and change nothing but the gesture's clocks until a note lands.
    pub fn is_asleep(&self) -> bool {
        self.instrument.is_skipping()
            && !self.instrument.is_ringing()
            && self.thermal.iter().all(|e| !e.is_ringing())
            && !self.rubbed.is_sounding()
    }

    /// Stands in for `n` calls of [`Performer::tick`] with `bow` while
    /// [`Performer::is_asleep`]: the output would be `n` zeros, so only the gesture
    /// advances (sample by sample while a vibrato, an attack or the dynamics move, so the
    /// result is the same bits; once, at rest). What makes a silent block cost nothing.
    pub fn skip(&mut self, n: usize, bow: BowControl) {
        debug_assert!(self.is_asleep());
        let g = &self.gesture;
        let at_rest = g.vibrato_cents == 0.0
            && g.vibrato_now == 0.0
            && g.scale == g.target
            && self.stroke.is_settled()
            && self.direct.is_settled();
        let steps = if at_rest { n.min(1) } else { n };
        for _ in 0..steps {
            self.bow_now = self.shape(bow);
        }
    }

    /// Silences every engine and forgets the held notes (the source and the controllers
    /// stay).
    pub fn reset(&mut self) {
        for engine in self.engines() {
            engine.reset();
        }
        self.held = [false; 128];
        self.refresh_others();
    }

    /// One sample. Every engine ticks while it sounds (the one just switched away from
    /// rings on); the contact probe is the source's.
    ///
    /// The commonest case, a steady gesture on the waveguide strings alone, is a few
    /// instructions here and inlined into the caller; everything else is out of line in
    /// [`Performer::tick_general`], so its registers and stack do not weigh on the common
    /// path (callgrind: 521 instructions per sample this way, 561 with both in one
    /// function).
    #[inline]
    pub fn tick(&mut self, bow: BowControl) -> Frame {
        if !self.others_awake {
            if let Some(played) = self.steady_bow(bow) {
                self.bow_now = played;
                return self.instrument.tick(played);
            }
        }
        self.tick_general(bow)
    }

    /// [`Performer::tick`] with the gesture moving or other engines sounding.
    #[inline(never)]
    fn tick_general(&mut self, bow: BowControl) -> Frame {
        let bow = match self.steady_bow(bow) {
            Some(played) => played,
            None => self.shape(bow),
        };
        self.bow_now = bow;
        let mut frame = self.instrument.tick(bow);
        if !self.others_awake {
            return frame;
        }
        for (k, engine) in self.thermal.iter_mut().enumerate() {
            if engine.is_sounding() {
                let f = engine.tick(bow);
                frame.audio += f.audio;
                if self.source == Source::Thermal(k) {
                    frame.bow_point_velocity_m_per_s = f.bow_point_velocity_m_per_s;
                    frame.friction_force_n = f.friction_force_n;
                }
            }
        }
        if self.rubbed.is_sounding() {
            frame.audio += self.rubbed.tick_bow(&bow);
        }
        frame
    }

    /// The bow as played while the gesture is steady (see [`Performer::shape`]): the
    /// factors on `bow`; `None` while the gesture moves.
    #[inline]
    fn steady_bow(&self, bow: BowControl) -> Option<BowControl> {
        Some(match self.steady? {
            (v, f, 1.0) => BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * v,
                force_n: bow.force_n * f,
                ..bow
            },
            (v, f, away) => BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * v,
                force_n: bow.force_n * f,
                position_beta: (bow.position_beta * away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
            },
        })
    }

    /// `out.len()` samples of audio with the bow held at `bow` and no event between: the
    /// same samples as as many [`Performer::tick`]s. Once the gesture is steady and only
    /// the waveguide strings sound, the strings run alone over the rest (the gesture has
    /// nothing to do per sample), which is what makes the performance layer cost nothing
    /// per sample.
    pub fn tick_block(&mut self, bow: BowControl, out: &mut [f64]) {
        let mut i = 0;
        while i < out.len() {
            if !self.others_awake {
                if let Some(played) = self.steady_bow(bow) {
                    self.bow_now = played;
                    for sample in &mut out[i..] {
                        *sample = self.instrument.tick(played).audio;
                    }
                    return;
                }
            }
            out[i] = self.tick(bow).audio;
            i += 1;
        }
    }

    /// `n` samples with no event between, the bow given sample by sample by `next` (a
    /// host's smoothed parameters) with a value `C` of the caller's riding along (its
    /// gain, say); `sink(k, c, frame, played, self)` takes sample `k` with the bow as
    /// played. The same samples as `n` calls of [`Performer::tick`], but once the gesture
    /// is steady and only the waveguide strings sound (which no sample of an event-free run
    /// can change), the rest of the run loops over the strings alone with the checks
    /// hoisted: the performance layer's per-sample work is then the two or three factors
    /// on the bow (the plugin's per-sample path while automation moves or a live view is
    /// open).
    #[inline]
    pub fn tick_run<C>(
        &mut self,
        n: usize,
        mut next: impl FnMut() -> (BowControl, C),
        mut sink: impl FnMut(usize, C, &Frame, &BowControl, &Self),
    ) {
        let mut k = 0;
        while k < n {
            if !self.others_awake {
                if let Some((v, f, away)) = self.steady {
                    let mut played = self.bow_now;
                    if away == 1.0 {
                        for k in k..n {
                            let (bow, c) = next();
                            played = BowControl {
                                velocity_m_per_s: bow.velocity_m_per_s * v,
                                force_n: bow.force_n * f,
                                ..bow
                            };
                            let frame = self.instrument.tick(played);
                            sink(k, c, &frame, &played, self);
                        }
                    } else {
                        for k in k..n {
                            let (bow, c) = next();
                            played = BowControl {
                                velocity_m_per_s: bow.velocity_m_per_s * v,
                                force_n: bow.force_n * f,
                                position_beta: (bow.position_beta * away)
                                    .clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
                            };
                            let frame = self.instrument.tick(played);
                            sink(k, c, &frame, &played, self);
                        }
                    }
                    self.bow_now = played;
                    return;
                }
            }
            let (bow, c) = next();
            let frame = self.tick_general(bow);
            sink(k, c, &frame, &self.bow_now, self);
            k += 1;
        }
    }

    /// The waveguide strings (for tools and tests: energy, solver statistics, and the
    /// renderer's bristle, torsion and intonation settings).
    pub fn strings(&self) -> &Instrument {
        &self.instrument
    }

    pub fn strings_mut(&mut self) -> &mut Instrument {
        &mut self.instrument
    }

    /// Paper B's instrument of `kind` (after [`Performer::activate`]).
    pub fn thermal(&self, kind: InstrumentKind) -> Option<&ThermalInstrument> {
        let k = InstrumentKind::ALL.iter().position(|x| *x == kind)?;
        self.thermal.get(k)
    }

    pub fn rubbed(&self) -> &RubbedInstrument {
        &self.rubbed
    }

    /// The bow of the last sample as played: the one given to [`Performer::tick`] shaped
    /// by the dynamics.
    pub fn bow(&self) -> BowControl {
        self.bow_now
    }

    /// The bow as played (velocity m/s, force N, as [`Performer::bow`]) while a key is
    /// held, `None` otherwise: what the editor marks on its pad.
    pub fn bowed_bow(&self) -> Option<(f32, f32)> {
        self.held.iter().any(|&h| h).then_some((
            self.bow_now.velocity_m_per_s as f32,
            self.bow_now.force_n as f32,
        ))
    }

    /// What the notes play now.
    pub fn source(&self) -> Source {
        self.source
    }

    /// How late the current source's output is behind its model, whole host samples (its
    /// resampler's delay, rounded): what the plugin reports to the host as latency.
    pub fn latency_samples(&self) -> u32 {
        let samples = match self.source {
            Source::Strings => self.instrument.latency_samples(),
            Source::Thermal(k) => self.thermal.get(k).map_or(0.0, |e| e.latency_samples()),
            Source::Rubbed(_) => 0.0,
        };
        samples.round().clamp(0.0, 1e6) as u32
    }

    /// The last note the strings took (the editor draws its Schelleng window).
    pub fn last_note(&self) -> Option<u8> {
        self.last_note
    }

    /// The string the thermal source's last note went to, while the thermal model plays.
    pub fn probed_thermal_string(&self) -> Option<&ThermalString> {
        match self.source {
            Source::Thermal(k) => self.thermal.get(k).map(|e| e.probed_string()),
            _ => None,
        }
    }

    /// Applies a source: held notes move to the new source (its bow lands over the usual
    /// ramp) and the old one rings on, so there is no click.
    fn apply_source(&mut self, choice: Source) {
        if choice == self.source {
            return;
        }
        let held = self.held;
        self.all_notes_off();
        self.source = choice;
        if let Source::Rubbed(preset) = choice {
            self.rubbed.set_preset(preset);
        }
        for (note, down) in held.iter().enumerate() {
            if *down {
                self.land(note as u8, None);
            }
        }
    }

    fn thermal_settings(&self) -> ThermalSettings {
        ThermalSettings {
            nodes: match self.setup.thermal_nodes {
                ThermalNodes::Fixed(n) => n,
                ThermalNodes::Auto => self.auto_nodes,
            },
            width_m: self.setup.bow_width_m,
        }
    }

    /// `quality = auto`: the node count for a new note at the current bow position, kept
    /// if the current one is close enough ([`quality::auto_needs_rebuild`]).
    fn choose_auto_nodes(&mut self, note: u8) {
        if self.setup.thermal_nodes != ThermalNodes::Auto {
            return;
        }
        let wanted = quality::auto_nodes(
            self.setup.instrument,
            midi_to_hz(note as f64),
            self.setup.bow_position_beta,
            self.setup.bow_width_m,
        );
        if quality::auto_needs_rebuild(self.auto_nodes, wanted) {
            self.auto_nodes = wanted;
        }
    }

    /// What the host hears about a block of `block` samples (CLAP process status and tail
    /// extension, VST3 `getTailSamples`):
    /// - `KeepAlive` while a bow or an exciter is on;
    /// - `Tail(samples)` while lifted strings or rubbed objects ring out (the waveguide
    ///   body's last blocks after its strings slept count as one sample, renewed while it
    ///   rings);
    /// - `Normal` once silent, so a CLAP host may stop calling `process` until input.
    pub fn status(&mut self, block: usize) -> Status {
        if let Some((left, since)) = self.tail {
            if since + block < TAIL_EVERY {
                let left = (left - block as f64).max(1.0);
                self.tail = Some((left, since + block));
                return Status::Tail(left as u32);
            }
        }
        self.tail = None;
        let mut tail_s = 0.0f64;
        let mut sounding = false;
        for engine in self.engines() {
            if !engine.is_ringing() {
                continue;
            }
            sounding = true;
            match engine.ring_out_s() {
                Some(s) => tail_s = tail_s.max(s),
                None => return Status::KeepAlive,
            }
        }
        if !sounding {
            return Status::Normal;
        }
        // At least one sample while anything rings; below CLAP's "infinite" (i32::MAX).
        let samples = (tail_s * self.sample_rate_hz)
            .ceil()
            .clamp(1.0, (i32::MAX - 1) as f64);
        self.tail = Some((samples, 0));
        Status::Tail(samples as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::contact::ContactSample;
    use crate::measure::regime::{classify_regime, Regime};

    const FS: f64 = 48_000.0;

    /// `(start, length)` of the spans of at most `size` samples that cover
    /// `0..marks.last()` without crossing a mark (an event's sample).
    fn spans(marks: &[usize], size: usize) -> Vec<(usize, usize)> {
        let end = marks.last().copied().unwrap_or(0);
        let mut v = Vec::new();
        let mut at = 0;
        while at < end {
            let next = marks.iter().copied().find(|&m| m > at).unwrap_or(end);
            let n = size.min(next - at);
            v.push((at, n));
            at += n;
        }
        v
    }

    fn cello() -> Performer {
        cello_with(&Setup::default())
    }

    /// A cello performer activated at `FS` and configured with `setup`.
    fn cello_with(setup: &Setup) -> Performer {
        let mut p = Performer::new(InstrumentKind::Cello);
        p.activate(setup, FS).unwrap();
        p.configure(setup);
        p
    }

    #[test]
    fn a_chosen_bridge_colours_the_point_bow_sound_and_leaves_the_string_alone() {
        // The point-bow body only colours what radiates (it feeds nothing back): with a
        // chosen bridge's reduction as the body the string moves exactly as with the
        // generic body, and the sound changes, towards the bridge's strongest horizontal
        // mode.
        let bow = BowControl::default();
        let play = |bridge: Option<BridgeModes>| {
            let setup = Setup::default();
            let mut p = Performer::new(InstrumentKind::Cello);
            p.set_user_bridge(InstrumentKind::Cello, bridge);
            p.activate(&setup, FS).unwrap();
            p.configure(&setup);
            p.note_on(50, 0.8);
            let frames: Vec<Frame> = (0..(0.5 * FS) as usize).map(|_| p.tick(bow)).collect();
            frames
        };
        let violin = bridge_data::shipped_violin_bridge();
        let (modes, _) = crate::dsp::body::body_from_bridge(&violin.modes);
        let generic = play(None);
        let chosen = play(Some(violin));
        let probe = |f: &[Frame]| -> Vec<u64> {
            f.iter()
                .map(|x| x.bow_point_velocity_m_per_s.to_bits())
                .collect()
        };
        assert_eq!(probe(&generic), probe(&chosen), "the body moved the string");
        assert!(chosen.iter().all(|f| f.audio.is_finite()));
        let audio = |f: &[Frame]| -> Vec<f64> {
            f[(0.2 * FS) as usize..].iter().map(|x| x.audio).collect()
        };
        let (a, b) = (audio(&generic), audio(&chosen));
        assert_ne!(a, b, "the chosen bridge changed nothing");
        // The strongest kept mode's band carries more of the sound than with the generic
        // body (the D3 note's partials near it are lifted).
        let near = |x: &[f64]| {
            let f = modes[0].freq_hz;
            (0..5)
                .map(|k| {
                    crate::analysis::partial_amplitude(
                        x,
                        FS,
                        f * 2f64.powf((k as f64 - 2.0) / 24.0),
                    )
                })
                .fold(0.0, f64::max)
                / crate::analysis::rms(x)
        };
        assert!(
            near(&b) > near(&a),
            "{} vs {} at {} Hz",
            near(&b),
            near(&a),
            modes[0].freq_hz
        );
    }

    #[test]
    fn one_bow_plays_two_adjacent_strings_and_leaves_the_others_ringing() {
        let bow = BowControl::default();
        let settle = |p: &mut Performer| {
            for _ in 0..(0.1 * FS) as usize {
                p.tick(bow);
            }
        };
        let bowed = |p: &Performer| -> Vec<usize> {
            (0..4).filter(|&i| p.strings().bow_gain(i) > 0.0).collect()
        };
        // A double stop on the D and A strings (2, 3): both bowed.
        let mut p = cello();
        p.note_on(50, 0.8);
        p.note_on(57, 0.8);
        settle(&mut p);
        assert_eq!(bowed(&p), [2, 3]);
        // C and A strings (0, 3) cannot share a bow: the later one takes it, and the C
        // string, bowed for 0.1 s first, rings on.
        let mut p = cello();
        p.note_on(36, 0.8);
        settle(&mut p);
        p.note_on(57, 0.8);
        settle(&mut p);
        assert_eq!(bowed(&p), [3]);
        assert!(
            p.strings().string(0).energy_j() > 0.0,
            "the C string rings on"
        );
        // A four-note chord, low to high: the bow ends on the top two strings.
        let mut p = cello();
        for note in [36, 43, 50, 57] {
            p.note_on(note, 0.8);
        }
        settle(&mut p);
        assert_eq!(bowed(&p), [2, 3]);
    }

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
        // Half expression is half the range down, on both (smoothing and the attack have
        // settled after 0.5 s; 1e-6 is f32 rounding).
        let scale = 10f64.powf(-DYNAMICS_RANGE_DB * 0.5 / 20.0);
        assert!(((v as f64).abs() / 0.1 - scale).abs() < 1e-6, "{v}");
        assert!((f as f64 / 1.0 - scale).abs() < 1e-6, "{f}");
        p.note_off(50);
        assert_eq!(p.bowed_bow(), None);
    }

    /// Bows cello D3 at the defaults with the expression at `e` from the start; returns
    /// the RMS over 1.5..2 s and the regime of its last 8 periods on the probe.
    fn bowed_at(e: f32) -> (f64, Option<Regime>) {
        let mut p = cello();
        p.set_controller(11, e);
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        let n = (2.0 * FS) as usize;
        let mut audio = Vec::with_capacity(n);
        let mut probe = Vec::with_capacity(n);
        for i in 0..n {
            if i % 256 == 0 {
                p.configure(&Setup::default());
            }
            let frame = p.tick(bow);
            audio.push(frame.audio);
            probe.push(ContactSample::new(&frame, &p.bow()));
        }
        let tail = &audio[(1.5 * FS) as usize..];
        let rms = (tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64).sqrt();
        let f0 = midi_to_hz(50.0);
        let window = (8.0 * FS / f0) as usize;
        (
            rms,
            classify_regime(&probe[n - window..], FS as f32, f0 as f32),
        )
    }

    #[test]
    fn without_the_window_guard_a_soft_dynamic_under_a_heavy_bow_turns_raucous() {
        // Expression 0.25 is 22.5 dB down: with the guard the force follows the velocity
        // (Helmholtz, the test below); without it a bow 13x slower under the full 1 N
        // presses about three times Schelleng's F_max for cello D3 and loses Helmholtz
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
        let bow = BowControl::default();
        let n = (2.0 * FS) as usize;
        let mut probe = Vec::with_capacity(n);
        for i in 0..n {
            if i % 256 == 0 {
                p.configure(&setup);
            }
            let frame = p.tick(bow);
            probe.push(ContactSample::new(&frame, &p.bow()));
        }
        let played = p.bow();
        assert_eq!(played.force_n, 1.0, "the force is the parameter's");
        assert_eq!(played.position_beta, 0.1, "no drift without the guard");
        let f0 = midi_to_hz(50.0);
        let window = 8 * (FS / f0) as usize;
        let tail = &probe[n - window..];
        let regime = classify_regime(tail, FS as f32, f0 as f32);
        let v: Vec<f64> = tail.iter().map(|s| s.string_velocity as f64).collect();
        let v_b = played.velocity_m_per_s;
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

    #[test]
    fn with_the_window_guard_soft_dynamics_move_the_bow_from_the_bridge() {
        let mut p = cello();
        p.set_controller(11, 0.0);
        p.note_on(50, 0.8);
        let bow = BowControl::default();
        for _ in 0..(0.5 * FS) as usize {
            p.tick(bow);
        }
        // -30 dB: the bow 2^(1/2) times farther from the bridge (1e-6: the smoothing's
        // last step and rounding).
        assert!(
            (p.bow().position_beta / 0.1 - 2f64.sqrt()).abs() < 1e-6,
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
        let mut last = 0.0;
        for e in [0.25, 0.5, 0.75, 1.0] {
            let (rms, regime) = bowed_at(e);
            println!("expression {e}: RMS {rms:.5}, {regime:?}");
            assert!(rms > last, "expression {e}: RMS {rms} not above {last}");
            // Velocity and force scale together, so the bow keeps its place in the window.
            assert_eq!(regime, Some(Regime::Helmholtz), "expression {e}");
            last = rms;
        }
        // The amplitude follows the bow velocity (Raman): 30 dB of range, so expression
        // 0.5 plays 15 dB below full, within 3 dB (the corners round more at low force).
        let ratio_db = 20.0 * (bowed_at(0.5).0 / bowed_at(1.0).0).log10();
        assert!((ratio_db + 15.0).abs() < 3.0, "{ratio_db:.1} dB");
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

    /// Depth (largest offset, cents) and rate (upward zero crossings, Hz) after the fade-in.
    fn depth_and_rate(cents: &[f64]) -> (f64, f64) {
        let steady = &cents[((VIBRATO_DELAY_S + VIBRATO_FADE_S) * FS) as usize + 64..];
        let depth = steady.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let ups: Vec<usize> = steady
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
            .map(|(i, _)| i)
            .collect();
        let rate = (ups.len() - 1) as f64 * FS / (ups[ups.len() - 1] - ups[0]) as f64;
        (depth, rate)
    }

    #[test]
    fn the_mod_wheel_vibrato_moves_the_finger_at_its_rate_and_depth() {
        let cents = vibrato_cents(&Setup::default(), &[]);
        // Silent through the onset delay.
        let delay = (VIBRATO_DELAY_S * FS) as usize;
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
        assert!((rate / 7.0 - 1.0).abs() < 0.05, "parameter: {rate}");
        // CC19 at 0: the slowest rate.
        let (_, rate) = depth_and_rate(&vibrato_cents(&setup, &[(19, 0.0)]));
        assert!(
            (rate / VIBRATO_RATE_MIN_HZ - 1.0).abs() < 0.05,
            "CC19: {rate}"
        );
        // The drift: successive cycles are not all the same length, and none strays
        // further than the drift allows (3 %, plus 2 % for cycles counted to a sample
        // and the finger's 64-sample steps).
        let cents = vibrato_cents(&Setup::default(), &[]);
        let steady = &cents[((VIBRATO_DELAY_S + VIBRATO_FADE_S) * FS) as usize + 64..];
        let ups: Vec<usize> = steady
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
            .map(|(i, _)| i)
            .collect();
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

    /// The probe's velocity while the string sticks to the bow, averaged over samples
    /// `from..to` of a render where `events` happen at their samples.
    fn stick_velocity(p: &mut Performer, from: usize, to: usize) -> f64 {
        let bow = BowControl::default();
        let mut sum = 0.0;
        let mut n = 0;
        for i in 0..to {
            let frame = p.tick(bow);
            let rel = frame.bow_point_velocity_m_per_s - p.bow().velocity_m_per_s;
            if i >= from && rel.abs() < 0.1 * bow.velocity_m_per_s {
                sum += frame.bow_point_velocity_m_per_s;
                n += 1;
            }
        }
        sum / n.max(1) as f64
    }

    #[test]
    fn skipping_silent_blocks_gives_the_same_bits_as_ticking_them() {
        // A phrase with gaps long enough for the strings to fall asleep, vibrato and
        // dynamics moving through the silences; one performer ticks every sample, the
        // other skips blocks while asleep, as the plugin does.
        // (A lifted string sleeps once its energy falls 120 dB or so: about 15 s for D3.)
        let events: [(usize, u8, Option<f32>); 4] = [
            (0, 50, Some(1.0)),
            (4_800, 50, None),
            (20 * 48_000, 69, Some(0.3)),
            (20 * 48_000 + 9_600, 69, None),
        ];
        let render = |skipping: bool| {
            let mut p = cello();
            p.set_controller(1, 0.7);
            let bow = BowControl::default();
            let (block, frames) = (512, 40 * 48_000);
            let mut out = Vec::with_capacity(frames);
            let mut skipped = 0;
            let mut next = 0;
            while out.len() < frames {
                let start = out.len();
                if start == 3 * 48_000 {
                    p.set_controller(11, 0.4);
                }
                let lands = next < events.len() && events[next].0 < start + block;
                if skipping && !lands && p.is_asleep() {
                    p.skip(block, bow);
                    out.resize(start + block, 0.0);
                    skipped += 1;
                    continue;
                }
                for i in start..start + block {
                    while next < events.len() && events[next].0 == i {
                        match events[next] {
                            (_, n, Some(v)) => p.note_on(n, v),
                            (_, n, None) => p.note_off(n),
                        }
                        next += 1;
                    }
                    out.push(p.tick(bow).audio);
                }
                p.configure(&Setup::default());
            }
            (out, skipped)
        };
        let (ticked, _) = render(false);
        let (skipped, blocks) = render(true);
        assert!(blocks > 100, "only {blocks} blocks skipped");
        assert!(ticked.iter().any(|x| x.abs() > 1e-3));
        let differing = ticked
            .iter()
            .zip(&skipped)
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(differing, 0);
    }

    #[test]
    fn direct_bow_controllers_move_the_played_bow_until_the_parameter_moves() {
        let mut p = cello();
        p.note_on(50, 0.5);
        let bow = BowControl::default();
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        // CC22 at 100: the force knob's curve, 10 (100/127)^4 = 3.8 N.
        p.set_controller(direct::CC_BOW_FORCE, 100.0 / 127.0);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        let want = direct::force_at((100.0f32 / 127.0) as f64);
        assert!((p.bow().force_n - want).abs() < 1e-9, "{:?}", p.bow());
        // The parameter moves (automation): the force is the parameter's again.
        let automated = BowControl {
            force_n: 2.0,
            ..bow
        };
        p.tick(automated);
        assert_eq!(p.bow().force_n, 2.0);
    }

    #[test]
    fn a_custom_midi_map_routes_a_controller_to_its_targets_and_unmaps_the_rest() {
        // CC74 drives the bow force over the lower half of its controller range and the
        // vibrato depth; CC22 and CC11, unmapped, do nothing.
        let mut map = MidiMap::empty();
        let mut force = midi_map::Mapping::new(74, Target::BowForce);
        force.max = 0.5;
        map.add(force);
        map.add(midi_map::Mapping::new(74, Target::VibratoDepth));
        let mut p = cello();
        p.set_midi_map(&map);
        p.note_on(50, 0.5);
        let bow = BowControl::default();
        let run = |p: &mut Performer| {
            for _ in 0..(0.2 * FS) as usize {
                p.tick(bow);
            }
        };
        run(&mut p);
        let before = p.bow();
        p.set_controller(direct::CC_BOW_FORCE, 1.0);
        p.set_controller(11, 0.2);
        run(&mut p);
        assert_eq!(p.bow(), before, "an unmapped controller moved the bow");
        assert_eq!(p.gesture.vibrato_cents, 0.0);
        p.set_controller(74, 1.0);
        run(&mut p);
        // The force controller's curve at half its travel (the mapping's top).
        assert!(
            (p.bow().force_n - direct::force_at(0.5)).abs() < 1e-9,
            "{:?}",
            p.bow()
        );
        assert_eq!(p.gesture.vibrato_cents, MAX_VIBRATO_CENTS);
        // Back to the default map: CC22 is the force again.
        p.set_midi_map(&MidiMap::default());
        p.set_controller(direct::CC_BOW_FORCE, 1.0);
        run(&mut p);
        assert!((p.bow().force_n - direct::force_at(1.0)).abs() < 1e-9);
    }

    #[test]
    fn a_block_gives_the_same_samples_as_ticking_it() {
        // Through an attack, a steady stretch, a controller and a second note, with blocks
        // of every size from 1 to 700: the block path is only a shortcut.
        let bow = BowControl::default();
        let events = |p: &mut Performer, at: usize| match at {
            0 => p.note_on(50, 0.8),
            20_000 => p.set_controller(11, 0.6),
            30_000 => p.note_on(57, 0.4),
            40_000 => p.note_off(50),
            _ => {}
        };
        let marks = [0, 20_000, 30_000, 40_000, 48_000];
        let mut ticked = cello();
        let mut want = Vec::new();
        for at in 0..48_000 {
            events(&mut ticked, at);
            want.push(ticked.tick(bow).audio.to_bits());
        }
        for block in [1, 7, 64, 511, 700] {
            let mut p = cello();
            let mut got = Vec::new();
            for (at, n) in spans(&marks, block) {
                events(&mut p, at);
                let mut out = vec![0.0; n];
                p.tick_block(bow, &mut out);
                got.extend(out.iter().map(|x| x.to_bits()));
            }
            assert_eq!(got, want, "blocks of {block}");
        }
    }

    #[test]
    fn a_run_with_the_bow_moving_gives_the_same_frames_as_ticking_it() {
        // As the plugin while automation moves: the bow changes every sample (a slow
        // force and position sweep, so the gesture's position factor is not 1 after the
        // ff controller), through an attack, a controller, a second note, a rubbed source
        // ringing on after a switch, with runs of every size from 1 to 700.
        let bow_at = |at: usize| {
            let t = at as f64 / FS;
            BowControl {
                velocity_m_per_s: 0.1 + 0.02 * (3.0 * t).sin(),
                force_n: 0.8 + 0.3 * (2.0 * t).sin(),
                position_beta: 0.1 + 0.02 * (5.0 * t).sin(),
            }
        };
        let events = |p: &mut Performer, at: usize| match at {
            0 => p.note_on(50, 0.8),
            20_000 => p.set_controller(11, 1.0),
            30_000 => p.note_on(57, 0.4),
            35_000 => p.configure(&Setup {
                rubbed: Some(RubbedPreset::ALL[0]),
                ..Setup::default()
            }),
            40_000 => p.note_off(50),
            _ => {}
        };
        let marks = [0, 20_000, 30_000, 35_000, 40_000, 48_000];
        let mut ticked = cello();
        let mut want = Vec::new();
        for at in 0..48_000 {
            events(&mut ticked, at);
            let f = ticked.tick(bow_at(at));
            let b = ticked.bow();
            want.push(
                [
                    f.audio,
                    f.bow_point_velocity_m_per_s,
                    b.force_n,
                    b.position_beta,
                ]
                .map(f64::to_bits),
            );
        }
        for run in [1, 7, 64, 511, 700] {
            let mut p = cello();
            let mut got = Vec::new();
            for (at, n) in spans(&marks, run) {
                events(&mut p, at);
                let mut k_next = at;
                p.tick_run(
                    n,
                    || {
                        k_next += 1;
                        (bow_at(k_next - 1), k_next - 1)
                    },
                    |k, sample, f, b, _| {
                        assert_eq!(sample, at + k, "the caller's value rides with its sample");
                        got.push(
                            [
                                f.audio,
                                f.bow_point_velocity_m_per_s,
                                b.force_n,
                                b.position_beta,
                            ]
                            .map(f64::to_bits),
                        );
                    },
                );
            }
            assert_eq!(got, want, "runs of {run}");
        }
    }

    #[test]
    fn alternate_bow_strokes_reverse_the_stick_velocity() {
        let mut p = cello();
        let mut sticks = Vec::new();
        for note in [50, 52, 53, 55] {
            p.note_on(note, 0.8);
            // 0.3 s into each 0.5 s note: past the attack.
            sticks.push(stick_velocity(
                &mut p,
                (0.3 * FS) as usize,
                (0.5 * FS) as usize,
            ));
            p.note_off(note);
        }
        println!("stick velocities {sticks:?}");
        // The string sticks to the bow, which moves at 0.1 m/s down, up, down, up (10 %:
        // the probe's velocity while sticking includes small ripples).
        for (k, v) in sticks.iter().enumerate() {
            let want = if k % 2 == 0 { 0.1 } else { -0.1 };
            assert!((v - want).abs() < 0.01, "note {k}: {v}");
        }
    }

    #[test]
    fn a_legato_note_on_one_string_keeps_the_stroke_and_the_bow_on() {
        let mut p = cello();
        let bow = BowControl::default();
        p.note_on(50, 0.8);
        // Past the attack and its accent.
        for _ in 0..(0.4 * FS) as usize {
            p.tick(bow);
        }
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // E3 lands before D3 lifts: the same string, so the finger moves and the bow goes
        // on: no new attack (the played bow stays the parameters'), no force dip.
        p.note_on(52, 0.8);
        p.note_off(50);
        assert_eq!(InstrumentKind::Cello.string_for_note(52), Some(string));
        for _ in 0..(0.3 * FS) as usize {
            p.tick(bow);
            assert_eq!(p.bow(), bow);
            assert_eq!(p.strings().bow_gain(string), 1.0);
        }
        // A separate note after both lift starts an up-bow from rest.
        p.note_off(52);
        p.note_on(53, 0.8);
        p.tick(bow);
        assert!(p.bow().velocity_m_per_s.abs() < 0.01);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        assert_eq!(p.bow().velocity_m_per_s, -bow.velocity_m_per_s);
    }

    #[test]
    fn a_soft_legato_note_glides_the_finger_and_a_firm_one_jumps() {
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // D3 bowed, then F3 legato on the same string at `velocity`; the string's pitch
        // (cents above D3) every 64 samples for 0.3 s.
        let slide = |velocity: f32| {
            let mut p = cello();
            let bow = BowControl::default();
            p.note_on(50, 0.8);
            for _ in 0..(0.3 * FS) as usize {
                p.tick(bow);
            }
            let d3 = p.strings().string(string).fundamental_hz();
            p.note_on(53, velocity);
            p.note_off(50);
            assert_eq!(InstrumentKind::Cello.string_for_note(53), Some(string));
            let mut cents = Vec::new();
            for i in 0..(0.3 * FS) as usize {
                p.tick(bow);
                if i % 64 == 0 {
                    cents.push(1200.0 * (p.strings().string(string).fundamental_hz() / d3).log2());
                }
            }
            cents
        };
        let firm = slide(0.8);
        assert!(
            (firm[0] - 300.0).abs() < 10.0,
            "a firm legato jumps: {}",
            firm[0]
        );
        let soft = slide(0.3);
        // Rises monotonically from D3 to F3 over the glide time (0.12 s), then stays.
        assert!(soft.windows(2).all(|w| w[1] >= w[0] - 1e-9));
        let at = |t: f64| soft[(t * FS / 64.0) as usize];
        assert!(at(0.0) < 20.0, "{}", at(0.0));
        let half = at(0.5 * GLIDE_S_DEFAULT);
        // Halfway in time, halfway in semitones (within 20 cents: the intonation table
        // moves each place on the string by a few cents, and steps are 1.3 ms).
        assert!((half - 150.0).abs() < 20.0, "{half}");
        assert!((at(0.25) - firm[firm.len() - 1]).abs() < 0.01);
    }

    #[test]
    fn a_soft_legato_note_glides_the_thermal_finger_too() {
        // Paper B's thermal cello: D3 bowed, then F3 legato and soft on the same string;
        // the string's tuning (cents above D3) every 64 samples.
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        let setup = Setup {
            point_law: None,
            ..Setup::default()
        };
        let mut p = cello_with(&setup);
        let bow = BowControl::default();
        let tuned = |p: &Performer| {
            p.thermal(InstrumentKind::Cello)
                .unwrap()
                .string(string)
                .fundamental_hz()
        };
        p.note_on(50, 0.8);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        let d3 = tuned(&p);
        p.note_on(53, 0.3);
        p.note_off(50);
        let (mut cents, mut audio) = (Vec::new(), Vec::new());
        for i in 0..(0.25 * FS) as usize {
            audio.push(p.tick(bow).audio);
            if i % 64 == 0 {
                cents.push(1200.0 * (tuned(&p) / d3).log2());
            }
        }
        // The bow stays on through the glide: every 10 ms of it sounds.
        assert!(audio.chunks(480).all(|c| crate::analysis::rms(c) > 1e-3));
        let at = |t: f64| cents[(t * FS / 64.0) as usize];
        // Rises monotonically from D3 to F3 over the glide time, then stays.
        assert!(cents.windows(2).all(|w| w[1] >= w[0] - 1e-9));
        assert!(at(0.0) < 20.0, "{}", at(0.0));
        // Halfway in time, halfway in semitones (within 20 cents: the intonation table
        // moves each place on the string by a few cents, and steps are 1.3 ms).
        let half = at(0.5 * GLIDE_S_DEFAULT);
        assert!((half - 150.0).abs() < 20.0, "{half}");
        let end = cents[cents.len() - 1];
        assert!((end - 300.0).abs() < 15.0, "{end}");
        assert!((at(0.2) - end).abs() < 0.01);
    }

    #[test]
    fn the_bend_range_follows_the_setup_and_midi_rpn_0() {
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // The pitch `note` sounds at when stopped on D3's string, unbent.
        let stopped_hz = |note: u8| {
            let setup = Setup {
                preferred_string: Some(string),
                ..Setup::default()
            };
            let mut p = cello_with(&setup);
            p.note_on(note, 0.8);
            p.strings().string(string).fundamental_hz()
        };
        let mut p = cello();
        p.note_on(50, 0.8);
        let hz = |p: &Performer| p.strings().string(string).fundamental_hz();
        let same = |a: f64, b: f64| (1200.0 * (a / b).log2()).abs() < 0.01;
        p.set_pitch_wheel(1.0);
        assert!(same(hz(&p), stopped_hz(52)), "default range: two semitones");
        let setup = Setup {
            bend_range_semitones: 7.0,
            ..Setup::default()
        };
        p.configure(&setup);
        assert!(
            same(hz(&p), stopped_hz(57)),
            "the parameter: seven semitones"
        );
        // RPN 0 (CC101 0, CC100 0, CC6 12, CC38 0): twelve semitones, over the parameter.
        for (cc, v) in [(101, 0), (100, 0), (6, 12), (38, 0)] {
            p.set_controller(cc, v as f32 / 127.0);
        }
        assert!(same(hz(&p), stopped_hz(62)), "RPN 0: twelve semitones");
        // Down: D3 is the open D string, which a bend cannot take further below its open
        // pitch than the tuning margin (within 10 cents: the intonation table moves each
        // place on the string by a few cents).
        p.set_pitch_wheel(0.0);
        let open = midi_to_hz(50.0);
        let cents = 1200.0 * (hz(&p) / open).log2();
        assert!(
            (cents + 100.0 * PITCH_BEND_SEMITONES).abs() < 10.0,
            "{cents}"
        );
        // A data entry for another RPN changes nothing.
        for (cc, v) in [(101, 0), (100, 1), (6, 3)] {
            p.set_controller(cc, v as f32 / 127.0);
        }
        assert_eq!(p.bend_range(), 12.0);
    }
}
