//! The instrument: four bowed waveguide strings of a violin, viola or cello, a shared bow,
//! note handling and a generic body.
//!
//! **Which string plays a note.** A note goes to the highest string whose open pitch is at
//! or below it (the lowest hand position), stopped so it sounds the note. Notes below the
//! lowest open string are refused; so are notes more than [`MAX_STOP_SEMITONES`] above
//! the highest open string (the end of the fingerboard). Each string plays one note at a
//! time: two notes on different strings are a double stop.
//!
//! Note on stops the string and lands the bow (the force ramps up over [`BOW_RAMP_S`]);
//! note off lifts it (the force ramps down) and the string rings on, still stopped, and
//! decays. A string whose energy falls below [`SLEEP_ENERGY_J`] with the bow lifted is
//! cleared and skipped until the next note on it.
//!
//! The notes, fingers and bow envelopes are the four-string instrument's
//! ([`super::strings::FourStrings`], shared with paper B's instrument); this module holds
//! the strings and body it plays ([`WaveguideBank`]) and what only they have (friction
//! laws, torsion, bow hair, custom bodies).
//!
//! ```
//! use colophony::dsp::instrument::{BowControl, Instrument, InstrumentKind};
//! let mut cello = Instrument::new(InstrumentKind::Cello, 48_000.0);
//! assert_eq!(cello.note_on(50), Some(2)); // D3 on the D string
//! let bow = BowControl { velocity_m_per_s: 0.1, force_n: 1.0, position_beta: 0.1 };
//! let peak = (0..24_000).map(|_| cello.tick(bow).audio.abs()).fold(0.0, f64::max);
//! assert!(peak > 0.01 && peak < 1.0);
//! ```

use super::body::{BodyMode, BodyModes, MAX_BODY_MODES};
use super::friction::bristle::{BristleParams, SolverStats};
use super::friction::{AnyFriction, BowInput, FrictionContact, FrictionModel};
use super::halfband::HalfbandDecimator;
use super::intonation::{self, MAX_CORRECTION_CENTS};
use super::resample::Resampler;
pub use super::strings::FourStrings;
use super::strings::{StringBank, StringBow};
use super::waveguide::{StringSpec, WaveguideString};

/// The rate the point-bow strings and their body run at, whatever the host's: the output
/// is resampled to the host rate ([`Resampler`]). The bowed string's regime (Helmholtz
/// motion or a double slip: both are stable over much of the window, and which one an
/// attack falls into changes with any detail of the discretisation) and its pitch then do
/// not depend on the project's rate, and the intonation table, measured at this rate,
/// holds at every rate. 48 kHz: the commonest host rate (no resampling there), and twice
/// the hearing range. Measured in docs/precision.md (issue 16, item 3). The violin's and
/// viola's strings run at a multiple of it ([`InstrumentKind::point_oversampling`]).
pub const INTERNAL_RATE_HZ: f64 = 48_000.0;

/// Most times [`INTERNAL_RATE_HZ`] any instrument's point strings run at
/// ([`InstrumentKind::point_oversampling`]); their delay lines are sized for it.
pub const MAX_POINT_OVERSAMPLING: usize = 2;

pub const STRINGS: usize = 4;
/// Highest note above the highest open string (about the end of the fingerboard).
pub const MAX_STOP_SEMITONES: u8 = 31;
/// Bow landing and lifting time, s.
pub const BOW_RAMP_S: f64 = 0.02;
/// Default pitch-bend range, semitones either way; also how far a bend may take a note
/// below its open string or above the highest note (the tuning margins below).
pub const PITCH_BEND_SEMITONES: f64 = 2.0;
/// Widest pitch-bend range, semitones either way (the finger slides; a bend still stops
/// at [`PITCH_BEND_SEMITONES`] below the open string and above the highest note).
pub const MAX_BEND_RANGE_SEMITONES: f64 = 12.0;
/// Reference pitch A4, Hz: lowest (baroque pitch), default and highest (Venetian high
/// pitch). Every note, open strings included, is tuned from it.
pub const REFERENCE_HZ_MIN: f64 = 415.0;
pub const REFERENCE_HZ_DEFAULT: f64 = 440.0;
pub const REFERENCE_HZ_MAX: f64 = 466.0;
/// Semitones the tuning can move every note (the reference pitch, then the bend) below
/// and above its equal-tempered pitch at A4 = 440 Hz: the strings' delay lines and the
/// thermal instrument's rate floor are sized for them.
pub const LOWEST_TUNING_SEMITONES: f64 =
    -PITCH_BEND_SEMITONES - 1.013 - MAX_CORRECTION_CENTS / 100.0; // 12 log2(415/440)
pub const HIGHEST_TUNING_SEMITONES: f64 =
    PITCH_BEND_SEMITONES + 0.993 + MAX_CORRECTION_CENTS / 100.0; // 12 log2(466/440)

/// Semitones from A4 = 440 Hz to the reference `a4_hz` (clamped to
/// [`REFERENCE_HZ_MIN`]..=[`REFERENCE_HZ_MAX`]; a NaN is the default).
pub fn reference_semitones(a4_hz: f64) -> f64 {
    if a4_hz.is_nan() {
        return 0.0;
    }
    12.0 * (a4_hz.clamp(REFERENCE_HZ_MIN, REFERENCE_HZ_MAX) / REFERENCE_HZ_DEFAULT).log2()
}
/// A lifted string whose wave energy is below this sleeps (about -130 dB below a
/// default bowed note's few millijoules).
pub const SLEEP_ENERGY_J: f64 = 1e-16;
/// The body sleeps once every mode's state is below this (N-scale: output below -200 dB of
/// a bowed note).
const BODY_QUIET_N: f64 = 1e-12;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstrumentKind {
    Violin,
    Viola,
    Cello,
}

impl InstrumentKind {
    pub const ALL: [InstrumentKind; 3] = [Self::Violin, Self::Viola, Self::Cello];

    pub fn name(self) -> &'static str {
        match self {
            Self::Violin => "violin",
            Self::Viola => "viola",
            Self::Cello => "cello",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(name))
    }

    /// MIDI notes of the open strings, low to high.
    pub fn open_notes(self) -> [u8; STRINGS] {
        match self {
            Self::Violin => [55, 62, 69, 76],
            Self::Viola => [48, 55, 62, 69],
            Self::Cello => [36, 43, 50, 57],
        }
    }

    /// String data, low to high (docs/literature-values.md §1.4: Desvages/NESS sets; viola G, D, A
    /// inharmonicities are not in the table and are chosen between the neighbouring
    /// violin and viola values). Open pitches are equal-tempered from A4 = 440 Hz.
    pub fn strings(self) -> [StringSpec; STRINGS] {
        let (z0, b): ([f64; 4], [f64; 4]) = match self {
            Self::Violin => (
                [0.350, 0.303, 0.203, 0.173],
                [2.7e-4, 2.3e-4, 2.1e-4, 4.8e-5],
            ),
            Self::Viola => (
                [0.484, 0.323, 0.281, 0.274],
                [3.4e-4, 2.7e-4, 2.3e-4, 2.1e-4],
            ),
            Self::Cello => (
                [1.91, 0.833, 0.506, 0.504],
                [5.7e-4, 1.7e-4, 1.5e-4, 5.3e-5],
            ),
        };
        let notes = self.open_notes();
        std::array::from_fn(|i| StringSpec {
            open_hz: midi_to_hz(notes[i] as f64),
            z0_kg_per_s: z0[i],
            inharmonicity_open: b[i],
            q1: 500.0,
            q_hi: 250.0,
        })
    }

    /// Generic body modes (see [`super::body`]).
    fn body_modes(self) -> [BodyMode; 5] {
        let scale = match self {
            Self::Violin => 1.0,
            Self::Viola => 0.8,
            Self::Cello => 0.42,
        };
        [
            (275.0, 12.0, 0.8),
            (405.0, 15.0, 0.5),
            (470.0, 18.0, 1.0),
            (540.0, 18.0, 1.0),
            (2500.0, 2.5, 0.6),
        ]
        .map(|(f, q, gain)| BodyMode {
            freq_hz: f * scale,
            q,
            gain,
        })
    }

    /// What the bow force is multiplied by on string `index` when the strings are weighted
    /// ([`Instrument::set_string_weighting`]): the string's impedance over
    /// [`WEIGHT_REFERENCE_Z0`]. Schelleng's limits are both proportional to `Z0` (with the
    /// dashpot bridge `R = 2 Q1 Z0 / pi`, docs/literature-values.md), so one force parameter then
    /// keeps the same place in every string's window, as a player leans into the heavy
    /// strings.
    pub fn string_weight(self, index: usize) -> f64 {
        self.string_weight_for(index, WEIGHT_REFERENCE_Z0)
    }

    /// String `index`'s impedance over `reference_z0` (kg/s): its weight for a model whose
    /// force parameter is the force on a string of that impedance (paper B's thermal
    /// model: [`crate::dsp::thermal_instrument::THERMAL_WEIGHT_REFERENCE_Z0`]).
    pub fn string_weight_for(self, index: usize, reference_z0: f64) -> f64 {
        self.strings()[index.min(STRINGS - 1)].z0_kg_per_s / reference_z0
    }

    /// How many times [`INTERNAL_RATE_HZ`] each point-bow string of this instrument runs
    /// at (the bridge force of the faster ones is decimated back to it by a half-band
    /// filter, [`super::halfband`], before the body). A point bow's slip starts on a
    /// sample, so the Helmholtz period locks to the sample grid (docs/playing-space.md,
    /// "The sample-grid lock"): the violin's and viola's top octaves (periods of 18 to 55
    /// samples at 48 kHz) play 96 kHz strings, where the lock is half as wide, and so does
    /// the cello's A string (A4 to A5 have 110 to 55 samples a period at 48 kHz, E6 36;
    /// docs/playing-space.md, "The cello's A string at 96 kHz"). The cello's three lower
    /// strings, which play the notes below A3 unless a note is asked onto them, run at
    /// 48 kHz, at half the cost.
    pub fn point_oversampling(self) -> [usize; STRINGS] {
        match self {
            Self::Violin | Self::Viola => [2; STRINGS],
            Self::Cello => [1, 1, 1, 2],
        }
    }

    /// Output scale: bridge force to a sample value, so that a default note of any
    /// instrument peaks near -12 dBFS.
    pub fn output_scale_per_n(self) -> f64 {
        let mean_z0: f64 =
            self.strings().iter().map(|s| s.z0_kg_per_s).sum::<f64>() / STRINGS as f64;
        0.1 / mean_z0
    }

    /// The string a note goes to, if the instrument can play it.
    /// Vibrating length of the open strings, m (docs/literature-values.md §1.4: violin 0.32,
    /// viola 0.38, cello 0.69).
    pub fn string_length_m(self) -> f64 {
        match self {
            Self::Violin => 0.32,
            Self::Viola => 0.38,
            Self::Cello => 0.69,
        }
    }

    pub fn string_for_note(self, note: u8) -> Option<usize> {
        let open = self.open_notes();
        if note < open[0] || note > open[STRINGS - 1] + MAX_STOP_SEMITONES {
            return None;
        }
        open.iter().rposition(|&o| o <= note)
    }

    /// The string a note goes to when the player asks for string `preferred` (0 = the
    /// lowest): that string if it can play the note (at or above its open pitch, at most
    /// [`MAX_STOP_SEMITONES`] above), else the usual choice of [`Self::string_for_note`].
    pub fn string_for_note_on(self, note: u8, preferred: Option<usize>) -> Option<usize> {
        if let Some(p) = preferred.filter(|&p| p < STRINGS) {
            let open = self.open_notes()[p];
            if note >= open && note <= open + MAX_STOP_SEMITONES {
                return Some(p);
            }
        }
        self.string_for_note(note)
    }

    /// Playable notes, inclusive.
    pub fn note_range(self) -> (u8, u8) {
        let open = self.open_notes();
        (open[0], open[STRINGS - 1] + MAX_STOP_SEMITONES)
    }
}

/// The factor [`Instrument::ring_out_s`] puts on each string's Q1 (see there).
const RING_OUT_Q_MARGIN: f64 = 1.05;

/// Seconds for a string's energy to fall from `energy_j` to [`SLEEP_ENERGY_J`] at its
/// fundamental's decay rate: amplitude falls as `exp(-pi f0 t / Q1)`, energy twice as fast,
/// so `t = Q1 ln(E / E_sleep) / (2 pi f0)` (0 below the threshold or for absurd inputs).
pub fn ring_out_s(energy_j: f64, f0_hz: f64, q1: f64) -> f64 {
    let t = q1 * (energy_j / SLEEP_ENERGY_J).ln() / (2.0 * std::f64::consts::PI * f0_hz);
    if t.is_finite() && t > 0.0 {
        t
    } else {
        0.0
    }
}

pub fn midi_to_hz(note: f64) -> f64 {
    440.0 * 2f64.powf((note - 69.0) / 12.0)
}

/// The player's bow, shared by every bowed string.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowControl {
    /// Signed: the sign is the bow direction.
    pub velocity_m_per_s: f64,
    pub force_n: f64,
    /// Distance from the bridge over the vibrating length.
    pub position_beta: f64,
}

impl Default for BowControl {
    fn default() -> Self {
        Self {
            velocity_m_per_s: 0.1,
            force_n: 1.0,
            position_beta: 0.1,
        }
    }
}

/// One sample of output with the probed string's contact signals.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Frame {
    pub audio: f64,
    /// String velocity at the bow point of the last string that got a note, m/s.
    pub bow_point_velocity_m_per_s: f64,
    /// Friction force on that string, N.
    pub friction_force_n: f64,
}

/// One note's own expression on top of the shared controls (MPE's per-channel bend,
/// pressure and timbre; CLAP's note expressions): its finger's bend, how hard the bow
/// presses on its string, and where on its string the bow plays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoteExpression {
    /// Added to the shared pitch bend, semitones (the string's reach still limits it).
    pub bend_semitones: f64,
    /// Multiplies the bow force on this string (0..=[`MAX_NOTE_FORCE_SCALE`]).
    pub force_scale: f64,
    /// Multiplies the bow position beta on this string (the result within
    /// [`MIN_NOTE_BETA`]..=[`MAX_NOTE_BETA`]).
    pub position_scale: f64,
}

impl NoteExpression {
    /// No expression of its own: the shared bow and bend.
    pub const NEUTRAL: Self = Self {
        bend_semitones: 0.0,
        force_scale: 1.0,
        position_scale: 1.0,
    };

    /// Takes `new` (sanitized) in place of this one; whether the bend changed (the
    /// string must be retuned).
    pub fn replace(&mut self, new: NoteExpression) -> bool {
        let new = new.sanitized();
        let bent = new.bend_semitones != self.bend_semitones;
        *self = new;
        bent
    }

    /// Finite and within the ranges above (a non-finite part stays neutral).
    pub fn sanitized(self) -> Self {
        let or = |x: f64, neutral: f64| if x.is_finite() { x } else { neutral };
        Self {
            bend_semitones: or(self.bend_semitones, 0.0)
                .clamp(-MAX_NOTE_BEND_SEMITONES, MAX_NOTE_BEND_SEMITONES),
            force_scale: or(self.force_scale, 1.0).clamp(0.0, MAX_NOTE_FORCE_SCALE),
            position_scale: or(self.position_scale, 1.0).clamp(0.0, MAX_NOTE_BETA / MIN_NOTE_BETA),
        }
    }
}

/// The widest per-note bend, semitones: MPE's default member-channel range.
pub const MAX_NOTE_BEND_SEMITONES: f64 = 48.0;
/// The impedance of the string the force parameter is the force on when the strings are
/// weighted, kg/s: about the violin's A string (0.203), so the default 1 N is 1 N there.
/// Chosen by measurement (docs/playing-space.md, "Weighted strings"): from 0.5 down to
/// 0.15 kg/s, the lower the reference (the more force on every string), the more notes
/// settle into Helmholtz motion at the defaults; 0.2 doubles them against no weighting
/// while keeping the violin's strings near the forces players use (0.9-1.8 N).
pub const WEIGHT_REFERENCE_Z0: f64 = 0.2;

/// The most force String Weight bows a string with, N: the Bow Force parameter's top.
/// Without the cap the parameter's 10 N would bow the cello's C string with 95 N (five
/// times its `F_max` at 0.1 m/s), raucous and up to 14 dB over full scale (measured,
/// every point law, 44.1 kHz); at 10 N it peaks at 0.2-0.7 of full scale. The defaults
/// stay under it on every string (the cello's C string: 9.55 N).
pub const MAX_WEIGHTED_FORCE_N: f64 = 10.0;

/// The most a note's pressure may multiply its string's bow force.
pub const MAX_NOTE_FORCE_SCALE: f64 = 4.0;
/// A note's own bow position stays within the Bow Position parameter's range.
pub const MIN_NOTE_BETA: f64 = 0.02;
pub const MAX_NOTE_BETA: f64 = 0.5;

/// One point-bow string with its contact.
#[derive(Debug, Clone)]
struct StringVoice {
    string: WaveguideString,
    contact: AnyFriction,
    awake: bool,
}

/// The point-bow instrument's strings and body at the internal rate: four independent
/// waveguide strings, each with its own friction contact, whose bridge forces drive the
/// body's modes ([`super::body`]); the bridge is rigid for the strings.
#[derive(Debug, Clone)]
pub struct WaveguideBank {
    kind: InstrumentKind,
    /// The rate the strings and body run at ([`INTERNAL_RATE_HZ`], or the host's for
    /// [`Instrument::native`]).
    sample_rate_hz: f64,
    voices: [StringVoice; STRINGS],
    body: BodyModes,
    /// Each instrument's body in place of the generic one ([`Instrument::set_body`]):
    /// modes and their count, per [`InstrumentKind::ALL`] index.
    custom_bodies: [Option<([BodyMode; MAX_BODY_MODES], usize)>; 3],
    output_scale: f64,
    /// The probed string's last internal sample: velocity at the bow, friction force.
    probe: (f64, f64),
    /// Each string runs at its `oversample` times `sample_rate_hz`
    /// ([`InstrumentKind::point_oversampling`]; 1 for [`Instrument::native`]).
    oversample: [usize; STRINGS],
    /// Whether the strings may run faster than the bank ([`Instrument::native`]: no).
    oversampling: bool,
    /// Brings the bridge force of 2x strings down to the bank's rate.
    decimator: HalfbandDecimator,
    /// Whether quiet lifted strings sleep (the default; off only to measure the saving).
    skipping: bool,
    /// No string awake and the body rung out: a sample costs nothing.
    body_asleep: bool,
}

/// The four waveguide strings of a violin, viola or cello with a shared bow, note
/// handling and a generic body (see the module doc): [`FourStrings`] over
/// [`WaveguideBank`].
pub type Instrument = FourStrings<WaveguideBank>;

impl WaveguideBank {
    /// The rate string `index` runs at: the bank's times its oversampling.
    pub fn string_rate_hz(&self, index: usize) -> f64 {
        self.sample_rate_hz * self.oversample[index.min(STRINGS - 1)] as f64
    }

    /// The body `kind` plays: its custom one if set, else the generic one.
    fn body_of(&self, kind: InstrumentKind) -> BodyModes {
        let k = InstrumentKind::ALL.iter().position(|&x| x == kind);
        match k.and_then(|k| self.custom_bodies[k].as_ref()) {
            Some((modes, n)) => BodyModes::new(&modes[..*n], 1.0, self.sample_rate_hz),
            None => BodyModes::new(&kind.body_modes(), 1.0, self.sample_rate_hz),
        }
    }
}

impl StringBank for WaveguideBank {
    type Settings = ();
    const SAMPLE_IS_FLUSHED: bool = true;

    fn internal_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    fn stop(&mut self, i: usize, hz: f64) -> bool {
        let string = &mut self.voices[i].string;
        string.stop_at(hz);
        string.is_playable()
    }

    fn bend(&mut self, i: usize, hz: f64) -> bool {
        let string = &mut self.voices[i].string;
        string.bend_to(hz);
        string.is_playable()
    }

    fn release_finger(&mut self, i: usize, hz: f64) -> bool {
        let string = &mut self.voices[i].string;
        string.release_to(hz);
        string.is_playable()
    }

    fn set_finger_reflection(&mut self, i: usize, reflection: f64) {
        self.voices[i].string.set_finger_reflection(reflection);
    }

    fn wake(&mut self, i: usize) {
        let voice = &mut self.voices[i];
        voice.awake = voice.string.is_playable();
    }

    fn string_awake(&self, i: usize) -> bool {
        self.voices[i].awake
    }

    #[inline(always)]
    fn is_awake(&self) -> bool {
        !(self.body_asleep && self.voices.iter().all(|v| !v.awake))
    }

    fn set_skipping(&mut self, skipping: bool) {
        self.skipping = skipping;
    }

    /// One internal sample. Out of line, with the strings and friction inlined into it,
    /// so the caller's loop stays small. Callgrind, `colophony render` of cello D3 with
    /// the hyperbolic law (192 000 samples, whole process): 621 instructions a sample,
    /// against 600 for the point-bow instrument before it became a [`FourStrings`] (the
    /// fade, the probe and the closure that hands each string its bow), and 632 with
    /// this inlined into an out-of-line tick.
    #[inline(never)]
    fn sample(&mut self, probed: usize, mut bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        // `tick` checked that something is awake; sleep changes only between blocks.
        let skipping = self.skipping;
        self.body_asleep = false;
        let mut bridge = 0.0;
        // The bridge force of the strings at twice the bank's rate, a pair a bank sample.
        let mut fine = [0.0; 2];
        let mut any_fine = false;
        for (i, voice) in self.voices.iter_mut().enumerate() {
            if !voice.awake && skipping {
                continue;
            }
            let bow = bow_of(i);
            voice.string.set_bow_position(bow.position_beta);
            let input = BowInput {
                velocity_m_per_s: bow.velocity_m_per_s,
                normal_force_n: bow.force,
            };
            if self.oversample[i] == 1 {
                let out = voice.string.tick(&mut voice.contact, input);
                bridge += out.bridge_force_n;
                if i == probed {
                    self.probe = (out.bow_point_velocity_m_per_s, out.friction_force_n);
                }
            } else {
                // The bow is held over the string's two samples; the probe is the later's.
                any_fine = true;
                for force in &mut fine {
                    let out = voice.string.tick(&mut voice.contact, input);
                    *force += out.bridge_force_n;
                    if i == probed {
                        self.probe = (out.bow_point_velocity_m_per_s, out.friction_force_n);
                    }
                }
            }
        }
        if any_fine {
            bridge += self.decimator.process(fine[0], fine[1]);
        }
        super::filters::flush_tiny(self.body.tick(bridge) * self.output_scale)
    }

    fn probe(&self) -> (f64, f64) {
        self.probe
    }

    fn sleep(&mut self, lifted: &[bool; STRINGS]) -> bool {
        // The body sleeps too once no string is awake and its modes have rung out
        // (state below 1e-12 N: output below -200 dB of a bowed note).
        self.body_asleep = self.voices.iter().all(|v| !v.awake) && self.body.is_quiet(BODY_QUIET_N);
        if self.body_asleep {
            self.body.reset();
            self.decimator.reset();
        }
        for (voice, &lifted) in self.voices.iter_mut().zip(lifted) {
            if voice.awake && lifted && voice.string.energy_j() < SLEEP_ENERGY_J {
                voice.string.reset();
                voice.awake = false;
            }
        }
        self.body_asleep
    }

    /// Each awake string's energy is taken to fall at its fundamental's rate
    /// ([`ring_out_s`]), the slowest of its partials; the body then rings out from its
    /// present state at its modes' own rates (an overestimate: it will have decayed while
    /// the strings did).
    fn ring_out_s(&self, lifted: &[bool; STRINGS]) -> Option<f64> {
        let body_s = if self.body_asleep {
            0.0
        } else {
            self.body.samples_below(BODY_QUIET_N) / self.sample_rate_hz
        };
        let mut longest = 0.0f64;
        for (voice, &lifted) in self.voices.iter().zip(lifted) {
            if !voice.awake {
                continue;
            }
            if !lifted {
                return None;
            }
            let s = &voice.string;
            // Measured after the bow lifts (cello D3, 2.5 N, the energy's decay over
            // successive seconds, in periods of the fundamental): Q 500 over 1-6 s, then
            // 516, 551, 601, 633 and 641 by 24-29 s, with or without torsion and hair. The
            // slow part is the loop's DC pair (a right-going and a left-going wave of
            // opposite constant value: no string velocity, a constant force), which the
            // bow's mean friction force charges and which decays at the one-pole loss's DC
            // gain (above its gain at the fundamental): Q about 640 per period here. The
            // estimate takes Q1 5 % high, enough for the default note's tail (the tail
            // test); a loud note's tail can still outlast it. A DC blocker in the loop is
            // the fix (docs/playing-space.md, "Weighted strings").
            let q = RING_OUT_Q_MARGIN * s.spec().q1;
            longest = longest.max(ring_out_s(s.energy_j(), s.fundamental_hz(), q));
        }
        Some(longest + body_s)
    }

    fn energy_j(&self) -> f64 {
        self.voices.iter().map(|v| v.string.energy_j()).sum()
    }

    fn reset(&mut self) {
        for voice in &mut self.voices {
            voice.string.reset();
            voice.contact.reset();
            voice.awake = false;
        }
        self.body.reset();
        self.decimator.reset();
        self.probe = (0.0, 0.0);
    }

    fn settings(&self) {}

    fn configure(&mut self, _settings: ()) -> Result<(), String> {
        Ok(())
    }
}

impl Instrument {
    /// The instrument the plugin plays at host rate `host_rate_hz`: strings and body at
    /// [`INTERNAL_RATE_HZ`], resampled to the host rate (no resampler at 48 kHz).
    /// Allocates everything; instrument changes later do not allocate.
    pub fn new(kind: InstrumentKind, host_rate_hz: f64) -> Self {
        Self::with_internal_rate(kind, host_rate_hz, INTERNAL_RATE_HZ, true)
    }

    /// Strings and body at the host rate itself, no resampling: paper A's model as the
    /// papers discretise it, for the convergence studies in the rate.
    pub fn native(kind: InstrumentKind, sample_rate_hz: f64) -> Self {
        Self::with_internal_rate(kind, sample_rate_hz, sample_rate_hz, false)
    }

    /// Strings and body at `internal_rate_hz`, resampled to `host_rate_hz`; with
    /// `oversampling`, the strings of each instrument at its
    /// [`InstrumentKind::point_oversampling`] times that. A rate that is not finite and
    /// positive is taken as 48 kHz.
    fn with_internal_rate(
        kind: InstrumentKind,
        host_rate_hz: f64,
        internal_rate_hz: f64,
        oversampling: bool,
    ) -> Self {
        let usable = |r: f64| {
            if r.is_finite() && r > 0.0 {
                r
            } else {
                INTERNAL_RATE_HZ
            }
        };
        let (host_rate_hz, sample_rate_hz) = (usable(host_rate_hz), usable(internal_rate_hz));
        let resampler = (host_rate_hz != sample_rate_hz).then(|| {
            Box::new(
                Resampler::fixed(sample_rate_hz, host_rate_hz)
                    .expect("finite positive rates are always resampled"),
            )
        });
        // Lowest fundamental any instrument can reach: cello C bent down at the lowest
        // reference pitch.
        let lowest_hz = midi_to_hz(36.0 + LOWEST_TUNING_SEMITONES) * 0.99;
        let specs = kind.strings();
        let oversample = if oversampling {
            kind.point_oversampling()
        } else {
            [1; STRINGS]
        };
        let max_string_rate_hz = sample_rate_hz * MAX_POINT_OVERSAMPLING as f64;
        let voices = std::array::from_fn(|i| {
            let string_rate_hz = sample_rate_hz * oversample[i] as f64;
            StringVoice {
                string: WaveguideString::with_capacity(
                    specs[i],
                    string_rate_hz,
                    lowest_hz,
                    if oversampling {
                        max_string_rate_hz
                    } else {
                        string_rate_hz
                    },
                ),
                contact: AnyFriction::new(
                    FrictionModel::Hyperbolic,
                    BristleParams::plugin_string(),
                    string_rate_hz,
                )
                .expect("the built-in bristle parameters are valid"),
                awake: false,
            }
        });
        let bank = WaveguideBank {
            kind,
            sample_rate_hz,
            voices,
            body: BodyModes::new(&kind.body_modes(), 1.0, sample_rate_hz),
            custom_bodies: [None; 3],
            output_scale: kind.output_scale_per_n(),
            probe: (0.0, 0.0),
            oversample,
            oversampling,
            decimator: HalfbandDecimator::new(),
            skipping: true,
            body_asleep: true,
        };
        Self::from_bank(
            bank,
            kind,
            host_rate_hz,
            resampler,
            intonation::model_index(FrictionModel::Hyperbolic.name()),
        )
    }

    /// Switches instrument: every string is replaced and silenced. Real-time safe.
    pub fn set_kind(&mut self, kind: InstrumentKind) {
        if kind == self.kind {
            return;
        }
        self.set_kind_notes(kind);
        let bank = &mut self.bank;
        bank.kind = kind;
        let oversample = if bank.oversampling {
            kind.point_oversampling()
        } else {
            [1; STRINGS]
        };
        bank.oversample = oversample;
        bank.decimator.reset();
        for ((voice, spec), times) in bank.voices.iter_mut().zip(kind.strings()).zip(oversample) {
            let string_rate_hz = bank.sample_rate_hz * times as f64;
            voice.string.set_spec(spec);
            voice.string.set_sample_rate(string_rate_hz);
            voice.contact.set_sample_rate(string_rate_hz);
            voice.awake = false;
        }
        bank.body = bank.body_of(kind);
        bank.output_scale = kind.output_scale_per_n();
    }

    /// Plays `kind`'s body as `modes` (at most [`MAX_BODY_MODES`]; a fitted bridge's
    /// passive reduction, [`super::body::body_from_bridge`]) instead of the generic one;
    /// `None` goes back to it. Takes effect now if `kind` is playing, else when it is
    /// chosen. Real-time safe.
    pub fn set_body(&mut self, kind: InstrumentKind, modes: Option<&[BodyMode]>) {
        let Some(k) = InstrumentKind::ALL.iter().position(|&x| x == kind) else {
            return;
        };
        let bank = &mut self.bank;
        bank.custom_bodies[k] = modes.map(|m| {
            let mut kept = [BodyMode {
                freq_hz: 0.0,
                q: 1.0,
                gain: 0.0,
            }; MAX_BODY_MODES];
            let n = m.len().min(MAX_BODY_MODES);
            kept[..n].copy_from_slice(&m[..n]);
            (kept, n)
        });
        if kind == bank.kind {
            bank.body = bank.body_of(kind);
            bank.body_asleep = false;
        }
    }

    /// The string a note was sent to, with its current tuning (for tests and tools).
    pub fn string(&self, index: usize) -> &WaveguideString {
        &self.bank.voices[index].string
    }

    /// Strings computed on the next sample.
    pub fn awake_strings(&self) -> usize {
        self.bank.voices.iter().filter(|v| v.awake).count()
    }

    /// Switches every string's friction law, handing over force and stick state (no click).
    pub fn set_friction_model(&mut self, model: FrictionModel) {
        for voice in &mut self.bank.voices {
            voice.contact.set_model(model);
        }
        if self
            .hands
            .fingering
            .set_intonation_row(intonation::model_index(model.name()))
        {
            self.retune();
        }
    }

    /// Turns the strings' torsion at the bow on (the default) or off
    /// ([`WaveguideString::set_torsion`]).
    pub fn set_torsion(&mut self, enabled: bool) {
        for voice in &mut self.bank.voices {
            voice.string.set_torsion(enabled);
        }
    }

    /// Lets the bow hair yield (the default) or ties the contact rigidly to the bow
    /// ([`WaveguideString::set_bow_hair`]).
    pub fn set_bow_hair(&mut self, enabled: bool) {
        for voice in &mut self.bank.voices {
            voice.string.set_bow_hair(enabled);
        }
    }

    /// Replaces the bristle parameters of every string (validated; real-time safe).
    pub fn set_bristle_params(&mut self, params: BristleParams) -> Result<(), String> {
        let bank = &mut self.bank;
        for (i, voice) in bank.voices.iter_mut().enumerate() {
            let rate = bank.sample_rate_hz * bank.oversample[i] as f64;
            let model = voice.contact.model();
            voice.contact = AnyFriction::new(model, params, rate)?;
        }
        Ok(())
    }

    /// Sets every string's Newton tolerance for the bristle laws (see
    /// [`crate::dsp::friction::bristle::BristleFriction::set_newton_tolerance`]). Call it
    /// after [`Self::set_bristle_params`], which rebuilds the contacts at the default.
    pub fn set_newton_tolerance(&mut self, tolerance_m_per_s: f64) {
        for voice in &mut self.bank.voices {
            voice
                .contact
                .bristle_mut()
                .set_newton_tolerance(tolerance_m_per_s);
        }
    }

    /// Sets every string's bristle integrator (see
    /// [`crate::dsp::friction::bristle::BristleIntegrator`]); after
    /// [`Self::set_bristle_params`], which rebuilds the contacts with the trapezoid.
    pub fn set_bristle_integrator(
        &mut self,
        integrator: crate::dsp::friction::bristle::BristleIntegrator,
    ) {
        for voice in &mut self.bank.voices {
            voice.contact.bristle_mut().set_integrator(integrator);
        }
    }

    /// Most dispersion allpass sections each string's fit may use (refits the strings;
    /// see [`super::waveguide::WaveguideString::set_dispersion_cap`]). For the
    /// work-precision bench, not the audio thread.
    pub fn set_dispersion_cap(&mut self, stages: usize) {
        for voice in &mut self.bank.voices {
            voice.string.set_dispersion_cap(stages);
        }
    }

    pub fn friction_model(&self) -> FrictionModel {
        self.bank.voices[0].contact.model()
    }

    /// Newton statistics of the probed string's bristle contact.
    pub fn probed_solver_stats(&self) -> SolverStats {
        self.bank.voices[self.hands.probed].contact.bristle().stats
    }

    /// Newton statistics of string `index`'s bristle contact (the stress suite checks
    /// every string's).
    pub fn solver_stats(&self, index: usize) -> SolverStats {
        self.bank.voices[index].contact.bristle().stats
    }

    /// Whether the contact of the probed string is sticking (for analysis).
    pub fn probed_is_sticking(&self) -> bool {
        self.bank.voices[self.hands.probed].contact.is_sticking()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_go_to_the_highest_open_string_at_or_below_them() {
        let cello = InstrumentKind::Cello;
        assert_eq!(cello.string_for_note(36), Some(0));
        assert_eq!(cello.string_for_note(49), Some(1));
        assert_eq!(cello.string_for_note(50), Some(2));
        assert_eq!(cello.string_for_note(80), Some(3));
        assert_eq!(cello.string_for_note(35), None);
        assert_eq!(cello.string_for_note(57 + MAX_STOP_SEMITONES + 1), None);
    }

    #[test]
    fn a_named_string_takes_the_notes_it_reaches_and_leaves_the_rest_to_the_usual_string() {
        let cello = InstrumentKind::Cello;
        // A3 sul C (C2 + 21 semitones) and sul G.
        assert_eq!(cello.string_for_note_on(57, Some(0)), Some(0));
        assert_eq!(cello.string_for_note_on(57, Some(1)), Some(1));
        // G2 cannot be played on the D string: it goes to the G string as usual.
        assert_eq!(cello.string_for_note_on(43, Some(2)), Some(1));
        // Beyond the stop range of the C string: the usual string.
        assert_eq!(
            cello.string_for_note_on(36 + MAX_STOP_SEMITONES + 1, Some(0)),
            Some(3)
        );
        // No preference, or a string that does not exist: the usual choice.
        assert_eq!(
            cello.string_for_note_on(57, None),
            cello.string_for_note(57)
        );
        assert_eq!(
            cello.string_for_note_on(57, Some(7)),
            cello.string_for_note(57)
        );
        // Unplayable notes stay unplayable.
        assert_eq!(cello.string_for_note_on(35, Some(0)), None);
    }

    /// Issue 16, item 1: the reference pitch tunes every note, the lowest open string bent
    /// down at 415 Hz and the highest stopped note bent up at 466 Hz included. With the
    /// intonation table the free string sits the table's correction (at the bent note's
    /// place on its string) below; without it, its first partial is tuned exactly (as at
    /// 440 Hz), so its pitch is checked to 0.05 cents: the peak estimator's resolution on
    /// one second of a decaying partial.
    #[test]
    fn the_reference_pitch_tunes_every_note_from_a4() {
        use crate::analysis::{cents, peak_frequency_hz};
        let fs = 48_000.0;
        for (a4, note, bend) in [(415.0, 36u8, -2.0), (466.0, 57 + 31, 2.0), (415.0, 57, 0.0)] {
            let mut cello = Instrument::new(InstrumentKind::Cello, fs);
            cello.set_reference_pitch(a4);
            cello.set_pitch_bend(bend);
            let index = cello.note_on(note).unwrap();
            let want = a4 * 2f64.powf((note as f64 + bend - 69.0) / 12.0);
            let above_open = note as f64 + bend - InstrumentKind::Cello.open_notes()[index] as f64;
            let c = intonation::shipped().correction_cents(
                intonation::model_index("hyperbolic"),
                InstrumentKind::Cello,
                index,
                above_open,
            );
            let tuned = want * 2f64.powf(-c / 1200.0);
            let f = cello.string(index).fundamental_hz();
            assert!(
                (f - tuned).abs() < 1e-9 * tuned,
                "{f} Hz, table says {tuned} Hz"
            );
            cello.set_intonation(None);
            let bow = BowControl::default();
            for _ in 0..(0.2 * fs) as usize {
                cello.tick(bow);
            }
            // The finger stays down: the free decay of the stopped string.
            cello.set_fingers_held(true);
            cello.note_off(note);
            for _ in 0..(0.1 * fs) as usize {
                cello.tick(bow);
            }
            let x: Vec<f64> = (0..fs as usize).map(|_| cello.tick(bow).audio).collect();
            assert!((cello.string(index).fundamental_hz() - want).abs() < 1e-9 * want);
            let got = peak_frequency_hz(&x, fs, want, 30.0);
            assert!(
                cents(got, want).abs() < 0.05,
                "A4 = {a4}, note {note}: {} cents",
                cents(got, want)
            );
        }
    }

    #[test]
    fn the_instrument_plays_a_note_on_the_string_the_player_names() {
        let mut cello = Instrument::new(InstrumentKind::Cello, 48_000.0);
        cello.set_preferred_string(Some(1));
        assert_eq!(cello.note_on(57), Some(1));
        cello.set_preferred_string(None);
        assert_eq!(cello.note_on(57), Some(3));
    }

    /// Weighted, each string is bowed with the force times its weight: a weighted note at
    /// 1 N renders the same bits as the bare string at the weight in newtons, on every
    /// string, and switching the instrument keeps the weighting (the violin's weights).
    #[test]
    fn a_weighted_string_is_bowed_with_the_force_times_its_impedance_ratio() {
        let render = |kind: InstrumentKind, note: u8, weighted: bool, force_n: f64| {
            let mut i = Instrument::new(InstrumentKind::Cello, 48_000.0);
            i.set_string_weighting(weighted);
            i.set_kind(kind);
            i.note_on(note);
            let bow = BowControl {
                force_n,
                ..BowControl::default()
            };
            (0..4800)
                .map(|_| i.tick(bow).audio.to_bits())
                .collect::<Vec<_>>()
        };
        for kind in [InstrumentKind::Cello, InstrumentKind::Violin] {
            for (s, note) in kind.open_notes().into_iter().enumerate() {
                let w = kind.string_weight(s);
                // Z0 / 0.2 kg/s: between 0.87 (violin E) and 9.6 (cello C).
                assert!((0.8..10.0).contains(&w), "{kind:?} string {s}: {w}");
                assert_eq!(
                    render(kind, note, true, 1.0),
                    render(kind, note, false, w),
                    "{kind:?} string {s}"
                );
                assert_ne!(
                    render(kind, note, true, 1.0),
                    render(kind, note, false, 1.0)
                );
            }
        }
        // The top of the force parameter on the cello's C string (weight 9.55): bowed with
        // the cap, 10 N, not 95.5 N.
        let c = InstrumentKind::Cello;
        assert_eq!(
            render(c, 36, true, 10.0),
            render(c, 36, false, MAX_WEIGHTED_FORCE_N)
        );
    }
}
