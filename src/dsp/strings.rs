//! One four-string instrument, generic over the string model and its bridge: the
//! point-bow [`super::instrument::Instrument`] (paper A's waveguide strings on a body) and
//! paper B's [`super::thermal_instrument::ThermalInstrument`] (two-polarisation strings
//! under a finite-width thermal bow, coupled at a modal bridge) are both
//! [`FourStrings`], each over its own [`StringBank`].
//!
//! What exists once, here: which string a note goes to and where the finger stops it
//! ([`Fingering`]), the bow landing and lifting on each string ([`BowEnvelope`]), the
//! note's own expression and the per-string force weighting turned into each string's
//! bow, the finger's glide, the pitch bend and reference pitch retuning what sounds, the
//! resampler from the strings' internal rate to the host's, sleeping, the host's tail,
//! the fade around a change of discretisation, and the guard that turns a non-finite
//! sample into silence. What the bank keeps: its strings, how one is stopped and
//! retuned, how a sample is computed, and how its parts fall asleep.
//!
//! **Rates.** The bow envelope's ramp over [`BOW_RAMP_S`], the glide's steps and each
//! string's bow move once per internal sample, inside the resampler's pull: with the
//! host's bow held over a host sample, the strings meet the same inputs at every host
//! rate, so a note's regime and pitch do not depend on the project's rate (the
//! resampler is all that differs). Once per host sample: the output's fade, the
//! non-finite guard and the probe.
//!
//! ```
//! use colophony::dsp::instrument::Instrument;
//! use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
//! // The point-bow instrument is `FourStrings<WaveguideBank>`.
//! let mut violin = Instrument::new(InstrumentKind::Violin, 44_100.0);
//! assert_eq!(violin.note_on(69), Some(2)); // A4 on the A string
//! let bow = BowControl { velocity_m_per_s: 0.2, force_n: 0.5, position_beta: 0.12 };
//! let peak = (0..22_050).map(|_| violin.tick(bow).audio.abs()).fold(0.0, f64::max);
//! assert!(peak > 0.01 && peak < 1.0);
//! violin.note_off(69);
//! ```

use super::body::{body_for, BodyModes, FadingBody};
use super::filters::flush_tiny;
use super::fingering::{BowEnvelope, Fingering};
use super::friction::law;
use super::intonation::IntonationTable;
use super::radiation::Radiation;
use super::resample::Resampler;
use super::vocabulary::{
    BowControl, Frame, InstrumentKind, NoteExpression, Pluck, Strike, BOW_RAMP_S, MAX_NOTE_BETA,
    MAX_WEIGHTED_FORCE_N, MIN_NOTE_BETA, STRINGS,
};

/// The bow on one string for one host sample, as the bank takes it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StringBow {
    /// Signed bow velocity, m/s.
    pub velocity_m_per_s: f64,
    /// Normal force in the bank's unit ([`StringBank::force_divisor`]: N for a point bow,
    /// N/m spread over a bow's width), the envelope and expression applied.
    pub force: f64,
    /// Bow position over the vibrating length.
    pub position_beta: f64,
}

/// The strings and bridge of one four-string instrument at their internal rate (see the
/// module doc for what stays in [`FourStrings`]).
pub trait StringBank {
    /// The discretisation whose change rebuilds the strings (paper B's node count and bow
    /// width; `()` where nothing does).
    type Settings: Copy + PartialEq + std::fmt::Debug;

    /// The rate [`StringBank::sample`] runs at, Hz.
    fn internal_rate_hz(&self) -> f64;
    /// Whether [`StringBank::sample`]'s output is already flushed of subnormals (then,
    /// without a resampler, it is not flushed again).
    const SAMPLE_IS_FLUSHED: bool = false;
    /// Whether [`StringBank::sample`] already gives the sound through the instrument's
    /// body (the point-bow bank's modes). Where it gives the force on the bridge (paper
    /// B's modal bridge), [`FourStrings`] passes it through the same body at the host
    /// rate ([`super::body::body_for`], a mute loading it as it does the bank's).
    const HAS_BODY: bool = false;
    /// The impedance of the string the force parameter is the force on when the strings
    /// are weighted ([`FourStrings::set_string_weighting`]), kg/s: string `i` is bowed
    /// with the force times its `Z0` over this.
    const WEIGHT_REFERENCE_Z0: f64 = crate::dsp::vocabulary::WEIGHT_REFERENCE_Z0;
    /// The intonation table's row that tunes a plucked or struck note's free ring
    /// ([`Fingering::set_free_row`]); `None` where a string rings where it is tuned.
    const FREE_PITCH_ROW: Option<usize> = None;
    /// The bow force in newtons is divided by this before it reaches the strings (1 for a
    /// point bow; the bow's width for a bow whose force is per metre).
    fn force_divisor(&self) -> f64 {
        1.0
    }
    /// What multiplies the resampled output (the bank's own output scale where it is
    /// applied after resampling; 1 where [`StringBank::sample`] already gives audio).
    fn output_gain(&self) -> f64 {
        1.0
    }
    /// Stops string `i` for a new note sounding `hz`; false if it cannot (the note is
    /// then refused and the string is as before, or silenced).
    fn stop(&mut self, i: usize, hz: f64) -> bool;
    /// Moves string `i`'s sounding note to `hz` (a bend, a glide, a new reference); false
    /// if the string cannot follow (its bow is then lifted).
    fn bend(&mut self, i: usize, hz: f64) -> bool;
    /// The stopping finger has left string `i`: it sounds `hz` (its open pitch), the part
    /// between the old stopping point and the nut at rest; false as [`StringBank::stop`].
    fn release_finger(&mut self, i: usize, hz: f64) -> bool;
    /// The stopping finger's reflection on string `i`, 0..=1 (1: pressed; less while it
    /// leaves the string). Only takes energy out.
    fn set_finger_reflection(&mut self, i: usize, reflection: f64);
    /// A mute on the bridge (con sordino) or none; banks without one ignore it.
    fn set_mute(&mut self, _on: bool) {}
    /// Whether [`StringBank::touch`] touches.
    const TOUCHABLE: bool = false;
    /// A light finger touches string `i` at the node of its partial `partial` nearest the
    /// bridge (a harmonic), or leaves it (`None`), as
    /// [`super::waveguide::WaveguideString::set_touch`] with a resistance of
    /// [`HARMONIC_FINGER_RESISTANCE_Z0`] times the string's impedance; the string's
    /// stopped pitch stays, its partial sounds at that many times it. Banks that cannot
    /// touch ignore it.
    fn touch(&mut self, _i: usize, _partial: Option<u32>) {}
    /// A harmonic on partial `n` is bowed `sqrt(n)` times nearer the bridge than the
    /// asked position, not `n` times (the part between the bridge and the finger bowed
    /// where a stopped string of that length would be).
    const HARMONIC_BOW_AT_ROOT: bool = false;
    /// Whether [`StringBank::pluck`] plucks.
    const PLUCKABLE: bool = false;
    /// Plucks string `i` (pizzicato) as [`super::waveguide::WaveguideString::pluck`]:
    /// `width` is the finger's contact over the vibrating length. False where the bank's
    /// strings cannot be plucked (nothing changes).
    fn pluck(&mut self, _i: usize, _displacement_m: f64, _position_beta: f64, _width: f64) -> bool {
        false
    }
    /// Strikes string `i` at its bow point with the bow's stick (col legno battuto) as
    /// [`super::waveguide::WaveguideString::strike`]. False where the bank's strings cannot
    /// be struck (nothing changes); banks that pluck strike too.
    fn strike(&mut self, _i: usize, _strike: Strike) -> bool {
        false
    }
    /// A bow landed on string `i`: it is computed from the next sample.
    fn wake(&mut self, i: usize);
    /// Whether string `i` is being computed (bowed, or ringing on).
    fn string_awake(&self, i: usize) -> bool;
    /// Whether anything is computed: a string, or the bridge or body ringing on.
    fn is_awake(&self) -> bool;
    /// Whether the strings themselves are awake (not only the body).
    fn strings_awake(&self) -> bool {
        (0..STRINGS).any(|i| self.string_awake(i))
    }
    /// Whether sleeping strings are skipped (off only to measure the saving).
    fn set_skipping(&mut self, skipping: bool);
    /// One internal sample: the output before [`StringBank::output_gain`]. `bow_of(i)`
    /// gives string `i`'s bow (and moves its envelope): call it once for each string
    /// computed, in order, and not for a string that sleeps. `probed`: the string whose
    /// contact [`StringBank::probe`] reports.
    fn sample(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64;
    /// [`StringBank::sample`] inlined where it is called: for a bank's own
    /// [`StringBank::samples`] loop.
    #[inline(always)]
    fn sample_inline(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        self.sample(probed, bow_of)
    }
    /// The strings' part of [`StringBank::sample_inline`] for a bank whose
    /// [`StringBank::samples`] runs the rest over the block (what the rest takes is the
    /// bank's own). `SHAPE`: what the bank found true of the whole block (its friction
    /// law, how many strings it computes), in the bank's own code, compiled into the
    /// block's loop.
    #[inline(always)]
    fn strings_inline<const SHAPE: u8>(
        &mut self,
        probed: usize,
        bow_of: impl FnMut(usize) -> StringBow,
    ) -> f64 {
        self.sample_inline(probed, bow_of)
    }
    /// Internal samples into `out`, each computed by `step`: the samples of a loop of
    /// `step.tick(self)`, in one call for the block (a bank runs its strings in that loop
    /// without a call a sample).
    #[inline(always)]
    fn samples(&mut self, out: &mut [f64], step: &mut impl InternalSample<Self>)
    where
        Self: Sized,
    {
        for sample in out {
            *sample = step.tick(self);
        }
    }
    /// The internal samples `out.len()` host samples need, through `resampler`, each
    /// computed by `step` (which sets the bows, moving at the internal rate, and calls
    /// [`StringBank::sample`]).
    #[inline(always)]
    fn render(
        &mut self,
        resampler: &mut Resampler,
        out: &mut [f64],
        mut step: impl InternalSample<Self>,
    ) where
        Self: Sized,
    {
        resampler.process(|| step.tick(self), out);
    }
    /// The probed string's last internal sample: velocity at the bow and friction force.
    fn probe(&self) -> (f64, f64);
    /// Once per block, with which strings' bows are lifted and at rest: puts quiet parts
    /// to sleep. Returns whether everything sleeps now (what the resampler holds is then
    /// cleared).
    fn sleep(&mut self, lifted: &[bool; STRINGS]) -> bool;
    /// Seconds until everything would sleep with every bow lifted (`None` while a bow is
    /// on an awake string); walks the delay lines.
    fn ring_out_s(&self, lifted: &[bool; STRINGS]) -> Option<f64>;
    /// Total energy of the strings (and the bridge where it stores any), J.
    fn energy_j(&self) -> f64;
    /// Silences everything.
    fn reset(&mut self);
    /// The current discretisation.
    fn settings(&self) -> Self::Settings;
    /// Rebuilds the strings for `settings` (silenced, asleep; no allocation): the caller
    /// re-lands the held notes. On an error nothing changed.
    fn configure(&mut self, settings: Self::Settings) -> Result<(), String>;
}

/// A violin, viola, cello or double bass: four strings of one model on one bridge, played by notes
/// and one bow (see the module doc).
#[derive(Debug, Clone)]
pub struct FourStrings<B: StringBank> {
    pub(super) bank: B,
    pub(super) kind: InstrumentKind,
    /// Fingers and bow on each string.
    pub(super) hands: Hands,
    /// From the internal rate to the host's; `None` where they are the same. Boxed: the
    /// instrument moves as a whole when the performer swaps engines.
    pub(super) resampler: Option<Box<Resampler>>,
    /// The rate [`FourStrings::tick`] is called at, Hz.
    host_rate_hz: f64,
    /// Whether quiet lifted strings sleep (the default; off only to measure the saving).
    skipping: bool,
    /// Times the non-finite guard in [`FourStrings::tick`] reset the instrument.
    recoveries: u64,
    /// A change of discretisation waiting for the fade-out to end.
    pending: Option<B::Settings>,
    fade: f64,
    fade_step: f64,
    /// The body at the host rate for a bank without one (`!B::HAS_BODY`), fading to a
    /// mute's modes and back; unused otherwise.
    body: FadingBody,
    /// A mute on the bridge (con sordino).
    muted: bool,
    /// The sound leaving the body at the host rate ([`Radiation`]).
    radiation: Radiation,
}

/// The player's hands on the four strings: the notes and fingers, and the bow on each
/// string, moved once per internal sample ([`Hands::step`]).
#[derive(Debug, Clone)]
pub(super) struct Hands {
    /// Notes, fingers and tuning.
    pub(super) fingering: Fingering,
    /// The bow on each string.
    pub(super) bows: [BowEnvelope; STRINGS],
    /// Whether each string's note has an expression of its own (one test a sample).
    expressive: [bool; STRINGS],
    /// The bow force's factor on each string when weighted ([`InstrumentKind::string_weight`]).
    weights: [f64; STRINGS],
    /// Whether the bow force is weighted per string ([`FourStrings::set_string_weighting`]).
    weighted: bool,
    /// The string the last note went to (the probe's).
    pub(super) probed: usize,
    /// The bow envelope's step per internal sample.
    ramp_step: f64,
    /// Internal samples left of each string's finger lift (0: none under way).
    pub(super) lifts: [u32; STRINGS],
    /// Whether any finger is lifting (one test a sample otherwise).
    pub(super) lifting: bool,
    /// A finger lift's length in internal samples ([`FINGER_LIFT_S`]).
    pub(super) lift_samples: u32,
    /// Each string's open note.
    open_notes: [u8; STRINGS],
    /// Whether released notes keep their fingers down ([`FourStrings::set_fingers_held`]).
    fingers_held: bool,
    /// Whether each string rings free: released, no finger on it (lifted, or an open
    /// string's note): the left hand's bend and vibrato no longer reach it.
    free: [bool; STRINGS],
}

/// One internal sample's work, handed to [`StringBank::render`]: a type with an
/// always-inlined method rather than a closure, because a closure made outside a bank's
/// `#[target_feature]` loop is compiled as its own function without the feature, and the
/// per-sample work would run as baseline SSE2 code.
pub trait InternalSample<B> {
    /// Sets the bows for one internal sample and computes it.
    fn tick(&mut self, bank: &mut B) -> f64;
    /// [`InternalSample::tick`] through [`StringBank::strings_inline`]: the strings' part
    /// of the sample only, for a bank that runs the rest over the block; `SHAPE` as there.
    #[inline(always)]
    fn tick_strings<const SHAPE: u8>(&mut self, bank: &mut B) -> f64 {
        self.tick(bank)
    }
    /// Each string's bow and the probed string, when every sample this computes bows
    /// the same ([`SteadyBows`]): a bank may then set them once for its whole block.
    #[inline(always)]
    fn steady(&self) -> Option<(&[StringBow; STRINGS], usize)> {
        None
    }
}

/// The player's hands with the bow of this host sample: [`InternalSample`] for
/// [`FourStrings::tick`] (`INLINE` false) and, with the bank's sample inlined into the
/// bank's loop, for a block's [`StringBank::samples`] (`INLINE` true).
struct HandsSample<'a, const INLINE: bool> {
    hands: &'a mut Hands,
    bow: BowControl,
}

impl<B: StringBank, const INLINE: bool> InternalSample<B> for HandsSample<'_, INLINE> {
    #[inline(always)]
    fn tick(&mut self, bank: &mut B) -> f64 {
        self.hands
            .tick::<B, INLINE, false, { law::ANY }>(bank, self.bow)
    }

    #[inline(always)]
    fn tick_strings<const SHAPE: u8>(&mut self, bank: &mut B) -> f64 {
        self.hands.tick::<B, true, true, SHAPE>(bank, self.bow)
    }
}

/// Each string's bow over a block in which nothing moves it ([`Hands::steady_bows`]):
/// [`InternalSample`] without the hands' per-sample work.
struct SteadyBows {
    bows: [StringBow; STRINGS],
    probed: usize,
}

impl<B: StringBank> InternalSample<B> for SteadyBows {
    #[inline(always)]
    fn tick(&mut self, bank: &mut B) -> f64 {
        let bows = self.bows;
        bank.sample_inline(self.probed, move |i| bows[i % STRINGS])
    }

    #[inline(always)]
    fn tick_strings<const SHAPE: u8>(&mut self, bank: &mut B) -> f64 {
        let bows = self.bows;
        bank.strings_inline::<SHAPE>(self.probed, move |i| bows[i % STRINGS])
    }

    #[inline(always)]
    fn steady(&self) -> Option<(&[StringBow; STRINGS], usize)> {
        Some((&self.bows, self.probed))
    }
}

impl Hands {
    /// Each string's bow for a block played with the player's bow `bow`, where nothing in
    /// the hands moves within it: no finger lifting or gliding, every bow's ramp arrived.
    /// The bows [`Hands::tick`] would give each sample of the block (a settled ramp's step
    /// changes nothing); `None` while something moves.
    fn steady_bows<B: StringBank>(
        &mut self,
        bank: &B,
        bow: BowControl,
    ) -> Option<[StringBow; STRINGS]> {
        if self.lifting
            || self.fingering.is_gliding()
            || !self.bows.iter().all(BowEnvelope::is_settled)
        {
            return None;
        }
        let divisor = bank.force_divisor();
        Some(std::array::from_fn(|i| {
            self.string_bow(i, bow, divisor, B::HARMONIC_BOW_AT_ROOT)
        }))
    }

    /// One internal sample of `bank` with the player's bow `bow`: the finger's glide, then
    /// the bank's sample, asking for each string's bow as it computes it (the envelope,
    /// the weighting and the note's expression on the shared bow). `INLINE`: the bank's
    /// sample inlined here ([`StringBank::sample_inline`]).
    #[inline(always)]
    fn tick<B: StringBank, const INLINE: bool, const STRINGS_ONLY: bool, const SHAPE: u8>(
        &mut self,
        bank: &mut B,
        bow: BowControl,
    ) -> f64 {
        if self.lifting {
            self.lift_tick(bank);
        }
        if let Some(retune) = self.fingering.glide_tick() {
            for (i, hz) in retune.into_iter().enumerate() {
                if let Some(hz) = hz {
                    if !bank.bend(i, hz) {
                        self.bows[i].bowed = false;
                    }
                }
            }
        }
        let divisor = bank.force_divisor();
        let probed = self.probed;
        let bow_of = move |i| self.string_bow(i, bow, divisor, B::HARMONIC_BOW_AT_ROOT);
        if STRINGS_ONLY {
            bank.strings_inline::<SHAPE>(probed, bow_of)
        } else if INLINE {
            bank.sample_inline(probed, bow_of)
        } else {
            bank.sample(probed, bow_of)
        }
    }

    /// One internal sample of the lifting fingers: each one's reflection dips to
    /// [`FINGER_LIFT_MIN_REFLECTION`] and comes back over [`FINGER_LIFT_S`] (half a sine);
    /// then the finger is off and the string sounds open.
    #[cold]
    fn lift_tick<B: StringBank>(&mut self, bank: &mut B) {
        let mut any = false;
        for i in 0..STRINGS {
            let left = self.lifts[i];
            if left == 0 {
                continue;
            }
            let left = left - 1;
            self.lifts[i] = left;
            if left == 0 {
                self.free[i] = true;
                bank.set_finger_reflection(i, 1.0);
                bank.touch(i, None);
                self.fingering.set_partial(i, 1);
                self.fingering.start(i, self.open_notes[i]);
                self.expressive[i] = false;
                if !bank.release_finger(i, self.fingering.tuned_hz(i)) {
                    self.bows[i].bowed = false;
                }
            } else {
                any = true;
                let progress = 1.0 - left as f64 / self.lift_samples as f64;
                let dip = (std::f64::consts::PI * progress).sin();
                bank.set_finger_reflection(i, 1.0 - (1.0 - FINGER_LIFT_MIN_REFLECTION) * dip);
            }
        }
        self.lifting = any;
    }

    /// Starts lifting the finger from string `i` if a released stopped note holds it; a
    /// released open string rings free at once.
    fn lift_finger(&mut self, i: usize) {
        if self.bows[i].bowed {
            return;
        }
        // A natural harmonic's string is stopped by nothing: it rings on, the touching
        // finger on it, as an open string does.
        match self.fingering.stopped_note(i) {
            Some(n) if n != self.open_notes[i] => {
                if self.lifts[i] == 0 {
                    self.lifts[i] = self.lift_samples;
                    self.lifting = true;
                }
            }
            Some(_) => self.free[i] = true,
            None => {}
        }
    }

    /// Ends a finger lift under way on string `i` (a new note stops the string there):
    /// the finger presses again.
    fn keep_finger<B: StringBank>(&mut self, bank: &mut B, i: usize) {
        self.free[i] = false;
        if self.lifts[i] != 0 {
            self.lifts[i] = 0;
            bank.set_finger_reflection(i, 1.0);
        }
    }

    /// String `i`'s bow for this internal sample (its envelope moves one step).
    #[inline(always)]
    fn string_bow(
        &mut self,
        i: usize,
        bow: BowControl,
        divisor: f64,
        harmonic_at_root: bool,
    ) -> StringBow {
        let gain = self.bows[i].tick(self.ramp_step);
        // Weighted, a string is never bowed harder than the force parameter's top.
        let base = if self.weighted {
            (bow.force_n * self.weights[i]).min(MAX_WEIGHTED_FORCE_N)
        } else {
            bow.force_n
        };
        let base = base / divisor;
        if !self.expressive[i] {
            StringBow {
                velocity_m_per_s: bow.velocity_m_per_s,
                force: base * gain,
                position_beta: bow.position_beta,
            }
        } else {
            let e = self.fingering.expression(i);
            // A harmonic is bowed as its part between the bridge and the touching finger
            // would be as a stopped string: that much nearer the bridge (or by the square
            // root of the partial, [`StringBank::HARMONIC_BOW_AT_ROOT`]).
            let partial = self.fingering.partial(i) as f64;
            let (lighter, nearer) = if partial > 1.0 {
                let nearer = if harmonic_at_root {
                    partial.sqrt()
                } else {
                    partial
                };
                (HARMONIC_FORCE_SCALE, nearer)
            } else {
                (1.0, 1.0)
            };
            StringBow {
                velocity_m_per_s: bow.velocity_m_per_s,
                force: base * e.force_scale * gain * lighter,
                position_beta: (bow.position_beta * e.position_scale)
                    .clamp(MIN_NOTE_BETA, MAX_NOTE_BETA)
                    / nearer,
            }
        }
    }
}

/// The resistance of a light finger touching a string for a harmonic, in units of the
/// string's impedance: `R = 2 Z0` passes half of a wave through the finger, reflects a
/// quarter of its energy and takes the rest out, so the partials without a node there die
/// within a few passes. A choice: no measured fingertip resistance was found.
pub const HARMONIC_FINGER_RESISTANCE_Z0: f64 = 2.0;

/// A harmonic is bowed with this share of the asked force: a lighter bow, as players bow
/// harmonics. A choice: of 0.3, 0.5, 0.7 and 1, measured through the performer at the
/// defaults (103 natural and artificial harmonics over the four instruments, each at its
/// free partial), 0.5 and 0.7 sounded the most within 10 cents (99 of 103, against 75 at
/// 1), and 0.5 leaves the most room under the window's top.
pub const HARMONIC_FORCE_SCALE: f64 = 0.5;

/// Fade-out before the strings are rebuilt for a new discretisation, s.
pub const RECONFIGURE_FADE_S: f64 = 0.01;

/// The bow envelope's step per internal sample at `rate_hz`.
fn ramp_step(rate_hz: f64) -> f64 {
    1.0 / (BOW_RAMP_S * rate_hz).max(1.0)
}

/// How long a stopping finger takes to leave the string when its note is released, s.
pub const FINGER_LIFT_S: f64 = 0.04;
/// The lowest reflection of a leaving finger, halfway through its lift: its pad, no
/// longer pressed to the fingerboard, damps the string instead of stopping it.
pub const FINGER_LIFT_MIN_REFLECTION: f64 = 0.1;

/// A finger lift's length in internal samples at `rate_hz` (at least 2).
fn lift_samples(rate_hz: f64) -> u32 {
    (FINGER_LIFT_S * rate_hz)
        .round()
        .clamp(2.0, u32::MAX as f64) as u32
}

impl<B: StringBank> FourStrings<B> {
    /// `bank` played at `host_rate_hz` (finite and positive: the constructors check),
    /// through `resampler` where the rates differ. `intonation_row`: the shipped
    /// intonation table's row the notes are tuned by.
    pub(super) fn from_bank(
        bank: B,
        kind: InstrumentKind,
        host_rate_hz: f64,
        resampler: Option<Box<Resampler>>,
        intonation_row: usize,
    ) -> Self {
        let internal_rate_hz = bank.internal_rate_hz();
        let mut fingering = Fingering::new(kind, Some(intonation_row));
        fingering.set_free_row(B::FREE_PITCH_ROW);
        Self {
            bank,
            kind,
            hands: Hands {
                fingering,
                bows: [BowEnvelope::default(); STRINGS],
                expressive: [false; STRINGS],
                weights: std::array::from_fn(|i| kind.string_weight_for(i, B::WEIGHT_REFERENCE_Z0)),
                weighted: false,
                probed: 0,
                ramp_step: ramp_step(internal_rate_hz),
                lifts: [0; STRINGS],
                lifting: false,
                lift_samples: lift_samples(internal_rate_hz),
                open_notes: kind.open_notes(),
                fingers_held: false,
                free: [false; STRINGS],
            },
            resampler,
            host_rate_hz,
            skipping: true,
            recoveries: 0,
            pending: None,
            fade: 1.0,
            fade_step: 1.0 / (RECONFIGURE_FADE_S * host_rate_hz).max(1.0),
            body: FadingBody::new(
                super::body::body_for(kind, None, false, host_rate_hz),
                host_rate_hz,
            ),
            muted: false,
            radiation: Radiation::new(kind.a0_hz(), host_rate_hz),
        }
    }

    /// The body a bank without one plays at the host rate: the instrument's generic
    /// modes (with a chosen bridge too: paper B's model plays the bridge itself, and its
    /// sound leaves through the instrument's body), loaded by the mute if on.
    fn host_body(&self) -> BodyModes {
        body_for(self.kind, None, self.muted, self.host_rate_hz)
    }

    pub fn kind(&self) -> InstrumentKind {
        self.kind
    }

    /// The host rate [`FourStrings::tick`] runs at.
    pub fn sample_rate_hz(&self) -> f64 {
        self.host_rate_hz
    }

    /// The rate the strings run at.
    pub fn internal_rate_hz(&self) -> f64 {
        self.bank.internal_rate_hz()
    }

    /// How late the output is behind the strings, host samples (the resampler's delay;
    /// 0 at the internal rate).
    pub fn latency_samples(&self) -> f64 {
        self.resampler.as_ref().map_or(0.0, |r| r.latency_samples())
    }

    /// Weights the bow force per string (on: string `i` is bowed with the force times
    /// its impedance over the bank's [`StringBank::WEIGHT_REFERENCE_Z0`], never more than
    /// [`MAX_WEIGHTED_FORCE_N`];
    /// off, the default: every string gets the force as given, the bare model the tools
    /// measure). The performer turns it on for the player (the String Weight parameter).
    pub fn set_string_weighting(&mut self, on: bool) {
        self.hands.weighted = on;
    }

    /// Whether the bow force is weighted per string.
    pub fn string_weighting(&self) -> bool {
        self.hands.weighted
    }

    /// Another instrument's notes, weights and bows (the bank changes its strings).
    pub(super) fn set_kind_notes(&mut self, kind: InstrumentKind) {
        self.kind = kind;
        self.hands.fingering.set_kind(kind);
        self.hands.bows = [BowEnvelope::default(); STRINGS];
        self.hands.expressive = [false; STRINGS];
        self.hands.weights =
            std::array::from_fn(|i| kind.string_weight_for(i, B::WEIGHT_REFERENCE_Z0));
        self.hands.open_notes = kind.open_notes();
        self.hands.free = [false; STRINGS];
        self.radiation.retune(kind.a0_hz(), self.host_rate_hz);
        if !B::HAS_BODY {
            self.body.playing = self.host_body();
        }
        self.press_every_finger();
    }

    /// Ends every finger lift under way.
    fn press_every_finger(&mut self) {
        for i in 0..STRINGS {
            self.hands.keep_finger(&mut self.bank, i);
        }
        self.hands.lifting = false;
    }

    /// Stops the string for `note` and lands the bow on it. Returns the string, or `None`
    /// if no string can play the note (it is then ignored).
    pub fn note_on(&mut self, note: u8) -> Option<usize> {
        let index = self.stop_for(note, false)?;
        self.hands.bows[index].bowed = true;
        self.bank.wake(index);
        self.hands.probed = index;
        Some(index)
    }

    /// Puts a mute on the bridge (con sordino) or takes it off: the bridge's modes carry
    /// its mass ([`super::body::muted`]; on the thermal model's modal bridge
    /// [`super::body::muted_bridge_mode`]).
    pub fn set_mute(&mut self, on: bool) {
        self.bank.set_mute(on);
        if !B::HAS_BODY && on != self.muted {
            self.muted = on;
            let body = self.host_body();
            self.body.fade_to(&body, self.host_rate_hz);
        }
    }

    /// Stops the string for `note` and plucks it there (pizzicato): no bow lands, and a
    /// bow on that string lifts. The string rings until the note is released, when the
    /// finger lifts as after a bowed note. Returns the string, or `None` if no string can
    /// play the note or the strings cannot be plucked (then nothing sounds).
    pub fn pluck(&mut self, note: u8, pluck: Pluck) -> Option<usize> {
        self.unbowed(note, |bank, index, vibrating_m| {
            let width = pluck.width_m / vibrating_m;
            // Past the middle of a short stopped string the hand plucks its middle.
            let beta = (pluck.from_bridge_m / vibrating_m).clamp(MIN_NOTE_BETA, 0.5);
            bank.pluck(index, pluck.displacement_m, beta, width)
        })
    }

    /// Stops the string for `note` and strikes it at the bow point with the bow's stick
    /// (col legno battuto): no bow hair lands, and a bow on that string lifts; the string
    /// then rings as a plucked one does. Returns the string, or `None` if no string can
    /// play the note or the strings cannot be struck (then nothing sounds).
    pub fn strike(&mut self, note: u8, strike: Strike) -> Option<usize> {
        self.unbowed(note, |bank, index, _| bank.strike(index, strike))
    }

    /// A note played without the bow (plucked or struck): stops the string for `note`
    /// at its free pitch, lifts any bow from it and hands `excite` the bank, the string
    /// and its vibrating length (m); the string, or `None` if nothing sounds.
    fn unbowed(
        &mut self,
        note: u8,
        excite: impl FnOnce(&mut B, usize, f64) -> bool,
    ) -> Option<usize> {
        if !B::PLUCKABLE {
            return None;
        }
        let index = self.stop_for(note, true)?;
        self.hands.bows[index].bowed = false;
        let open = self.hands.open_notes[index];
        let vibrating_m =
            self.kind.string_length_m() * 2f64.powf(-(note.saturating_sub(open) as f64) / 12.0);
        if !excite(&mut self.bank, index, vibrating_m) {
            return None;
        }
        self.bank.wake(index);
        self.hands.probed = index;
        Some(index)
    }

    /// Chooses the string for `note` and stops it there (the finger down, the note's
    /// expression reset; `plucked`, tuned by its free pitch); `None`, and nothing changed,
    /// if no string can play it.
    fn stop_for(&mut self, note: u8, plucked: bool) -> Option<usize> {
        let index = self.hands.fingering.string_for_note_on(note)?;
        self.stop_on(index, note, plucked, 1)
    }

    /// Stops string `index` for `note` sounding its `partial` (1, or more for a harmonic:
    /// the string stopped that many times under the note; the touching finger is put on
    /// by [`FourStrings::harmonic`]), as [`FourStrings::stop_for`].
    fn stop_on(&mut self, index: usize, note: u8, plucked: bool, partial: u8) -> Option<usize> {
        self.hands.keep_finger(&mut self.bank, index);
        let before = (
            self.hands.fingering.note(index),
            self.hands.fingering.expression(index),
            self.hands.fingering.partial(index),
        );
        self.bank.touch(index, None);
        self.hands.fingering.start(index, note);
        self.hands.fingering.set_plucked(index, plucked);
        self.hands.fingering.set_partial(index, partial);
        let hz = self.hands.fingering.tuned_hz(index);
        if !self.bank.stop(index, hz) {
            self.hands.fingering.restore(index, before.0, before.1);
            self.hands.fingering.set_partial(index, before.2);
            return None;
        }
        self.hands.expressive[index] = partial > 1;
        Some(index)
    }

    /// Bows `note` as a harmonic ([`InstrumentKind::harmonic_for`]): its string stopped at
    /// the note's pitch over the harmonic's partial (an open string for a natural
    /// harmonic, the note two octaves down for an artificial one), a light finger at that
    /// partial's node nearest the bridge, and the bow that much nearer the bridge, as a
    /// player bows a harmonic. The note sounds the partial, tuned as a stopped note bowed
    /// at its pitch. Released, an artificial harmonic's stopping finger lifts as after
    /// any stopped note; a natural harmonic rings on. `None` (nothing changed) if no
    /// harmonic plays the note or the strings cannot be touched.
    pub fn harmonic(&mut self, note: u8) -> Option<usize> {
        if !B::TOUCHABLE {
            return None;
        }
        let fingering = self.hands.fingering.harmonic_for(note)?;
        let index = self.stop_on(fingering.string, note, false, fingering.partial)?;
        self.bank.touch(index, Some(fingering.partial as u32));
        self.hands.bows[index].bowed = true;
        self.bank.wake(index);
        self.hands.probed = index;
        Some(index)
    }

    /// A legato note that slides the finger (portamento): on a string already bowed with
    /// another note, the stopping point glides from that note's place to this one over
    /// `glide_s` seconds (linearly in semitones, retuned every
    /// [`GLIDE_EVERY`](super::fingering::GLIDE_EVERY) samples at 48 kHz); otherwise, or with
    /// `glide_s` not positive, as [`FourStrings::note_on`].
    pub fn note_on_gliding(&mut self, note: u8, glide_s: f64) -> Option<usize> {
        let index = self.hands.fingering.string_for_note_on(note)?;
        self.hands.keep_finger(&mut self.bank, index);
        let from = match self.hands.fingering.note(index) {
            Some(old)
                if self.hands.bows[index].bowed
                    && self.bank.string_awake(index)
                    && self.pending.is_none()
                    && glide_s > 0.0
                    && glide_s.is_finite() =>
            {
                old as f64 + self.hands.fingering.glide(index)
            }
            _ => return self.note_on(note),
        };
        let distance = from - note as f64;
        let rate = self.bank.internal_rate_hz();
        self.hands
            .fingering
            .glide_to(index, note, distance, glide_s, rate);
        self.hands.probed = index;
        let hz = self.hands.fingering.tuned_hz(index);
        if !self.bank.bend(index, hz) {
            self.hands.bows[index].bowed = false;
        }
        Some(index)
    }

    /// Lifts the bow from the string playing `note`, if any, and the finger that stops it
    /// (an open string rings on; a stopped one is damped by the leaving finger, then rings
    /// open and quiet: [`FINGER_LIFT_S`]). A new note on the string during the lift keeps
    /// the finger down.
    pub fn note_off(&mut self, note: u8) {
        let hands = &mut self.hands;
        for i in 0..STRINGS {
            if hands.fingering.note(i) == Some(note) {
                hands.bows[i].bowed = false;
                if !hands.fingers_held {
                    hands.lift_finger(i);
                }
            }
        }
    }

    /// Whether released notes keep their fingers down (the sustain pedal, and how the
    /// free decay of a stopped note is measured): held, a note-off lifts only the bow
    /// and the string rings on at its stopped pitch; let go, the fingers of the released
    /// notes lift.
    pub fn set_fingers_held(&mut self, held: bool) {
        let was = std::mem::replace(&mut self.hands.fingers_held, held);
        if was && !held {
            for i in 0..STRINGS {
                self.hands.lift_finger(i);
            }
        }
    }

    /// Lifts the bow from every string, and the fingers as [`FourStrings::note_off`] does
    /// (unless they are held down).
    pub fn all_notes_off(&mut self) {
        for bow in &mut self.hands.bows {
            bow.bowed = false;
        }
        if !self.hands.fingers_held {
            for i in 0..STRINGS {
                self.hands.lift_finger(i);
            }
        }
    }

    /// Asks later notes to go to string `preferred` (0 = the lowest) where it can play
    /// them ([`InstrumentKind::string_for_note_on`]); `None` restores the usual choice.
    /// Notes already sounding stay where they are.
    pub fn set_preferred_string(&mut self, preferred: Option<usize>) {
        self.hands.fingering.set_preferred_string(preferred);
    }

    /// Pitch bend in semitones (clamped to the bend range): moves every stopping point,
    /// as far as the string reaches ([`super::intonation::tuned_hz`]).
    pub fn set_pitch_bend(&mut self, semitones: f64) {
        if self.hands.fingering.set_pitch_bend(semitones) {
            self.retune();
        }
    }

    /// The dynamics' expression the bow is played at (0..=1, with the Dynamics Guard's
    /// bow): the intonation follows it ([`super::intonation::SOFT_EXPRESSIONS`]);
    /// sounding notes retune when it has moved far enough.
    pub fn set_dynamics(&mut self, expression: f64) {
        if self.hands.fingering.set_dynamics(expression) {
            self.retune();
        }
    }

    /// Gives string `index` its note's own expression (sanitized; see
    /// [`NoteExpression`]); a changed bend retunes it at once (a bend the string cannot
    /// follow lifts its bow). A new note on the string starts neutral again.
    pub fn set_note_expression(&mut self, index: usize, expression: NoteExpression) {
        if index >= STRINGS {
            return;
        }
        let bent = self.hands.fingering.set_expression(index, expression);
        self.hands.expressive[index] = self.hands.fingering.expression(index)
            != NoteExpression::NEUTRAL
            || self.hands.fingering.partial(index) > 1;
        if bent {
            let hz = self.hands.fingering.tuned_hz(index);
            if !self.bank.bend(index, hz) {
                self.hands.bows[index].bowed = false;
            }
        }
    }

    /// String `index`'s note expression.
    pub fn note_expression(&self, index: usize) -> NoteExpression {
        self.hands.fingering.expression(index)
    }

    /// Tunes every note from the reference pitch `a4_hz` (415..466 Hz; see
    /// [`super::vocabulary::reference_semitones`]); sounding notes follow at once.
    pub fn set_reference_pitch(&mut self, a4_hz: f64) {
        if self.hands.fingering.set_reference_pitch(a4_hz) {
            self.retune();
        }
    }

    /// Tunes by the bowed sound with `table` (the default is the shipped one), or by the
    /// free decay with `None` (paper A's scenes, the free-string tuning tests). Sounding
    /// notes follow at once.
    pub fn set_intonation(&mut self, table: Option<&'static IntonationTable>) {
        self.hands.fingering.set_intonation(table);
        self.retune();
    }

    /// Moves every stopped note to its pitch under the current bend and reference; a
    /// string that cannot follow has its bow lifted and rings on.
    pub(super) fn retune(&mut self) {
        for i in 0..STRINGS {
            if self.hands.fingering.note(i).is_some() && !self.hands.free[i] {
                let hz = self.hands.fingering.tuned_hz(i);
                if !self.bank.bend(i, hz) {
                    self.hands.bows[i].bowed = false;
                }
            }
        }
    }

    /// How far the bow rests on string `index`: 0 lifted, 1 fully on (it ramps between
    /// over [`BOW_RAMP_S`]); 0 for a string that does not exist.
    pub fn bow_gain(&self, index: usize) -> f64 {
        self.hands.bows.get(index).map_or(0.0, |b| b.gain)
    }

    /// Total energy of the strings (and of the bridge where it stores any), J.
    pub fn energy_j(&self) -> f64 {
        self.bank.energy_j()
    }

    /// Whether any string is awake (bowed or still ringing).
    pub fn is_sounding(&self) -> bool {
        self.bank.strings_awake()
    }

    /// Whether anything still rings: an awake string, or the bridge or body after the
    /// strings slept.
    pub fn is_ringing(&self) -> bool {
        self.bank.is_awake()
    }

    fn lifted(&self) -> [bool; STRINGS] {
        std::array::from_fn(|i| self.hands.bows[i].is_lifted())
    }

    /// Seconds until everything would fall asleep if no bow lands again (the host's
    /// tail), or `None` while a bow is on a string or a change of discretisation is
    /// pending. Walks the delay lines: call once per block.
    pub fn ring_out_s(&self) -> Option<f64> {
        if self.pending.is_some() && self.bank.is_awake() {
            return None;
        }
        self.bank.ring_out_s(&self.lifted())
    }

    /// Puts what is lifted and quiet to sleep. Called once per block by the plugin and
    /// the renderer (it walks the delay lines).
    pub fn update_sleep(&mut self) {
        if !self.skipping || self.pending.is_some() {
            return;
        }
        if self.bank.sleep(&self.lifted()) {
            // What the resampler and the radiation still hold is below -200 dB: asleep
            // is silence.
            if let Some(r) = &mut self.resampler {
                r.reset();
            }
            self.body.reset();
            self.radiation.reset();
        }
    }

    /// Silences every string and forgets every note.
    pub fn reset(&mut self) {
        self.bank.reset();
        self.body.reset();
        self.radiation.reset();
        self.hands.bows = [BowEnvelope::default(); STRINGS];
        self.hands.expressive = [false; STRINGS];
        self.hands.fingering.clear();
        self.hands.free = [false; STRINGS];
        self.press_every_finger();
        if let Some(r) = &mut self.resampler {
            r.reset();
        }
    }

    /// Turns sleeping off (every string is computed every sample) or on. Off only serves
    /// to measure what skipping saves and changes: `colophony bench scenes`.
    pub fn set_skipping(&mut self, skipping: bool) {
        self.skipping = skipping;
        self.bank.set_skipping(skipping);
    }

    /// Whether sleeping strings are skipped (the default; see [`FourStrings::set_skipping`]).
    pub fn is_skipping(&self) -> bool {
        self.skipping
    }

    /// How often the non-finite guard in [`FourStrings::tick`] has fired (it never should:
    /// the stress suite asserts zero, since the guard would otherwise hide a NaN).
    pub fn recoveries(&self) -> u64 {
        self.recoveries
    }

    /// Asks for a new discretisation. If the instrument sounds, the output fades out
    /// first and the change lands after [`RECONFIGURE_FADE_S`].
    pub(super) fn request_settings(&mut self, settings: B::Settings) {
        if settings == self.bank.settings() && self.pending.is_none() {
            return;
        }
        if self.bank.is_awake() {
            self.pending = Some(settings);
        } else {
            // Within the limits every setting is valid; keep the old one if not.
            let _ = self.apply_settings(settings);
        }
    }

    /// Rebuilds the strings for `settings` now; the held notes' bows land again.
    pub(super) fn apply_settings(&mut self, settings: B::Settings) -> Result<(), String> {
        self.bank.configure(settings)?;
        self.hands.ramp_step = ramp_step(self.bank.internal_rate_hz());
        self.hands.lift_samples = lift_samples(self.bank.internal_rate_hz());
        if let Some(r) = &mut self.resampler {
            // Within its capacity: the bank's rates are bounded at construction.
            let _ = r.set_input_rate(self.bank.internal_rate_hz());
        }
        let reference = 2f64.powf(self.hands.fingering.reference_semitones() / 12.0);
        for i in 0..STRINGS {
            self.hands.bows[i].gain = 0.0;
            let hz = match self.hands.fingering.note(i) {
                Some(_) => self.hands.fingering.tuned_hz(i),
                None => self.kind.strings()[i].open_hz * reference,
            };
            if !self.bank.stop(i, hz) {
                self.hands.bows[i] = BowEnvelope::default();
                self.hands.fingering.clear_string(i);
                self.hands.expressive[i] = false;
            }
        }
        for i in 0..STRINGS {
            if self.hands.bows[i].bowed {
                self.bank.wake(i);
            }
        }
        Ok(())
    }

    /// One host sample: the internal samples it needs, resampled (the bows hold over
    /// them), or one internal sample where the rates are the same.
    #[inline]
    pub fn tick(&mut self, bow: BowControl) -> Frame {
        if self.skipping && !self.bank.is_awake() {
            // Silence; the resampler was cleared when the instrument fell asleep.
            return Frame::default();
        }
        if let Some(settings) = self.pending {
            self.fade -= self.fade_step;
            if self.fade <= 0.0 {
                self.pending = None;
                self.fade = 1.0;
                let _ = self.apply_settings(settings);
                return Frame::default();
            }
        }
        let out = match &mut self.resampler {
            None if B::SAMPLE_IS_FLUSHED && self.pending.is_none() => {
                // One internal sample, already audio: as it is.
                let audio = self
                    .hands
                    .tick::<B, false, false, { law::ANY }>(&mut self.bank, bow)
                    * self.bank.output_gain();
                return self.finish(audio);
            }
            None => self
                .hands
                .tick::<B, false, false, { law::ANY }>(&mut self.bank, bow),
            Some(resampler) => {
                let mut out = [0.0];
                let step = HandsSample::<false> {
                    hands: &mut self.hands,
                    bow,
                };
                self.bank.render(resampler, &mut out, step);
                out[0]
            }
        };
        let mut audio = out * self.bank.output_gain();
        if self.pending.is_some() {
            audio *= self.fade;
        }
        self.finish(flush_tiny(audio))
    }

    /// The host sample `audio` with the probe, or silence (and a reset) if it is not finite.
    #[inline(always)]
    fn finish(&mut self, audio: f64) -> Frame {
        let audio = if B::HAS_BODY {
            audio
        } else {
            self.body.tick(audio)
        };
        let audio = self.radiation.tick(audio);
        if !audio.is_finite() {
            // Cannot happen with finite inputs; if it ever does, recover to silence rather
            // than emit garbage.
            self.reset();
            self.recoveries += 1;
            return Frame::default();
        }
        let (velocity, force) = self.bank.probe();
        Frame {
            audio,
            bow_point_velocity_m_per_s: velocity,
            friction_force_n: force,
        }
    }

    /// Renders `out.len()` samples of audio with constant bow settings: the same samples
    /// as a loop over [`FourStrings::tick`]. Asleep, the block is zeros without a
    /// per-sample call (nothing wakes within a block: only a note and
    /// [`FourStrings::update_sleep`], between blocks, change it).
    pub fn process(&mut self, bow: BowControl, out: &mut [f64]) {
        if self.skipping && !self.bank.is_awake() {
            out.fill(0.0);
            return;
        }
        if B::SAMPLE_IS_FLUSHED && B::HAS_BODY && self.resampler.is_none() && self.pending.is_none()
        {
            // What `tick` does a sample on this path, a stage at a time over the block: the
            // bank's samples (already audio), then the gain and the radiation.
            if let Some(bows) = self.hands.steady_bows(&self.bank, bow) {
                let mut step = SteadyBows {
                    bows,
                    probed: self.hands.probed,
                };
                self.bank.samples(out, &mut step);
            } else {
                let mut step = HandsSample::<true> {
                    hands: &mut self.hands,
                    bow,
                };
                self.bank.samples(out, &mut step);
            }
            let gain = self.bank.output_gain();
            if let Some(k) = self.radiation.block(gain, out) {
                // As `finish`: silence, and the instrument reset.
                self.reset();
                self.recoveries += 1;
                out[k..].fill(0.0);
            }
            return;
        }
        for sample in out {
            *sample = self.tick(bow).audio;
        }
    }
}
