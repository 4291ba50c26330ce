//! Plugin parameters. The ids are a contract with hosts, tools and tests: never rename them.
//!
//! | id | name | unit | range | default |
//! |---|---|---|---|---|
//! | `bow_velocity` | Bow Velocity | m/s | -1.5 .. 1.5 (sign = direction) | 0.1 |
//! | `bow_force` | Bow Force | N | 0 .. 10 (skewed) | 1.0 |
//! | `bow_position` | Bow Position | beta | 0.02 .. 0.5 | 0.1 |
//! | `instrument` | Instrument | - | violin, viola, cello | cello |
//! | `gain` | Output Gain | dB | -40 .. 12 | 0 |
//! | `friction_model` | Friction Model | - | hyperbolic, static (Stribeck), LuGre, elasto-plastic, thermal (paper B) | hyperbolic |
//! | `resonator` | Resonator | - | strings, paper A modal, door hinge, chalk, wine glass, brake squeal | strings |
//! | `bow_nodes` | Bow Nodes | nodes on the lowest string (thermal model, quality custom) | 1 .. 60 | 10 |
//! | `bow_width` | Bow Width | mm of hair in contact (thermal model) | 5 .. 20 | 10 |
//! | `string` | String | - | auto, I (highest) .. IV (lowest) | auto |
//! | `quality` | Quality | - | draft, good, reference, auto, custom | good |
//! | `reference_pitch` | Reference Pitch | Hz (A4) | 415 .. 466 | 440 |
//! | `dynamics_guard` | Dynamics Guard | - | off, on (the dynamics keep the bow in Schelleng's window) | on |
//! | `string_weight` | String Weight | - | off, on (each string bowed with the force times its impedance over 0.2 kg/s; paper B's thermal model over 1 kg/s) | on |

use crate::dsp::friction::FrictionModel;
use crate::dsp::rubbed::RubbedPreset;
use crate::dsp::vocabulary::InstrumentKind;
use crate::quality::Quality;
use nice_plug::prelude::*;

/// Smoothing time for the bow controls: short enough for sample-accurate gestures to
/// land within a couple of milliseconds, long enough to avoid zipper noise.
pub const BOW_SMOOTHING_MS: f32 = 2.0;

#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstrumentChoice {
    #[id = "violin"]
    Violin,
    #[id = "viola"]
    Viola,
    #[id = "cello"]
    Cello,
    #[id = "double-bass"]
    #[name = "Double bass"]
    DoubleBass,
}

/// The parameter's choices are the instruments in [`InstrumentKind::ALL`]'s order, with
/// their names as ids (a test checks both).
impl From<InstrumentChoice> for InstrumentKind {
    fn from(choice: InstrumentChoice) -> Self {
        InstrumentKind::ALL[choice.to_index().min(InstrumentKind::COUNT - 1)]
    }
}

/// The friction law at the bow: paper A's laws on the waveguide strings, or paper B's
/// finite-width thermal bow on its own four-string instrument.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionChoice {
    #[id = "hyperbolic"]
    Hyperbolic,
    #[id = "static"]
    #[name = "Static (Stribeck)"]
    Static,
    #[id = "lugre"]
    #[name = "LuGre"]
    LuGre,
    #[id = "elasto-plastic"]
    #[name = "Elasto-plastic"]
    ElastoPlastic,
    #[id = "thermal"]
    #[name = "Thermal (paper B)"]
    Thermal,
}

impl FrictionChoice {
    /// Paper A's law on the waveguide strings, or `None` for paper B's thermal bow.
    pub fn point_law(self) -> Option<FrictionModel> {
        match self {
            FrictionChoice::Hyperbolic => Some(FrictionModel::Hyperbolic),
            FrictionChoice::Static => Some(FrictionModel::Stribeck),
            FrictionChoice::LuGre => Some(FrictionModel::LuGre),
            FrictionChoice::ElastoPlastic => Some(FrictionModel::ElastoPlastic),
            FrictionChoice::Thermal => None,
        }
    }
}

/// What the bow rubs: the instrument's strings, or a modal object (paper A §5.2 presets).
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResonatorChoice {
    #[id = "strings"]
    Strings,
    #[id = "paper-modal"]
    #[name = "Paper A modal"]
    PaperModal,
    #[id = "door-hinge"]
    #[name = "Door hinge"]
    DoorHinge,
    #[id = "chalk"]
    Chalk,
    #[id = "wine-glass"]
    #[name = "Wine glass"]
    WineGlass,
    #[id = "brake-squeal"]
    #[name = "Brake squeal"]
    BrakeSqueal,
}

impl ResonatorChoice {
    /// The rubbed preset, or `None` for the strings.
    pub fn preset(self) -> Option<RubbedPreset> {
        match self {
            ResonatorChoice::Strings => None,
            ResonatorChoice::PaperModal => Some(RubbedPreset::PaperModal),
            ResonatorChoice::DoorHinge => Some(RubbedPreset::DoorHinge),
            ResonatorChoice::Chalk => Some(RubbedPreset::Chalk),
            ResonatorChoice::WineGlass => Some(RubbedPreset::WineGlass),
            ResonatorChoice::BrakeSqueal => Some(RubbedPreset::BrakeSqueal),
        }
    }
}

/// How notes are played ([`crate::performer::articulation`]).
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArticulationChoice {
    #[id = "arco"]
    #[name = "Arco"]
    Arco,
    #[id = "pizzicato"]
    #[name = "Pizzicato"]
    Pizzicato,
    #[id = "tremolo"]
    #[name = "Tremolo"]
    Tremolo,
    #[id = "spiccato"]
    #[name = "Spiccato"]
    Spiccato,
    #[id = "col-legno"]
    #[name = "Col legno"]
    ColLegno,
    #[id = "sautille"]
    #[name = "Sautillé"]
    Sautille,
    #[id = "harmonics"]
    #[name = "Harmonics"]
    Harmonics,
    #[id = "col-legno-tratto"]
    #[name = "Col legno tratto"]
    ColLegnoTratto,
}

/// What sets the tremolo's strokes ([`crate::performer::articulation::TremoloSync`]).
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum TremoloSyncChoice {
    #[id = "free"]
    #[name = "Free (Tremolo Rate)"]
    Free,
    #[id = "sixteenths"]
    #[name = "1/16 of the host tempo"]
    Sixteenths,
    #[id = "thirty-seconds"]
    #[name = "1/32 of the host tempo"]
    ThirtySeconds,
}

impl From<TremoloSyncChoice> for crate::performer::articulation::TremoloSync {
    fn from(choice: TremoloSyncChoice) -> Self {
        match choice {
            TremoloSyncChoice::Free => Self::Free,
            TremoloSyncChoice::Sixteenths => Self::Sixteenths,
            TremoloSyncChoice::ThirtySeconds => Self::ThirtySeconds,
        }
    }
}

impl From<ArticulationChoice> for crate::performer::Articulation {
    fn from(choice: ArticulationChoice) -> Self {
        match choice {
            ArticulationChoice::Arco => Self::Arco,
            ArticulationChoice::Pizzicato => Self::Pizzicato,
            ArticulationChoice::Tremolo => Self::Tremolo,
            ArticulationChoice::Spiccato => Self::Spiccato,
            ArticulationChoice::ColLegno => Self::ColLegno,
            ArticulationChoice::Sautille => Self::Sautille,
            ArticulationChoice::Harmonics => Self::Harmonics,
            ArticulationChoice::ColLegnoTratto => Self::ColLegnoTratto,
        }
    }
}

/// The direction of each new bow stroke ([`crate::performer::stroke`]): alternating, as
/// in détaché, or always one way (the bow velocity parameter's sign is down).
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrokeChoice {
    #[id = "alternate"]
    #[name = "Alternate (down, up)"]
    Alternate,
    #[id = "down"]
    #[name = "Down only"]
    Down,
    #[id = "up"]
    #[name = "Up only"]
    Up,
}

impl StrokeChoice {
    pub fn mode(self) -> crate::performer::stroke::StrokeMode {
        use crate::performer::stroke::StrokeMode;
        match self {
            StrokeChoice::Alternate => StrokeMode::Alternate,
            StrokeChoice::Down => StrokeMode::Down,
            StrokeChoice::Up => StrokeMode::Up,
        }
    }
}

/// Which string a note goes to: the usual choice (the highest string that reaches it,
/// the lowest hand position) or one the player names, as in "sul G". Strings are counted
/// from the highest: I is the violin's E and the viola's and cello's A, IV the lowest. A
/// note the named string cannot play goes where it usually would.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StringChoice {
    #[id = "auto"]
    Auto,
    #[id = "i"]
    #[name = "I (highest)"]
    I,
    #[id = "ii"]
    #[name = "II"]
    II,
    #[id = "iii"]
    #[name = "III"]
    III,
    #[id = "iv"]
    #[name = "IV (lowest)"]
    IV,
}

impl StringChoice {
    /// String index counted from the lowest (0), or `None` for the usual choice.
    pub fn index(self) -> Option<usize> {
        match self {
            StringChoice::Auto => None,
            StringChoice::I => Some(3),
            StringChoice::II => Some(2),
            StringChoice::III => Some(1),
            StringChoice::IV => Some(0),
        }
    }
}

/// Solver quality ([`crate::quality`]): the presets chosen from the work-precision
/// benchmark, or `custom` (the Bow Nodes parameter sets the thermal node count and the
/// Newton tolerance is the reference's).
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum QualityChoice {
    #[id = "draft"]
    Draft,
    #[id = "good"]
    Good,
    #[id = "reference"]
    Reference,
    #[id = "auto"]
    Auto,
    #[id = "custom"]
    #[name = "Custom (Bow Nodes)"]
    Custom,
}

impl QualityChoice {
    /// The preset, or `None` for custom.
    pub fn preset(self) -> Option<Quality> {
        match self {
            QualityChoice::Draft => Some(Quality::Draft),
            QualityChoice::Good => Some(Quality::Good),
            QualityChoice::Reference => Some(Quality::Reference),
            QualityChoice::Auto => Some(Quality::Auto),
            QualityChoice::Custom => None,
        }
    }
}

/// The version of the plugin state this build writes.
pub const STATE_VERSION: u32 = 2;
/// The persisted field that holds it.
pub const STATE_VERSION_FIELD: &str = "state-version";

/// The persisted `state-version` field: always saves [`STATE_VERSION`] (the state this
/// build writes, whatever version it loaded), and ignores what it loads (read by
/// [`crate::presets::migrate_state`] before the values are loaded).
#[derive(Debug, Default)]
pub struct StateVersion;

impl<'a> nice_plug::params::persist::PersistentField<'a, u32> for StateVersion {
    fn set(&self, _loaded: u32) {}

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&u32) -> R,
    {
        f(&STATE_VERSION)
    }
}

#[derive(Params)]
pub struct ColophonyParams {
    #[id = "bow_velocity"]
    pub bow_velocity: FloatParam,
    #[id = "bow_force"]
    pub bow_force: FloatParam,
    #[id = "bow_position"]
    pub bow_position: FloatParam,
    #[id = "instrument"]
    pub instrument: EnumParam<InstrumentChoice>,
    #[id = "gain"]
    pub gain: FloatParam,
    #[id = "friction_model"]
    pub friction_model: EnumParam<FrictionChoice>,
    #[id = "resonator"]
    pub resonator: EnumParam<ResonatorChoice>,
    #[id = "bow_nodes"]
    pub bow_nodes: IntParam,
    #[id = "bow_width"]
    pub bow_width_mm: FloatParam,
    #[id = "string"]
    pub string: EnumParam<StringChoice>,
    #[id = "quality"]
    pub quality: EnumParam<QualityChoice>,
    #[id = "reference_pitch"]
    pub reference_pitch: FloatParam,
    #[id = "bow_strokes"]
    pub bow_strokes: EnumParam<StrokeChoice>,
    #[id = "bend_range"]
    pub bend_range: FloatParam,
    #[id = "glide_time"]
    pub glide_time_ms: FloatParam,
    #[id = "vibrato_rate"]
    pub vibrato_rate: FloatParam,
    #[id = "dynamics_guard"]
    pub dynamics_guard: BoolParam,
    /// The strings weighted by their impedance ([`crate::performer::Setup`]).
    #[id = "string_weight"]
    pub string_weight: BoolParam,
    #[id = "articulation"]
    pub articulation: EnumParam<ArticulationChoice>,
    #[id = "keyswitch_octave"]
    pub keyswitch_octave: IntParam,
    #[id = "tremolo_rate"]
    pub tremolo_rate: FloatParam,
    #[id = "tremolo_sync"]
    pub tremolo_sync: EnumParam<TremoloSyncChoice>,
    #[id = "con_sordino"]
    pub con_sordino: BoolParam,
    /// The editor window's size, saved with the plugin state (not a parameter).
    #[persist = "editor-state"]
    pub editor_state: crate::editor_state::EditorState,
    /// The bridges chosen for the thermal instruments, saved with the project
    /// ([`crate::user_bridges`]; not a parameter).
    #[persist = "user-bridges"]
    pub user_bridges: crate::user_bridges::UserBridges,
    /// The state's version, for migrations ([`crate::presets::migrate_state`]).
    #[persist = "state-version"]
    pub state_version: StateVersion,
    /// Which controller moves what, saved with the project ([`crate::midi_learn`]; not a
    /// parameter). The editor's mapping page edits it.
    #[persist = "midi-map"]
    pub midi_map: crate::midi_learn::SharedMidiMap,
    /// The last controller received, for MIDI learn (not saved).
    pub last_controller: crate::midi_learn::LastController,
}

pub fn bow_velocity_range() -> FloatRange {
    FloatRange::Linear {
        min: -1.5,
        max: 1.5,
    }
}

pub fn bow_force_range() -> FloatRange {
    FloatRange::Skewed {
        min: 0.0,
        max: 10.0,
        factor: FloatRange::skew_factor(-2.0),
    }
}

pub fn bow_nodes_range() -> IntRange {
    IntRange::Linear {
        min: 1,
        max: crate::dsp::thermal_instrument::MAX_NODES as i32,
    }
}

pub fn bow_width_mm_range() -> FloatRange {
    FloatRange::Linear {
        min: (crate::dsp::thermal_instrument::MIN_WIDTH_M * 1e3) as f32,
        max: (crate::dsp::thermal_instrument::MAX_WIDTH_M * 1e3) as f32,
    }
}

pub fn reference_pitch_range() -> FloatRange {
    FloatRange::Linear {
        min: crate::dsp::vocabulary::REFERENCE_HZ_MIN as f32,
        max: crate::dsp::vocabulary::REFERENCE_HZ_MAX as f32,
    }
}

pub fn bow_position_range() -> FloatRange {
    FloatRange::Linear {
        min: 0.02,
        max: 0.5,
    }
}

impl Default for ColophonyParams {
    fn default() -> Self {
        Self {
            bow_velocity: FloatParam::new("Bow Velocity", 0.1, bow_velocity_range())
                .with_unit(" m/s")
                .with_value_to_string(formatters::v2s_f32_rounded(3))
                .with_smoother(SmoothingStyle::Linear(BOW_SMOOTHING_MS)),
            // Default inside the Schelleng window of the default note (cello D, v_b 0.1 m/s,
            // beta 0.1): F_max = 2 Z0 v_b / (beta (mu_s - mu_d)) = 5.1 N.
            bow_force: FloatParam::new("Bow Force", 1.0, bow_force_range())
                .with_unit(" N")
                .with_value_to_string(formatters::v2s_f32_rounded(3))
                .with_smoother(SmoothingStyle::Linear(BOW_SMOOTHING_MS)),
            bow_position: FloatParam::new("Bow Position", 0.1, bow_position_range())
                .with_unit(" beta")
                .with_value_to_string(formatters::v2s_f32_rounded(3))
                .with_smoother(SmoothingStyle::Linear(BOW_SMOOTHING_MS)),
            instrument: EnumParam::new("Instrument", InstrumentChoice::Cello),
            gain: FloatParam::new(
                "Output Gain",
                0.0,
                FloatRange::Linear {
                    min: -40.0,
                    max: 12.0,
                },
            )
            .with_unit(" dB")
            .with_value_to_string(formatters::v2s_f32_rounded(1))
            .with_smoother(SmoothingStyle::Linear(10.0)),
            friction_model: EnumParam::new("Friction Model", FrictionChoice::Hyperbolic),
            resonator: EnumParam::new("Resonator", ResonatorChoice::Strings),
            // Discrete: a change rebuilds the thermal grid (after a 10 ms fade), so neither
            // is smoothed.
            bow_nodes: IntParam::new("Bow Nodes", 10, bow_nodes_range()),
            bow_width_mm: FloatParam::new("Bow Width", 10.0, bow_width_mm_range())
                .with_unit(" mm")
                .with_step_size(0.5)
                .with_value_to_string(formatters::v2s_f32_rounded(1)),
            string: EnumParam::new("String", StringChoice::Auto),
            quality: EnumParam::new("Quality", QualityChoice::Good),
            // Not smoothed: a change retunes the sounding notes at the next block.
            reference_pitch: FloatParam::new(
                "Reference Pitch",
                crate::dsp::vocabulary::REFERENCE_HZ_DEFAULT as f32,
                reference_pitch_range(),
            )
            .with_unit(" Hz")
            .with_step_size(0.1)
            .with_value_to_string(formatters::v2s_f32_rounded(1)),
            bow_strokes: EnumParam::new("Bow Strokes", StrokeChoice::Alternate),
            // Not smoothed: a change re-bends the sounding notes at the next block.
            bend_range: FloatParam::new(
                "Pitch Bend Range",
                crate::dsp::vocabulary::PITCH_BEND_SEMITONES as f32,
                FloatRange::Linear {
                    min: 0.0,
                    max: crate::dsp::vocabulary::MAX_BEND_RANGE_SEMITONES as f32,
                },
            )
            .with_unit(" st")
            .with_step_size(0.01)
            .with_value_to_string(formatters::v2s_f32_rounded(2)),
            // Read at each glide's start.
            glide_time_ms: FloatParam::new(
                "Glide Time",
                (crate::performer::GLIDE_S_DEFAULT * 1e3) as f32,
                FloatRange::Skewed {
                    min: 10.0,
                    max: 2000.0,
                    factor: FloatRange::skew_factor(-1.5),
                },
            )
            .with_unit(" ms")
            .with_value_to_string(formatters::v2s_f32_rounded(0)),
            // Read at each vibrato step; the mod wheel (CC1) sets the depth.
            vibrato_rate: FloatParam::new(
                "Vibrato Rate",
                crate::performer::VIBRATO_RATE_HZ as f32,
                FloatRange::Linear {
                    min: crate::performer::VIBRATO_RATE_MIN_HZ as f32,
                    max: crate::performer::VIBRATO_RATE_MAX_HZ as f32,
                },
            )
            .with_unit(" Hz")
            .with_step_size(0.01)
            .with_value_to_string(formatters::v2s_f32_rounded(2)),
            // Read once per block.
            dynamics_guard: BoolParam::new("Dynamics Guard", true),
            // Read once per block.
            string_weight: BoolParam::new("String Weight", true),
            // Read at each note-on; a keyswitch or controller holds another until it moves.
            articulation: EnumParam::new("Articulation", ArticulationChoice::Arco),
            // Read at each note-on: C of this octave and the keys above it are keyswitches.
            keyswitch_octave: IntParam::new(
                "Keyswitch Octave",
                crate::performer::articulation::KEYSWITCH_OCTAVE_DEFAULT as i32,
                IntRange::Linear {
                    min: *crate::performer::articulation::KEYSWITCH_OCTAVES.start() as i32,
                    max: *crate::performer::articulation::KEYSWITCH_OCTAVES.end() as i32,
                },
            )
            .with_value_to_string(std::sync::Arc::new(|octave| format!("C{octave}")))
            .with_string_to_value(std::sync::Arc::new(|text| {
                text.trim().trim_start_matches(['C', 'c']).parse().ok()
            })),
            // Read at each block: a held tremolo follows it from its next stroke.
            tremolo_rate: FloatParam::new(
                "Tremolo Rate",
                crate::performer::articulation::TREMOLO_RATE_HZ as f32,
                FloatRange::Linear {
                    min: *crate::performer::articulation::TREMOLO_RATES_HZ.start() as f32,
                    max: *crate::performer::articulation::TREMOLO_RATES_HZ.end() as f32,
                },
            )
            .with_unit(" strokes/s")
            .with_step_size(0.1)
            .with_value_to_string(formatters::v2s_f32_rounded(1)),
            tremolo_sync: EnumParam::new("Tremolo Sync", TremoloSyncChoice::Free),
            // Read once per block: the bridge's modes take the mute's mass.
            con_sordino: BoolParam::new("Con Sordino", false),
            editor_state: Default::default(),
            user_bridges: Default::default(),
            state_version: StateVersion,
            midi_map: Default::default(),
            last_controller: Default::default(),
        }
    }
}

impl ColophonyParams {
    /// The parameters as the performer takes them (read once per block).
    pub fn setup(&self) -> crate::performer::Setup {
        use crate::performer::{Setup, ThermalNodes};
        use crate::quality::{self, Quality};
        let quality = self.quality.value().preset();
        Setup {
            instrument: self.instrument.value().into(),
            point_law: self.friction_model.value().point_law(),
            rubbed: self.resonator.value().preset(),
            // Custom quality solves the bristle laws to the reference's tolerance.
            newton_tolerance_m_per_s: quality
                .unwrap_or(Quality::Reference)
                .newton_tolerance_m_per_s(),
            reference_hz: self.reference_pitch.value() as f64,
            preferred_string: self.string.value().index(),
            thermal_nodes: match quality {
                None => ThermalNodes::Fixed(self.bow_nodes.value().max(1) as usize),
                Some(Quality::Auto) => ThermalNodes::Auto,
                Some(q) => {
                    ThermalNodes::Fixed(q.fixed_thermal_nodes().unwrap_or(quality::GOOD_NODES))
                }
            },
            bow_width_m: self.bow_width_mm.value() as f64 * 1e-3,
            bow_position_beta: self.bow_position.value() as f64,
            bow_strokes: self.bow_strokes.value().mode(),
            bend_range_semitones: self.bend_range.value() as f64,
            glide_s: self.glide_time_ms.value() as f64 * 1e-3,
            vibrato_rate_hz: self.vibrato_rate.value() as f64,
            dynamics_guard: self.dynamics_guard.value(),
            string_weight: self.string_weight.value(),
            articulation: self.articulation.value().into(),
            keyswitch_octave: self.keyswitch_octave.value() as i8,
            tremolo_rate_hz: self.tremolo_rate.value() as f64,
            tremolo_sync: self.tremolo_sync.value().into(),
            tempo_bpm: None,
            con_sordino: self.con_sordino.value(),
        }
    }

    /// The bow the parameters set (their values, not their smoothed ramps).
    pub fn bow(&self) -> crate::dsp::vocabulary::BowControl {
        crate::dsp::vocabulary::BowControl {
            velocity_m_per_s: self.bow_velocity.value() as f64,
            force_n: self.bow_force.value() as f64,
            position_beta: self.bow_position.value() as f64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_instrument_choices_are_the_instruments_in_order_with_their_names_as_ids() {
        let ids = InstrumentChoice::ids().expect("the choices have ids");
        assert_eq!(ids.len(), InstrumentKind::COUNT);
        for (i, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            assert_eq!(ids[i], kind.name());
            assert_eq!(InstrumentKind::from(InstrumentChoice::from_index(i)), kind);
        }
    }
}
