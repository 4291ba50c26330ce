//! What the performer is told each block ([`Setup`]) and what it tells the host
//! ([`Status`]), and the source a setup asks for ([`Source`]).

use super::*;

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
    /// How notes are played (a keyswitch or controller holds another until this changes).
    pub articulation: Articulation,
    /// The octave whose keys are keyswitches (C-1 = -1; [`super::articulation`]).
    pub keyswitch_octave: i8,
    /// Tremolo strokes a second ([`super::articulation::TREMOLO_RATES_HZ`]).
    pub tremolo_rate_hz: f64,
    /// Whether the tremolo's strokes follow the host's tempo.
    pub tremolo_sync: super::articulation::TremoloSync,
    /// The host's tempo, beats a minute, where it gives one.
    pub tempo_bpm: Option<f64>,
    /// A mute on the bridge (con sordino); a controller holds another until this changes.
    pub con_sordino: bool,
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
            articulation: Articulation::Arco,
            keyswitch_octave: super::articulation::KEYSWITCH_OCTAVE_DEFAULT,
            tremolo_rate_hz: super::articulation::TREMOLO_RATE_HZ,
            tremolo_sync: super::articulation::TremoloSync::Free,
            tempo_bpm: None,
            con_sordino: false,
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
            (None, None) => Source::Thermal(setup.instrument.index()),
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
