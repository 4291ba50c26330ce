//! The instrument: four bowed waveguide strings of a violin, viola, cello or double bass, a shared bow,
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
//! use colophony::dsp::instrument::Instrument;
//! use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
//! let mut cello = Instrument::new(InstrumentKind::Cello, 48_000.0);
//! assert_eq!(cello.note_on(50), Some(2)); // D3 on the D string
//! let bow = BowControl { velocity_m_per_s: 0.1, force_n: 1.0, position_beta: 0.1 };
//! let peak = (0..24_000).map(|_| cello.tick(bow).audio.abs()).fold(0.0, f64::max);
//! assert!(peak > 0.01 && peak < 1.0);
//! ```

pub use super::body::MUTE_FADE_S;
use super::body::{body_for, BodyMode, BodyModes, FadingBody, MAX_BODY_MODES};
use super::friction::bristle::{BristleParams, SolverStats};
use super::friction::{
    law, AnyFriction, BowInput, FrictionContact, FrictionModel, HyperbolicFriction, KnownLaw,
};
use super::halfband::HalfbandDecimator;
use super::intonation;
use super::resample::Resampler;
pub use super::strings::FourStrings;
use super::strings::{InternalSample, StringBank, StringBow, HARMONIC_FINGER_RESISTANCE_Z0};
use super::waveguide::{StringOutput, WaveguideString, ANY_STAGES, DEFAULT_DISPERSION_STAGES};

use super::vocabulary::*;

/// The body sleeps once every mode's state is below this (N-scale: output below -200 dB of
/// a bowed note).
const BODY_QUIET_N: f64 = 1e-12;

/// The factor [`Instrument::ring_out_s`] puts on each string's Q1 (see there).
const RING_OUT_Q_MARGIN: f64 = 1.05;

/// One point-bow string with its contact.
#[derive(Debug, Clone)]
struct StringVoice {
    string: WaveguideString,
    contact: AnyFriction,
    awake: bool,
}

impl StringVoice {
    /// One sample of the string with its contact; with `SLOW`, as struck while the stick
    /// strikes; `LAW` as [`KnownLaw`]'s (its bits above [`law::MASK`] the caller's).
    /// Always inlined: a call a string and sample costs its saving of the registers
    /// around it.
    #[inline(always)]
    fn tick<const SLOW: bool, const LAW: u8>(&mut self, input: BowInput) -> StringOutput {
        if SLOW && self.string.is_struck() {
            self.string.tick_struck(&mut self.contact, input)
        } else if LAW & law::MASK == law::ANY {
            self.string.tick(&mut self.contact, input)
        } else {
            self.string
                .tick(&mut KnownLaw::<LAW>(&mut self.contact), input)
        }
    }

    /// [`StringVoice::tick`], not `SLOW`, for a string whose dispersion has `STAGES`
    /// sections ([`WaveguideString::tick_with_stages`]).
    #[inline(always)]
    fn tick_with_stages<const LAW: u8, const STAGES: usize>(
        &mut self,
        input: BowInput,
    ) -> StringOutput {
        if LAW & law::MASK == law::ANY {
            self.string
                .tick_with_stages::<STAGES>(&mut self.contact, input)
        } else {
            self.string
                .tick_with_stages::<STAGES>(&mut KnownLaw::<LAW>(&mut self.contact), input)
        }
    }
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
    /// The body, fading to a mute's modes and back ([`FadingBody`]).
    body: FadingBody,
    /// Each instrument's body in place of the generic one ([`Instrument::set_body`]):
    /// modes and their count, per [`InstrumentKind::ALL`] index.
    custom_bodies: [Option<([BodyMode; MAX_BODY_MODES], usize)>; InstrumentKind::COUNT],
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
    /// AVX2 detected at run time ([`samples_avx2`]).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    wide_simd: bool,
    /// The strings [`StringBank::sample`] computes, in order: the awake ones (every one
    /// when not skipping), the first `computed_count` entries
    /// ([`WaveguideBank::update_computed`]).
    computed: [usize; STRINGS],
    computed_count: usize,
    /// No string awake and the body rung out: a sample costs nothing.
    body_asleep: bool,
    /// A mute on the bridge (con sordino, [`super::body::muted`]).
    muted: bool,
    /// A stick is striking a string (col legno), or the body is moving to a mute's modes:
    /// [`WaveguideBank::sample_slow`].
    slow: bool,
    /// The friction law the strings play with the hair ([`Instrument::set_friction_model`])
    /// and whether the hair yields ([`Instrument::set_bow_hair`]), kept while the stick
    /// plays instead ([`Instrument::set_stick_contact`]).
    law: FrictionModel,
    hair: bool,
    stick: bool,
}

/// The bow's stick drawn across the string (col legno tratto): varnished, unrosined wood
/// on the string, the hyperbolic law with these coefficients. Choices, not measurements
/// (none of a stick on a string was found): the stick's static friction well under the
/// rosined hair's 0.4, and a small fall to sliding, where rosin's falls to half.
pub const STICK_MU_S: f64 = 0.15;
/// The stick's sliding friction ([`STICK_MU_S`]).
pub const STICK_MU_D: f64 = 0.12;

/// The four waveguide strings of a violin, viola, cello or double bass with a shared bow, note
/// handling and a generic body (see the module doc): [`FourStrings`] over
/// [`WaveguideBank`].
pub type Instrument = FourStrings<WaveguideBank>;

impl WaveguideBank {
    /// Lists the strings a sample computes, after any change of which are awake or of
    /// skipping: a sample then walks only those.
    fn update_computed(&mut self) {
        let mut count = 0;
        for (i, voice) in self.voices.iter().enumerate() {
            if voice.awake || !self.skipping {
                self.computed[count] = i;
                count += 1;
            }
        }
        self.computed_count = count;
    }

    /// The rate string `index` runs at: the bank's times its oversampling.
    pub fn string_rate_hz(&self, index: usize) -> f64 {
        self.sample_rate_hz * self.oversample[index.min(STRINGS - 1)] as f64
    }

    /// The body `kind` plays: its custom one if set, else the generic one.
    fn body_of(&self, kind: InstrumentKind) -> BodyModes {
        let custom = self.custom_bodies[kind.index()]
            .as_ref()
            .map(|(modes, n)| &modes[..*n]);
        body_for(kind, custom, self.muted, self.sample_rate_hz)
    }
}

impl StringBank for WaveguideBank {
    type Settings = ();
    const SAMPLE_IS_FLUSHED: bool = true;

    const HAS_BODY: bool = true;

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

    const PLUCKABLE: bool = true;

    const TOUCHABLE: bool = true;

    fn touch(&mut self, i: usize, partial: Option<u32>) {
        let string = &mut self.voices[i].string;
        let r = HARMONIC_FINGER_RESISTANCE_Z0 * string.spec().z0_kg_per_s;
        string.set_touch(partial.map(|n| (n, r)));
    }

    fn set_mute(&mut self, on: bool) {
        if on != self.muted {
            self.muted = on;
            let body = self.body_of(self.kind);
            self.body.fade_to(&body, self.sample_rate_hz);
            self.slow = true;
        }
    }

    fn pluck(&mut self, i: usize, displacement_m: f64, position_beta: f64, width: f64) -> bool {
        let string = &mut self.voices[i].string;
        string.pluck(displacement_m, position_beta, width);
        string.is_playable()
    }

    fn strike(&mut self, i: usize, strike: Strike) -> bool {
        let string = &mut self.voices[i].string;
        string.strike(strike.mass_kg, strike.velocity_m_per_s);
        self.slow |= string.is_struck();
        string.is_playable()
    }

    fn wake(&mut self, i: usize) {
        let voice = &mut self.voices[i];
        voice.awake = voice.string.is_playable();
        self.update_computed();
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
        self.update_computed();
    }

    /// One internal sample, for the callers that go a sample at a time (the resampled
    /// path, a live view, the frame renderer). Out of line, with the strings and friction
    /// inlined into it, so the caller's loop stays small; a block goes through
    /// [`StringBank::samples`] instead, one call for all its samples.
    #[inline(never)]
    fn sample(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        self.sample_inline(probed, bow_of)
    }

    #[inline(always)]
    fn sample_inline(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        if self.slow {
            return self.sample_slow(probed, bow_of);
        }
        self.sample_as::<false, true, { law::ANY }>(probed, bow_of)
    }

    /// The strings' bridge force, for [`StringBank::samples`] to run the body over.
    #[inline(always)]
    fn strings_inline<const SHAPE: u8>(
        &mut self,
        probed: usize,
        bow_of: impl FnMut(usize) -> StringBow,
    ) -> f64 {
        self.sample_as::<false, false, SHAPE>(probed, bow_of)
    }

    /// The block's samples in out-of-line loops, each sample inlined into them: while no
    /// stick strikes and the body does not fade, the strings' bridge force over the block,
    /// then the body over it (the same operations on the same values, a stage at a time).
    /// Compiled for AVX2 where the CPU has it ([`samples_avx2`]).
    #[inline(never)]
    fn samples(&mut self, out: &mut [f64], step: &mut impl InternalSample<Self>) {
        #[cfg(target_arch = "x86_64")]
        if self.wide_simd {
            // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
            return unsafe { samples_avx2(self, out, step) };
        }
        self.samples_portable(out, step);
    }

    fn probe(&self) -> (f64, f64) {
        self.probe
    }

    fn sleep(&mut self, lifted: &[bool; STRINGS]) -> bool {
        // The body sleeps too once no string is awake and its modes have rung out
        // (state below 1e-12 N: output below -200 dB of a bowed note).
        self.body_asleep =
            self.voices.iter().all(|v| !v.awake) && self.body.playing.is_quiet(BODY_QUIET_N);
        if self.body_asleep {
            self.body.playing.reset();
            self.decimator.reset();
        }
        for (voice, &lifted) in self.voices.iter_mut().zip(lifted) {
            if voice.awake && lifted && voice.string.energy_j() < SLEEP_ENERGY_J {
                voice.string.reset();
                voice.awake = false;
            }
        }
        self.update_computed();
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
            self.body.playing.samples_below(BODY_QUIET_N) / self.sample_rate_hz
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
        self.update_computed();
        self.body.reset();
        self.decimator.reset();
        self.probe = (0.0, 0.0);
    }

    fn settings(&self) {}

    fn configure(&mut self, _settings: ()) -> Result<(), String> {
        Ok(())
    }
}

/// [`WaveguideBank::lone_steady_block`]'s loop: `voice` bowed by `input` for each sample
/// of `out` (its bridge force; with `TWICE`, two of the string's samples through
/// `decimator`), its dispersion's sections `STAGES`; the string's last output.
#[inline(always)]
fn lone_loop<const SHAPE: u8, const STAGES: usize, const TWICE: bool>(
    voice: &mut StringVoice,
    decimator: &mut HalfbandDecimator,
    input: BowInput,
    out: &mut [f64],
) -> StringOutput {
    const { assert!(STAGES == ANY_STAGES || STAGES <= DEFAULT_DISPERSION_STAGES) };
    let mut last = StringOutput::default();
    for sample in out {
        // The sums over the strings start at +0 ([`WaveguideBank::sample_as`]).
        *sample = if TWICE {
            let first = 0.0
                + voice
                    .tick_with_stages::<SHAPE, STAGES>(input)
                    .bridge_force_n;
            last = voice.tick_with_stages::<SHAPE, STAGES>(input);
            0.0 + decimator.tick(first, 0.0 + last.bridge_force_n)
        } else {
            last = voice.tick_with_stages::<SHAPE, STAGES>(input);
            0.0 + last.bridge_force_n
        };
    }
    last
}

/// [`StringBank::samples`] compiled for AVX2: the body's modes four to a vector, and three
/// operands an instruction where SSE2 copies a register first (no FMA: the same bits as
/// the portable path).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn samples_avx2(
    bank: &mut WaveguideBank,
    out: &mut [f64],
    step: &mut impl InternalSample<WaveguideBank>,
) {
    bank.samples_portable(out, step);
}

/// Marks a [`shape`] whose block computes one string at the bank's own rate.
const LONE: u8 = 4;

/// What [`WaveguideBank::samples`] found true of a whole block, as
/// [`StringBank::strings_inline`]'s `SHAPE`: the strings' [`law`], and whether it computes
/// one string at the bank's own rate (`lone`: no loop over the strings, no decimator).
const fn shape(law: u8, lone: bool) -> u8 {
    law | if lone { LONE } else { 0 }
}

impl WaveguideBank {
    /// [`StringBank::samples`] for any CPU.
    #[inline(always)]
    fn samples_portable(&mut self, out: &mut [f64], step: &mut impl InternalSample<Self>) {
        if self.slow {
            for sample in out {
                *sample = step.tick(self);
            }
            return;
        }
        // The strings' law, where they share one (compiled in, not asked each sample).
        let computed = &self.computed[..self.computed_count.min(STRINGS)];
        let first = computed
            .first()
            .map_or(law::ANY, |&i| self.voices[i].contact.law());
        let shared = computed
            .iter()
            .all(|&i| self.voices[i].contact.law() == first);
        // One string at the bank's own rate: no loop over strings, no decimator.
        let lone = computed.len() == 1 && self.oversample[computed[0] % STRINGS] == 1;
        match (if shared { first } else { law::ANY }, lone) {
            (law::HYPERBOLIC, true) => {
                self.strings_block::<{ shape(law::HYPERBOLIC, true) }>(out, step)
            }
            (law::HYPERBOLIC, false) => {
                self.strings_block::<{ shape(law::HYPERBOLIC, false) }>(out, step)
            }
            (law::STRIBECK, true) => {
                self.strings_block::<{ shape(law::STRIBECK, true) }>(out, step)
            }
            (law::STRIBECK, false) => {
                self.strings_block::<{ shape(law::STRIBECK, false) }>(out, step)
            }
            (law::BRISTLE, true) => self.strings_block::<{ shape(law::BRISTLE, true) }>(out, step),
            (law::BRISTLE, false) => {
                self.strings_block::<{ shape(law::BRISTLE, false) }>(out, step)
            }
            _ => self.strings_block::<{ shape(law::ANY, false) }>(out, step),
        }
        let body = &mut self.body.playing;
        let scale = self.output_scale;
        for sample in out {
            *sample = super::filters::flush_tiny(body.tick_inline(*sample) * scale);
        }
    }

    /// The strings' bridge force over a block of shape `SHAPE` ([`shape`]).
    #[inline(always)]
    fn strings_block<const SHAPE: u8>(
        &mut self,
        out: &mut [f64],
        step: &mut impl InternalSample<Self>,
    ) {
        if let Some((bows, probed)) = step.steady() {
            let i = self.computed[0] % STRINGS;
            if SHAPE & LONE != 0 {
                self.lone_steady_block::<SHAPE, false>(out, i, bows[i], probed);
                return;
            }
            // One string at twice the bank's rate (the violin's and viola's).
            if self.computed_count == 1 && self.oversample[i] == 2 {
                self.lone_steady_block::<SHAPE, true>(out, i, bows[i], probed);
                return;
            }
        }
        for sample in out {
            *sample = step.tick_strings::<SHAPE>(self);
        }
    }

    /// The bridge force over a block of a lone string `i` bowed by `bow` throughout,
    /// `probed` the probed string: its bow set once, then the string alone in the loop
    /// (the samples of [`WaveguideBank::sample_as`] for it). The string runs at the bank's
    /// rate ([`shape`]'s lone), or with `TWICE` at twice it through the decimator.
    #[inline(always)]
    fn lone_steady_block<const SHAPE: u8, const TWICE: bool>(
        &mut self,
        out: &mut [f64],
        i: usize,
        bow: StringBow,
        probed: usize,
    ) {
        if out.is_empty() {
            return;
        }
        self.body_asleep = false;
        let (voice, decimator) = (&mut self.voices[i], &mut self.decimator);
        voice.string.set_bow_position(bow.position_beta);
        let input = BowInput {
            velocity_m_per_s: bow.velocity_m_per_s,
            normal_force_n: bow.force,
        };
        // The dispersion's count compiled in, up to the fit's default cap, for a string
        // with nothing else on it.
        let stages = if voice.string.is_plain() {
            voice.string.dispersion_stages()
        } else {
            ANY_STAGES
        };
        let last = match stages {
            0 => lone_loop::<SHAPE, 0, TWICE>(voice, decimator, input, out),
            1 => lone_loop::<SHAPE, 1, TWICE>(voice, decimator, input, out),
            2 => lone_loop::<SHAPE, 2, TWICE>(voice, decimator, input, out),
            3 => lone_loop::<SHAPE, 3, TWICE>(voice, decimator, input, out),
            4 => lone_loop::<SHAPE, 4, TWICE>(voice, decimator, input, out),
            5 => lone_loop::<SHAPE, 5, TWICE>(voice, decimator, input, out),
            6 => lone_loop::<SHAPE, 6, TWICE>(voice, decimator, input, out),
            7 => lone_loop::<SHAPE, 7, TWICE>(voice, decimator, input, out),
            8 => lone_loop::<SHAPE, 8, TWICE>(voice, decimator, input, out),
            _ => lone_loop::<SHAPE, ANY_STAGES, TWICE>(voice, decimator, input, out),
        };
        if i == probed {
            self.probe = (last.bow_point_velocity_m_per_s, last.friction_force_n);
        }
    }

    /// [`StringBank::sample`] while a stick strikes a string (col legno: the struck
    /// strings take the stick's contact, [`WaveguideString::tick_struck`]) or the body
    /// fades to a mute's modes. Out of line, off the bowed strings' path: a few
    /// milliseconds at a time.
    #[cold]
    #[inline(never)]
    fn sample_slow(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        let out = self.sample_as::<true, true, { law::ANY }>(probed, bow_of);
        self.slow = self.body.is_fading() || self.voices.iter().any(|v| v.string.is_struck());
        out
    }

    /// One internal sample of every awake string and the body; with `SLOW`, a struck
    /// string ticks as struck and a fading body fades.
    #[inline(always)]
    fn sample_as<const SLOW: bool, const BODY: bool, const SHAPE: u8>(
        &mut self,
        probed: usize,
        mut bow_of: impl FnMut(usize) -> StringBow,
    ) -> f64 {
        const { assert!(SHAPE & LONE == 0 || !SLOW) };
        // `tick` checked that something is awake; sleep changes only between blocks.
        self.body_asleep = false;
        let mut bridge = 0.0;
        // The bridge force of the strings at twice the bank's rate, a pair a bank sample.
        let mut fine = [0.0; 2];
        let mut any_fine = false;
        // A lone string ([`shape`]): one pass at the bank's rate, known where compiled.
        let lone = SHAPE & LONE != 0;
        let count = if lone {
            1
        } else {
            self.computed_count.min(STRINGS)
        };
        for k in 0..count {
            let i = self.computed[k] % STRINGS;
            let voice = &mut self.voices[i];
            let bow = bow_of(i);
            voice.string.set_bow_position(bow.position_beta);
            let input = BowInput {
                velocity_m_per_s: bow.velocity_m_per_s,
                normal_force_n: bow.force,
            };
            if lone || self.oversample[i] == 1 {
                let out = voice.tick::<SLOW, SHAPE>(input);
                bridge += out.bridge_force_n;
                if i == probed {
                    self.probe = (out.bow_point_velocity_m_per_s, out.friction_force_n);
                }
            } else {
                // The bow is held over the string's two samples; the probe is the later's.
                any_fine = true;
                for force in &mut fine {
                    let out = voice.tick::<SLOW, SHAPE>(input);
                    *force += out.bridge_force_n;
                    if i == probed {
                        self.probe = (out.bow_point_velocity_m_per_s, out.friction_force_n);
                    }
                }
            }
        }
        if !lone && any_fine {
            bridge += self.decimator.tick(fine[0], fine[1]);
        }
        if !BODY {
            return bridge;
        }
        let body = if SLOW {
            self.body.tick(bridge)
        } else {
            self.body.playing.tick(bridge)
        };
        super::filters::flush_tiny(body * self.output_scale)
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
        // Lowest fundamental any instrument can reach: its lowest open string bent down at
        // the lowest reference pitch.
        let lowest_hz =
            midi_to_hz(InstrumentKind::LOWEST_OPEN_NOTE as f64 + LOWEST_TUNING_SEMITONES) * 0.99;
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
            body: FadingBody::new(
                super::body::body_for(kind, None, false, sample_rate_hz),
                sample_rate_hz,
            ),
            custom_bodies: [None; InstrumentKind::COUNT],
            output_scale: kind.output_scale_per_n(),
            probe: (0.0, 0.0),
            oversample,
            oversampling,
            decimator: HalfbandDecimator::new(),
            skipping: true,
            wide_simd: super::detect_wide_simd(),
            computed: [0; STRINGS],
            computed_count: 0,
            body_asleep: true,
            muted: false,
            law: FrictionModel::Hyperbolic,
            hair: true,
            stick: false,
            slow: false,
        };
        Self::from_bank(
            bank,
            kind,
            host_rate_hz,
            resampler,
            intonation::TunedModel::Point(FrictionModel::Hyperbolic).row(),
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
        bank.update_computed();
        bank.body.playing = bank.body_of(kind);
        bank.output_scale = kind.output_scale_per_n();
    }

    /// Plays `kind`'s body as `modes` (at most [`MAX_BODY_MODES`]; a fitted bridge's
    /// passive reduction, [`super::body::body_from_bridge`]) instead of the generic one;
    /// `None` goes back to it. Takes effect now if `kind` is playing, else when it is
    /// chosen. Real-time safe.
    pub fn set_body(&mut self, kind: InstrumentKind, modes: Option<&[BodyMode]>) {
        let k = kind.index();
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
            bank.body.playing = bank.body_of(kind);
            bank.body_asleep = false;
        }
    }

    /// The string a note was sent to, with its current tuning (for tests and tools).
    pub fn string(&self, index: usize) -> &WaveguideString {
        &self.bank.voices[index].string
    }

    /// The friction contact of the string `index` (for tests and tools).
    pub fn contact(&self, index: usize) -> &AnyFriction {
        &self.bank.voices[index].contact
    }

    /// Strings computed on the next sample.
    pub fn awake_strings(&self) -> usize {
        self.bank.voices.iter().filter(|v| v.awake).count()
    }

    /// Switches every string's friction law, handing over force and stick state (no click).
    pub fn set_friction_model(&mut self, model: FrictionModel) {
        self.bank.law = model;
        if !self.bank.stick {
            for voice in &mut self.bank.voices {
                voice.contact.set_model(model);
            }
        }
        if self
            .hands
            .fingering
            .set_intonation_row(intonation::TunedModel::Point(model).row())
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
        self.bank.hair = enabled;
        if !self.bank.stick {
            for voice in &mut self.bank.voices {
                voice.string.set_bow_hair(enabled);
            }
        }
    }

    /// The bow's stick plays the strings instead of its hair (`true`, col legno tratto):
    /// the hyperbolic law with the wood's [`STICK_MU_S`] and [`STICK_MU_D`], and no hair
    /// to yield (the stick is stiff); `false` gives the strings back their law and hair.
    /// The stick state and force are handed over as in a change of law. Real-time safe.
    pub fn set_stick_contact(&mut self, stick: bool) {
        if stick == self.bank.stick {
            return;
        }
        self.bank.stick = stick;
        let (law, hair) = (self.bank.law, self.bank.hair);
        let rosin = HyperbolicFriction::default();
        for voice in &mut self.bank.voices {
            if stick {
                voice
                    .contact
                    .set_hyperbolic_coefficients(STICK_MU_S, STICK_MU_D, rosin.v0_m_per_s);
                voice.contact.set_model(FrictionModel::Hyperbolic);
                voice.string.set_bow_hair(false);
            } else {
                voice
                    .contact
                    .set_hyperbolic_coefficients(rosin.mu_s, rosin.mu_d, rosin.v0_m_per_s);
                voice.contact.set_model(law);
                voice.string.set_bow_hair(hair);
            }
        }
    }

    /// Replaces the bristle parameters of every string (validated; real-time safe).
    pub fn set_bristle_params(&mut self, params: BristleParams) -> Result<(), String> {
        let bank = &mut self.bank;
        for (i, voice) in bank.voices.iter_mut().enumerate() {
            let rate = bank.sample_rate_hz * bank.oversample[i] as f64;
            let model = voice.contact.model();
            voice.contact = AnyFriction::new(model, params, rate)?;
            if bank.stick {
                let v0 = HyperbolicFriction::default().v0_m_per_s;
                voice
                    .contact
                    .set_hyperbolic_coefficients(STICK_MU_S, STICK_MU_D, v0);
            }
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

    /// The reference pitch tunes every note, the lowest open string bent
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
                intonation::TunedModel::Point(FrictionModel::Hyperbolic).row(),
                InstrumentKind::Cello,
                index,
                above_open,
            );
            let tuned = want * 2f64.powf(-c / 1200.0);
            let f = cello.string(index).fundamental_hz();
            // The string is tuned to this frequency: the two differ by f64 rounding only.
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
            // Without the table the string is tuned to `want` itself: rounding only.
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

#[cfg(test)]
mod block_tests {
    //! [`FourStrings::process`]'s block path (the bank's [`StringBank::samples`]) against
    //! the same instrument ticked sample by sample.
    use super::*;

    /// Every friction law, on the cello (strings at the bank's rate), the violin (strings
    /// at twice it, through the decimator) and the double bass, with two strings bowed, a
    /// glide, a mute put on (the body fading: the slow path within blocks), a stick's
    /// strike and a note released, in blocks of 1, 37 and 512: the same bits as ticking.
    /// Ticking runs portable code; the blocks run the AVX2 path where the CPU has it and
    /// the portable one, so the two compilations agree as well.
    #[test]
    fn a_block_of_every_law_gives_the_samples_of_ticking_it() {
        let n = 24_000;
        let events = |i: &mut Instrument, at: usize, kind: InstrumentKind| {
            let open = kind.open_notes();
            match at {
                0 => {
                    i.note_on(open[1] + 4);
                }
                3_000 => {
                    i.note_on(open[2] + 2);
                }
                8_000 => {
                    i.note_on_gliding(open[2] + 5, 0.05);
                }
                12_000 => i.set_mute(true),
                15_000 => {
                    i.strike(
                        open[3],
                        Strike {
                            mass_kg: 0.005,
                            velocity_m_per_s: 0.5,
                        },
                    );
                }
                18_000 => i.note_off(open[1] + 4),
                _ => {}
            }
        };
        let marks = [0, 3_000, 8_000, 12_000, 15_000, 18_000, n];
        let bow = BowControl::default();
        for law in FrictionModel::ALL {
            for kind in [
                InstrumentKind::Cello,
                InstrumentKind::Violin,
                InstrumentKind::DoubleBass,
            ] {
                let fresh = || {
                    let mut i = Instrument::new(kind, 48_000.0);
                    i.set_friction_model(law);
                    i
                };
                let mut ticked = fresh();
                let mut want = Vec::with_capacity(n);
                for at in 0..n {
                    events(&mut ticked, at, kind);
                    want.push(ticked.tick(bow).audio.to_bits());
                }
                // Bowed (a bowed note is far louder than -60 dBFS), not a silent render.
                assert!(want.iter().any(|&x| f64::from_bits(x).abs() > 1e-3));
                for (block, portable) in [1, 37, 512]
                    .into_iter()
                    .flat_map(|b| [(b, false), (b, true)])
                {
                    let mut i = fresh();
                    if portable {
                        i.bank.wide_simd = false;
                    }
                    let mut got = Vec::with_capacity(n);
                    let mut out = vec![0.0; block];
                    for span in marks.windows(2) {
                        events(&mut i, span[0], kind);
                        let mut at = span[0];
                        while at < span[1] {
                            let len = block.min(span[1] - at);
                            i.process(bow, &mut out[..len]);
                            got.extend(out[..len].iter().map(|x| x.to_bits()));
                            at += len;
                        }
                    }
                    assert!(
                        got == want,
                        "{law:?}, {kind:?}, blocks of {block}, portable {portable}"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod finger_tests {
    //! The four-string instrument's finger lift ([`super::FourStrings::note_off`]), on the
    //! point-bow instrument.
    use super::*;
    use crate::dsp::strings::FINGER_LIFT_S;

    const FS: f64 = 48_000.0;

    fn bowed(cello: &mut Instrument, seconds: f64) {
        for _ in 0..(seconds * FS) as usize {
            cello.tick(BowControl::default());
        }
    }

    #[test]
    fn a_released_stopped_note_lifts_its_finger_and_the_string_then_sounds_open() {
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        let string = cello.note_on(46).unwrap(); // Bb2 on the G string
        bowed(&mut cello, 0.5);
        cello.note_off(46);
        assert!(cello.hands.lifting && cello.hands.lifts[string] == cello.hands.lift_samples);
        // The lift takes FINGER_LIFT_S; then the string's note is its open one.
        bowed(&mut cello, FINGER_LIFT_S + 0.001);
        assert!(!cello.hands.lifting);
        let open = InstrumentKind::Cello.open_notes()[string];
        assert_eq!(cello.hands.fingering.note(string), Some(open));
    }

    #[test]
    fn the_next_note_on_the_same_string_keeps_the_finger_down() {
        // Released and restopped at the same instant (detache on one string), and legato
        // (the next note before the release): no lift either way.
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        let string = cello.note_on(46).unwrap();
        bowed(&mut cello, 0.3);
        cello.note_off(46);
        assert_eq!(cello.note_on(47), Some(string));
        assert_eq!(cello.hands.lifts[string], 0);
        bowed(&mut cello, 0.3);
        assert_eq!(cello.note_on(48), Some(string));
        cello.note_off(47);
        assert_eq!(cello.hands.lifts[string], 0);
        assert!(!cello.hands.lifting);
    }

    #[test]
    fn a_released_open_string_has_no_finger_to_lift() {
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        cello.note_on(50).unwrap(); // the open D
        bowed(&mut cello, 0.3);
        cello.note_off(50);
        assert!(!cello.hands.lifting);
    }

    #[test]
    fn the_leaving_finger_only_takes_energy_out() {
        // With the bow lifted the strings' energy may only fall through the lift (it
        // scales the reflected wave by at most 1), and the lift takes most of it.
        let mut cello = Instrument::new(InstrumentKind::Cello, FS);
        cello.note_on(46).unwrap();
        bowed(&mut cello, 0.5);
        cello.note_off(46);
        // The bow's 20 ms release ramp first (the bow still on the string).
        bowed(&mut cello, 0.021);
        let start = cello.energy_j();
        let mut last = start;
        while cello.hands.lifting {
            cello.tick(BowControl::default());
            let e = cello.energy_j();
            if cello.hands.lifting {
                // 1e-12 relative: rounding of the energy sum.
                assert!(e <= last * (1.0 + 1e-12), "{e} after {last}");
            } else {
                // The finger is off and the string refitted for its open length: the loss
                // and dispersion filters' stored energy is counted with their new
                // coefficients (1 %: that bookkeeping, not a gain; the waves keep theirs
                // and the new part of the string starts at rest).
                assert!(e <= last * 1.01, "{e} after {last} at the release");
            }
            last = e;
        }
        // What the lift took: at least 90 % of the string's energy (10 dB) from the end of
        // the bow's ramp to the finger's release. Measured 0.47 % left (23 dB); with the
        // finger held the string loses 0.6 dB in 40 ms, so the 10 dB are the lift's.
        assert!(last < 0.1 * start, "{last} of {start}");
    }
}
