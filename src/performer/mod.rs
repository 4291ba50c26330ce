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
//! Its parts: `setup` (what it is told each block, [`Setup`], and what it tells the host,
//! [`Status`]), `sources` (building the engines, following the setup, switching sources),
//! `routing` (keys to strings, legato, double stops, per-note expression), `midi` (the
//! wheel, pressure, RPN and controllers through [`midi_map`]), `gesture` (dynamics,
//! vibrato, the bow as played), [`stroke`] (bow direction and attack), [`direct`] (bow
//! controllers), [`mpe`], [`articulation`] (arco, pizzicato, keyswitches), `render` (a
//! sample, a block, a run) and `tail`.
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

pub mod articulation;
mod block;
pub mod catch;
pub mod direct;
mod gesture;
mod midi;
pub mod midi_map;
pub mod mpe;
mod render;
mod routing;
mod setup;
mod sources;
pub mod stroke;
mod tail;
#[cfg(test)]
mod testing;

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
pub use articulation::Articulation;
pub use block::Event;
use direct::DirectBow;
use gesture::Gesture;
pub use gesture::{
    bow_scale_at, guarded_bow, slip_damping, slowest_bow_scale, GuardedBow,
    DYNAMICS_DRIFT_EXPONENT, DYNAMICS_RANGE_DB, DYNAMICS_SMOOTHING_S, GLIDE_S_DEFAULT,
    HYPERBOLIC_SLIP_DAMPING, MAX_VIBRATO_CENTS, PORTAMENTO_BELOW_VELOCITY, STRIBECK_SLIP_DAMPING,
    STRIBECK_SLIP_SPAN, STRIBECK_SLOWEST_SCALE, THERMAL_SLOWEST_SCALE, VIBRATO_DELAY_S,
    VIBRATO_DEPTH_DRIFT, VIBRATO_DRIFT_S, VIBRATO_FADE_S, VIBRATO_RATE_DRIFT, VIBRATO_RATE_HZ,
    VIBRATO_RATE_MAX_HZ, VIBRATO_RATE_MIN_HZ,
};
use midi_map::{MidiMap, Target};
use mpe::{Handled, Mpe, NoteState};
use routing::NoteSlot;
pub use setup::{Setup, Source, Status, ThermalNodes};
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
    /// The attack's catch while it presses the string into Helmholtz motion ([`catch`]).
    catch: Option<catch::Catch>,
    /// The bow controls MIDI controllers hold (CC21-23).
    direct: DirectBow,
    /// Bridges the player chose for the thermal instrument of each kind.
    user_bridges: [Option<BridgeModes>; InstrumentKind::COUNT],
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
    /// The articulation a keyswitch or controller chose, until the parameter moves
    /// ([`articulation`]).
    articulation_midi: Option<Articulation>,
    /// The mute a controller put on or took off, until the parameter moves.
    con_sordino_midi: Option<bool>,
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
            catch: None,
            direct: DirectBow::new(48_000.0),
            user_bridges: Default::default(),
            others_awake: false,
            steady: None,
            configured: false,
            bow_now: BowControl::default(),
            mpe: Mpe::default(),
            notes: [NoteSlot::default(); 128],
            articulation_midi: None,
            con_sordino_midi: None,
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
        self.thermal.get(kind.index())
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
    /// held and notes are bowed, `None` otherwise: what the editor marks on its pad.
    pub fn bowed_bow(&self) -> Option<(f32, f32)> {
        let bowing =
            self.articulation() == Articulation::Arco || matches!(self.source, Source::Rubbed(_));
        (bowing && self.held.iter().any(|&h| h)).then_some((
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
}
