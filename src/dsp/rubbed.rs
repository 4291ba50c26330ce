//! Rubbed modal objects: paper A's modal scenario and the friction sound effects of its
//! §5.2 (squeaking door, chalk on a board, rubbed wine glass, brake squeal), each a
//! [`FrictionPair`] with documented modal data and friction parameters.
//!
//! The modal data are *designed*, not measured: mode frequencies from the physics of each
//! object (a hinge pin's bending modes, a slate board's plate modes, a wine glass's (n, 0)
//! bell modes, a brake disc's out-of-plane modes) with decay times typical of the material;
//! friction parameters start from the Sound Design Toolkit's rubbing preset
//! (docs/literature-values.md §1.1, §1.7) and are adjusted so each preset locks into stick-slip.
//!
//! **Why each preset sings.** Steady sliding at velocity `v` is unstable, so the object
//! self-excites even when the exciter lands gently, when the friction force falls with
//! speed faster than the mode's damping: `-F_N dmu/dv > r = 2 pi f m / Q`. With the
//! Stribeck curve the fall is steepest at `v = v_s / sqrt(2)`, so each preset rubs at a
//! velocity below `v_s`, where `-F_N dmu/dv` exceeds the first mode's `r` (door hinge
//! 12 against 0.7 kg/s, chalk 10 against 3.5, wine glass 3 against 0.007, brake 8.5 against
//! 4.8).
//!
//! ```
//! use colophony::dsp::rubbed::{RubbedPreset, RubbedScene};
//! let mut scene = RubbedScene::new(RubbedPreset::WineGlass, 48_000.0).unwrap();
//! let mut peak = 0.0f64;
//! for _ in 0..4800 {
//!     peak = peak.max(scene.tick(scene.preset_bow()).audio.abs());
//! }
//! assert!(peak.is_finite());
//! ```

use super::friction::bristle::{BristleParams, SolverStats};
use super::friction::{AnyFriction, BowInput, FrictionContact, FrictionModel};
use super::modal::{Exciter, FrictionPair, ModalObject, ModeSpec, PairOutput};
use super::vocabulary::BowControl;

/// The built-in rubbed scenes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RubbedPreset {
    /// Paper A's modal scenario: the authors' SMAC-03 script (docs/literature-values.md §1.7 row 1).
    PaperModal,
    DoorHinge,
    Chalk,
    WineGlass,
    BrakeSqueal,
}

impl RubbedPreset {
    pub const ALL: [RubbedPreset; 5] = [
        RubbedPreset::PaperModal,
        RubbedPreset::DoorHinge,
        RubbedPreset::Chalk,
        RubbedPreset::WineGlass,
        RubbedPreset::BrakeSqueal,
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            RubbedPreset::PaperModal => "paper-modal",
            RubbedPreset::DoorHinge => "door-hinge",
            RubbedPreset::Chalk => "chalk",
            RubbedPreset::WineGlass => "wine-glass",
            RubbedPreset::BrakeSqueal => "brake-squeal",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The scene's data.
    pub fn spec(self) -> RubbedSpec {
        let mode = |freq_hz: f64, q: f64, mass_kg: f64| ModeSpec {
            freq_hz,
            q,
            mass_kg,
            weight: 1.0,
        };
        match self {
            // Two string-like modes at 140 and 280 Hz, Q 500, 1 g each; the bow a free
            // 50 g mass (Q irrelevant without stiffness) pushed at the steady friction of
            // 0.5 m/s; F_N 1 N; sigma0 1e4, sigma1 10, sigma2 0.4, v_s 0.1, mu 0.4/0.2,
            // c 0.7. Exactly the values of the authors' script.
            RubbedPreset::PaperModal => RubbedSpec {
                resonator: vec![mode(140.0, 500.0, 1e-3), mode(280.0, 500.0, 1e-3)],
                exciter: Some(vec![mode(0.0, 1e5, 50e-3)]),
                bristle: BristleParams::modal_scenario(),
                velocity_m_per_s: 0.5,
                normal_force_n: 1.0,
                output_gain: 2.0,
            },
            // A door hinge: a steel pin and leaf, bending modes 500, 1300, 1700 Hz with
            // decays 30, 20, 10 ms (the SDT rubbing preset's object, Q = pi f tau), 10 g
            // modal masses; slow rotation (2 cm/s at the pin surface) under 4 N.
            // Dry steel friction: mu_s 0.8, mu_d 0.4 (the SDT defaults' range).
            RubbedPreset::DoorHinge => RubbedSpec {
                resonator: vec![
                    mode(500.0, 47.0, 0.01),
                    mode(1300.0, 82.0, 0.01),
                    mode(1700.0, 53.0, 0.01),
                ],
                exciter: None,
                bristle: BristleParams {
                    sigma0_n_per_m: 1e5,
                    sigma1_kg_per_s: 1.0,
                    sigma2_kg_per_s: 0.0,
                    stribeck_m_per_s: 0.01,
                    mu_s: 0.8,
                    mu_d: 0.4,
                    breakaway_ratio: 0.7,
                },
                velocity_m_per_s: 0.02,
                normal_force_n: 4.0,
                output_gain: 18.0,
            },
            // Chalk on a slate board: plate modes from 1.1 to 4.3 kHz, Q 30-60, 20 g modal
            // masses (a stiff chalk contact: sigma0 1e6 N/m, sigma1 0.1 kg/s); the chalk a velocity source at 0.14 m/s under 6 N; chalky friction
            // mu_s 0.7, mu_d 0.3 with a broad Stribeck drop (0.2 m/s), so the friction still
            // falls with speed at the drawing speed.
            RubbedPreset::Chalk => RubbedSpec {
                resonator: vec![
                    mode(1100.0, 40.0, 0.02),
                    mode(2300.0, 60.0, 0.02),
                    mode(3150.0, 50.0, 0.02),
                    mode(4300.0, 30.0, 0.02),
                ],
                exciter: None,
                bristle: BristleParams {
                    sigma0_n_per_m: 1e6,
                    sigma1_kg_per_s: 0.1,
                    sigma2_kg_per_s: 0.0,
                    stribeck_m_per_s: 0.2,
                    mu_s: 0.7,
                    mu_d: 0.3,
                    breakaway_ratio: 0.7,
                },
                velocity_m_per_s: 0.14,
                normal_force_n: 6.0,
                output_gain: 3.5,
            },
            // A wine glass rubbed at the rim by a wet finger: bell modes (2,0) 660 Hz,
            // (3,0) 1780 Hz, (4,0) 3340 Hz (ratios of a thin-walled glass), Q 1500-3000
            // (glass rings for seconds), 5 g modal masses; the finger a velocity source at
            // 7 cm/s under 1 N; wet skin on glass: mu_s 0.6, mu_d 0.25, v_s 0.1 m/s.
            RubbedPreset::WineGlass => RubbedSpec {
                resonator: vec![
                    mode(660.0, 3000.0, 0.005),
                    mode(1780.0, 2000.0, 0.005),
                    mode(3340.0, 1500.0, 0.005),
                ],
                exciter: None,
                bristle: BristleParams {
                    sigma0_n_per_m: 5e4,
                    sigma1_kg_per_s: 0.5,
                    sigma2_kg_per_s: 0.0,
                    stribeck_m_per_s: 0.1,
                    mu_s: 0.6,
                    mu_d: 0.25,
                    breakaway_ratio: 0.7,
                },
                velocity_m_per_s: 0.07,
                normal_force_n: 1.0,
                output_gain: 5.0,
            },
            // Brake squeal: out-of-plane disc modes 1.9, 3.6, 5.8 kHz, Q 300-500, 0.2 kg
            // modal masses; the pad a velocity source at 0.45 m/s sliding speed under 40 N;
            // pad on cast iron: mu_s 0.55, mu_d 0.4, falling over 0.6 m/s.
            RubbedPreset::BrakeSqueal => RubbedSpec {
                resonator: vec![
                    mode(1900.0, 500.0, 0.2),
                    mode(3600.0, 400.0, 0.2),
                    mode(5800.0, 300.0, 0.2),
                ],
                exciter: None,
                bristle: BristleParams {
                    sigma0_n_per_m: 1e6,
                    sigma1_kg_per_s: 5.0,
                    sigma2_kg_per_s: 0.0,
                    stribeck_m_per_s: 0.6,
                    mu_s: 0.55,
                    mu_d: 0.4,
                    breakaway_ratio: 0.7,
                },
                velocity_m_per_s: 0.45,
                normal_force_n: 40.0,
                output_gain: 1.5,
            },
        }
    }
}

/// A rubbed scene as data.
#[derive(Debug, Clone, PartialEq)]
pub struct RubbedSpec {
    pub resonator: Vec<ModeSpec>,
    /// Modes of a modal exciter pushed by a force; `None`: a rigid velocity source.
    pub exciter: Option<Vec<ModeSpec>>,
    pub bristle: BristleParams,
    /// Exciter velocity (rigid) or target sliding velocity (modal), m/s.
    pub velocity_m_per_s: f64,
    pub normal_force_n: f64,
    /// Audio = gain x resonator velocity at the contact.
    pub output_gain: f64,
}

/// One sample of a rubbed scene.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RubbedFrame {
    pub audio: f64,
    pub contact: PairOutput,
    /// Relative velocity exciter minus resonator, m/s.
    pub relative_velocity_m_per_s: f64,
}

/// A preset set up at a sample rate, with its friction contact.
#[derive(Debug, Clone)]
pub struct RubbedScene {
    pub spec: RubbedSpec,
    pair: FrictionPair,
    contact: AnyFriction,
    /// A modal exciter's push at the preset's normal force: the steady sliding friction
    /// at the target velocity (Stribeck part, scales with the normal force) and its
    /// viscous part `sigma2 v` (only while in contact).
    push_friction_n: f64,
    push_viscous_n: f64,
}

impl RubbedScene {
    /// The preset with the elasto-plastic law.
    pub fn new(preset: RubbedPreset, sample_rate_hz: f64) -> Result<Self, String> {
        Self::from_spec(preset.spec(), FrictionModel::ElastoPlastic, sample_rate_hz)
    }

    pub fn from_spec(
        spec: RubbedSpec,
        model: FrictionModel,
        sample_rate_hz: f64,
    ) -> Result<Self, String> {
        let resonator = ModalObject::new(&spec.resonator, sample_rate_hz)?;
        let exciter = match &spec.exciter {
            None => Exciter::Rigid,
            Some(modes) => Exciter::Modal(ModalObject::new(modes, sample_rate_hz)?),
        };
        let contact = AnyFriction::new(model, spec.bristle, sample_rate_hz)?;
        // A modal exciter is pushed with the steady sliding friction at the target
        // velocity (the authors' fe_b), so it settles there on average.
        let p = spec.bristle;
        let v = spec.velocity_m_per_s;
        let f_c = p.mu_d * spec.normal_force_n;
        let f_s = p.mu_s * spec.normal_force_n;
        let push_friction_n =
            v.signum() * (f_c + (f_s - f_c) * (-(v / p.stribeck_m_per_s).powi(2)).exp());
        Ok(Self {
            spec,
            pair: FrictionPair { resonator, exciter },
            contact,
            push_friction_n,
            push_viscous_n: p.sigma2_kg_per_s * v,
        })
    }

    pub fn set_friction_model(&mut self, model: FrictionModel) {
        self.contact.set_model(model);
    }

    pub fn solver_stats(&self) -> SolverStats {
        self.contact.bristle().stats
    }

    /// Newton tolerance of the bristle laws (see
    /// [`crate::dsp::friction::bristle::BristleFriction::set_newton_tolerance`]).
    pub fn set_newton_tolerance(&mut self, tolerance_m_per_s: f64) {
        self.contact
            .bristle_mut()
            .set_newton_tolerance(tolerance_m_per_s);
    }

    pub fn is_sticking(&self) -> bool {
        self.contact.is_sticking()
    }

    /// The preset's own velocity and force.
    pub fn preset_bow(&self) -> BowInput {
        BowInput {
            velocity_m_per_s: self.spec.velocity_m_per_s,
            normal_force_n: self.spec.normal_force_n,
        }
    }

    /// One sample with an explicit exciter velocity and normal force. A modal exciter is
    /// pushed with the steady friction at its target velocity under this normal force, so
    /// it still settles there; lifted (no normal force) it is not pushed and coasts. The
    /// push never exceeds what the active law holds back at high sliding speed
    /// ([`AnyFriction::high_speed_friction_n`]): the static curves have no viscous term,
    /// and a push above their `mu_d F_N` would never be balanced. (A fixed push
    /// accelerated the free mass without bound under a lighter force or a static law, and
    /// it then struck the object at tens of m/s.)
    pub fn tick(&mut self, bow: BowInput) -> RubbedFrame {
        let f_n = bow.normal_force_n;
        let push_n = if f_n > 0.0 && self.spec.normal_force_n > 0.0 {
            let push =
                self.push_friction_n * (f_n / self.spec.normal_force_n) + self.push_viscous_n;
            push.signum() * push.abs().min(self.contact.high_speed_friction_n(f_n))
        } else {
            0.0
        };
        let out = self.pair.tick(&mut self.contact, bow, push_n);
        let audio =
            super::filters::flush_tiny(self.spec.output_gain * out.resonator_velocity_m_per_s);
        RubbedFrame {
            audio: if audio.is_finite() { audio } else { 0.0 },
            contact: out,
            relative_velocity_m_per_s: out.exciter_velocity_m_per_s
                - out.resonator_velocity_m_per_s,
        }
    }

    pub fn reset(&mut self) {
        self.pair.reset();
        self.contact.reset();
    }

    /// Resonator modal energy, J.
    pub fn resonator_energy_j(&self) -> f64 {
        self.pair.resonator.energy_j()
    }

    /// Samples until the lifted resonator's energy falls below `threshold_j`
    /// ([`ModalObject::ring_out_samples`]).
    pub fn ring_out_samples(&self, threshold_j: f64) -> Option<f64> {
        self.pair.resonator.ring_out_samples(threshold_j)
    }
}

/// Bow landing/lifting time on a rubbed object, s (as on the strings).
const RUB_RAMP_S: f64 = 0.02;
/// Below this modal energy (J) with the exciter lifted, a rubbed object is silent.
const RUB_SLEEP_ENERGY_J: f64 = 1e-16;

/// The rubbed presets as a playable instrument: note on presses the exciter onto the
/// active object (force ramps over 20 ms), note off lifts it and the object rings on. The
/// bow controls scale the preset's own velocity and force: 1.0 at the plugin's defaults
/// (0.1 m/s, 1 N); a modal exciter (paper-modal) keeps its own target velocity, pushed in
/// proportion to the force (see [`RubbedScene::tick`]). Every preset is built
/// when the instrument is made, so switching never allocates; an object switched away from
/// is lifted and rings on (no click) until it falls asleep.
#[derive(Debug, Clone)]
pub struct RubbedInstrument {
    voices: Vec<RubbedVoice>,
    active: usize,
    notes_down: u32,
    ramp_step: f64,
    sample_rate_hz: f64,
}

/// The bow at which every rubbed preset plays at its own velocity and force: a bow of
/// twice this velocity rubs twice as fast ([`RubbedInstrument::tick`]).
pub const REFERENCE_BOW: BowControl = BowControl {
    velocity_m_per_s: 0.1,
    force_n: 1.0,
    position_beta: 0.1,
};

#[derive(Debug, Clone)]
struct RubbedVoice {
    scene: RubbedScene,
    bow_gain: f64,
    awake: bool,
}

impl RubbedInstrument {
    pub fn new(sample_rate_hz: f64) -> Self {
        let voices = RubbedPreset::ALL
            .iter()
            .map(|p| RubbedVoice {
                scene: RubbedScene::new(*p, sample_rate_hz).expect("built-in presets are valid"),
                bow_gain: 0.0,
                awake: false,
            })
            .collect();
        Self {
            voices,
            active: 1,
            notes_down: 0,
            ramp_step: 1.0 / (RUB_RAMP_S * sample_rate_hz),
            sample_rate_hz,
        }
    }

    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    pub fn preset(&self) -> RubbedPreset {
        RubbedPreset::ALL[self.active]
    }

    /// Switches the object that receives the notes. Held notes stay held: the exciter
    /// lifts off the old object and lands on the new one.
    pub fn set_preset(&mut self, preset: RubbedPreset) {
        let index = RubbedPreset::ALL
            .iter()
            .position(|p| *p == preset)
            .unwrap_or(0);
        if index != self.active {
            self.active = index;
            if self.notes_down > 0 {
                self.voices[index].awake = true;
            }
        }
    }

    pub fn set_friction_model(&mut self, model: FrictionModel) {
        for voice in &mut self.voices {
            voice.scene.set_friction_model(model);
        }
    }

    /// Newton tolerance of every voice's bristle law (m/s).
    pub fn set_newton_tolerance(&mut self, tolerance_m_per_s: f64) {
        for voice in &mut self.voices {
            voice.scene.set_newton_tolerance(tolerance_m_per_s);
        }
    }

    pub fn note_on(&mut self) {
        self.notes_down += 1;
        self.voices[self.active].awake = true;
    }

    pub fn note_off(&mut self) {
        self.notes_down = self.notes_down.saturating_sub(1);
    }

    pub fn all_notes_off(&mut self) {
        self.notes_down = 0;
    }

    pub fn is_bowed(&self) -> bool {
        self.notes_down > 0
    }

    pub fn is_sounding(&self) -> bool {
        self.voices.iter().any(|v| v.awake)
    }

    pub fn reset(&mut self) {
        for voice in &mut self.voices {
            voice.scene.reset();
            voice.bow_gain = 0.0;
            voice.awake = false;
        }
        self.notes_down = 0;
    }

    /// Modal energy of every object's resonator, J.
    pub fn energy_j(&self) -> f64 {
        self.voices
            .iter()
            .map(|v| v.scene.resonator_energy_j())
            .sum()
    }

    /// Newton statistics of `preset`'s bristle contact.
    pub fn solver_stats(&self, preset: RubbedPreset) -> SolverStats {
        let index = RubbedPreset::ALL
            .iter()
            .position(|p| *p == preset)
            .unwrap_or(0);
        self.voices[index].scene.solver_stats()
    }

    /// Samples until every object would fall asleep if no note comes (the host's tail), or
    /// `None` while the exciter touches one (or a mode can not be bounded).
    pub fn ring_out_samples(&self) -> Option<f64> {
        let mut longest = 0.0f64;
        for (i, voice) in self.voices.iter().enumerate() {
            if !voice.awake {
                continue;
            }
            if (i == self.active && self.notes_down > 0) || voice.bow_gain > 0.0 {
                return None;
            }
            longest = longest.max(voice.scene.ring_out_samples(RUB_SLEEP_ENERGY_J)?);
        }
        Some(longest)
    }

    /// Once per block: an object sleeps when lifted and quiet.
    pub fn update_sleep(&mut self) {
        for (i, voice) in self.voices.iter_mut().enumerate() {
            let bowed = i == self.active && self.notes_down > 0;
            if voice.awake
                && !bowed
                && voice.bow_gain == 0.0
                && voice.scene.resonator_energy_j() < RUB_SLEEP_ENERGY_J
            {
                voice.scene.reset();
                voice.awake = false;
            }
        }
    }

    /// One sample bowed with `bow` in SI units: the preset's own velocity and force are
    /// scaled by the bow's against [`REFERENCE_BOW`].
    pub fn tick(&mut self, bow: &BowControl) -> f64 {
        self.tick_scaled(
            bow.velocity_m_per_s / REFERENCE_BOW.velocity_m_per_s,
            bow.force_n / REFERENCE_BOW.force_n,
        )
    }

    /// One sample; `velocity_scale` and `force_scale` multiply the preset's own values.
    pub fn tick_scaled(&mut self, velocity_scale: f64, force_scale: f64) -> f64 {
        let mut audio = 0.0;
        for (i, voice) in self.voices.iter_mut().enumerate() {
            if !voice.awake {
                continue;
            }
            let target = if i == self.active && self.notes_down > 0 {
                1.0
            } else {
                0.0
            };
            if voice.bow_gain < target {
                voice.bow_gain = (voice.bow_gain + self.ramp_step).min(1.0);
            } else if voice.bow_gain > target {
                voice.bow_gain = (voice.bow_gain - self.ramp_step).max(0.0);
            }
            let spec = &voice.scene.spec;
            let bow = BowInput {
                velocity_m_per_s: spec.velocity_m_per_s * velocity_scale,
                normal_force_n: spec.normal_force_n * (force_scale * voice.bow_gain).max(0.0),
            };
            audio += voice.scene.tick(bow).audio;
        }
        audio
    }
}
