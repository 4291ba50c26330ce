//! Paper B's whole instrument, as the plugin plays it: the four strings of a violin, viola or
//! cello, each with two polarisations and the finite-width thermal bow of
//! [`super::thermal`], coupled at the instrument's passive modal bridge
//! ([`super::bridge`]), run at one internal rate and resampled to the host rate.
//!
//! **One rate, one bow width.** All strings meet at the bridge sample by sample, so they
//! share one internal rate: `fs = c_low N_B / w`, set by the lowest string (wave speed
//! `c_low = 2 L f_low`) so that it carries `N_B` nodes over the bow width `w` (paper B's
//! Table 1 counts nodes on the cello C string). A higher string has a faster wave speed
//! `c_i`, hence a wider node spacing `c_i / fs`; it gets `round(N_B c_low / c_i)` nodes
//! (at least one) so that the bow is about `w` wide on every string.
//!
//! **Notes.** As in [`super::instrument::Instrument`] (both are a
//! [`super::strings::FourStrings`]; this module holds the strings and bridge,
//! [`ThermalBank`]): a note goes to the highest open string at or below it, stopped to
//! sound it (the wave speed stays, the vibrating length shortens); the bow lands and lifts
//! over [`BOW_RAMP_S`](super::vocabulary::BOW_RAMP_S). Every playable note speaks: the
//! internal rate never falls below [`MIN_SAMPLES_PER_TOP_PERIOD`] samples per period of the
//! highest note, and where a stopped string is too short for the whole bow the contact is
//! narrowed to the nodes that fit, keeping the total force
//! ([`ThermalString::set_fundamental_with_delay`]). The bow force in newtons is spread
//! evenly over the width: `F_b = F / w` (N/m).
//!
//! **Changing the bow** (node count, width) rebuilds the grid: the output fades out over
//! [`RECONFIGURE_FADE_S`], the strings are reconfigured in place (no allocation) and the
//! held notes' bows land again. The audio bandwidth is the internal rate's Nyquist
//! frequency (a coarse bow is a low rate: `N_B = 1` over 1 cm on the cello is 9 kHz).
//!
//! **Skipping.** A lifted bow costs no contact or thermal work (see
//! [`super::thermal::ThermalString::tick_contact`]). A polarisation of a lifted string
//! whose waves hold less than half of [`SLEEP_ENERGY_J`] sleeps (its waves and end filters
//! are not computed) until the waves the bridge and the nut send it add up to as much: so
//! the open strings still ring in sympathy through the bridge (while another string
//! sounds on the generic bridges they do not fall asleep at all: `bench scenes`), and a
//! polarisation loses less than [`SLEEP_ENERGY_J`] per sleep. Once every polarisation
//! sleeps and the bridge has rung out, the whole instrument sleeps at no cost and wakes
//! exactly.
//!
//! ```
//! use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
//! use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
//! let bridge = colophony::dsp::bridge_data::shipped_bridge(InstrumentKind::Cello).modes;
//! let mut cello = ThermalInstrument::new(InstrumentKind::Cello, &bridge, 48_000.0, ThermalSettings::default()).unwrap();
//! cello.note_on(50);
//! let frame = cello.tick(BowControl::default());
//! assert!(frame.audio.is_finite());
//! ```

use super::bridge::{solve_junction, BridgeMode, ModalBridge};
use super::intonation;
use super::resample::Resampler;
pub use super::strings::{FourStrings, RECONFIGURE_FADE_S};
use super::strings::{InternalSample, StringBank, StringBow};
use super::thermal::{
    HairParams, ThermalBowControl, ThermalCapacity, ThermalParams, ThermalString, ThermalStringSpec,
};
use super::vocabulary::{
    midi_to_hz, InstrumentKind, Strike, HIGHEST_TUNING_SEMITONES, LOWEST_TUNING_SEMITONES,
    SLEEP_ENERGY_J, STRINGS,
};

/// Most bow nodes on the lowest string (paper B's Figure 6 uses 60).
pub const MAX_NODES: usize = 60;

/// The impedance of the string the force parameter is the force on when paper B's strings
/// are weighted (String Weight), kg/s: between the cello's C and G strings (1.91 and 0.83),
/// so the default 1 N is `F_max / 6.7` of every string's window at 0.1 m/s and beta 0.1
/// (`F_max = 2 Z0 v_b / (beta (mu_s - mu_d))` with the thermal law's 0.8 / 0.5). The
/// point laws' 0.2 kg/s would put it at `3 F_max / 4`, where the thermal pitch falls
/// steeply with force. Chosen by measurement (docs/playing-space.md, "Weighted strings
/// for paper B's model"): at the defaults, every third semitone at 48 kHz, the classifier
/// finds one slip a period on 47 of 48 notes with this reference, 43-45 with 0.3-0.75,
/// 35 unweighted (the top of the violin's A string and all of its E string raucous at 1 N).
pub const THERMAL_WEIGHT_REFERENCE_Z0: f64 = 1.0;
/// Narrowest and widest bow, m (a tilted bow touches with a few mm of hair; a flat
/// violin bow with about 1 cm, paper B's value).
pub const MIN_WIDTH_M: f64 = 0.005;
pub const MAX_WIDTH_M: f64 = 0.02;
/// The internal rate never gives the highest playable note (bent up) fewer samples per
/// period than this: its half-loop then holds a bow node and the bow's clearance
/// ([`super::thermal::BOW_CLEARANCE`]) with the filters' delay to spare, so every note
/// speaks. Only coarse, wide bows reach the floor (violin: 71 kHz, against 125 kHz for
/// Good's ten nodes over 1 cm); there the bow keeps its node count and is narrower than
/// asked.
pub const MIN_SAMPLES_PER_TOP_PERIOD: f64 = 16.0;

/// The bow's discretisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalSettings {
    /// Nodes on the lowest string, 1..=[`MAX_NODES`].
    pub nodes: usize,
    /// Bow width in contact, m, [`MIN_WIDTH_M`]..=[`MAX_WIDTH_M`].
    pub width_m: f64,
}

impl Default for ThermalSettings {
    /// Ten nodes over 1 cm: 90 kHz on the cello, a few per cent of a core.
    fn default() -> Self {
        Self {
            nodes: 10,
            width_m: 0.01,
        }
    }
}

impl ThermalSettings {
    /// Clamped into the supported ranges (a NaN width becomes the default).
    pub fn clamped(self) -> Self {
        let width_m = if self.width_m.is_finite() {
            self.width_m.clamp(MIN_WIDTH_M, MAX_WIDTH_M)
        } else {
            Self::default().width_m
        };
        Self {
            nodes: self.nodes.clamp(1, MAX_NODES),
            width_m,
        }
    }
}

/// The harmonic finger's resistance on the thermal strings, in units of the string's
/// impedance: `R = Z0`, lighter than the point-bow strings'
/// [`super::strings::HARMONIC_FINGER_RESISTANCE_Z0`]: it passes two thirds of a wave,
/// reflects a ninth of its energy and takes four ninths out (at `2 Z0`: half, a quarter
/// and a half). Chosen by measurement on the 57 test
/// harmonics of the violin, viola and cello at the defaults (docs/articulations.md#harmonics):
/// 53, 55, 55, 53 and 53 sound their partial within 10 cents at 0.5, 0.75, 1, 1.5 and 2
/// `Z0`, and at 4 `Z0` some do not speak.
pub const THERMAL_FINGER_Z0: f64 = 1.0;

/// The strings and bridge at the internal rate.
#[derive(Debug, Clone)]
struct Core {
    strings: Vec<ThermalString>,
    bridge: ModalBridge,
    arriving: [[f64; 2]; STRINGS],
    leaving: [[f64; 2]; STRINGS],
    impedances: [f64; STRINGS],
    /// A light finger touches some string (a harmonic): its junction runs each sample.
    touching: bool,
    /// The bow's stick strikes some string (col legno battuto): a struck string takes
    /// the stick's contact instead of the bow's.
    striking: bool,
    /// The probed string's last internal sample: string velocity at the bow's middle node,
    /// and the string whose nodes give the total friction force (summed when asked,
    /// [`StringBank::probe`]; `None`: lifted and idle, no force).
    probe: (f64, Option<usize>),
}

impl Core {
    /// One internal sample, `bow_of(i)` giving string `i`'s bow (force per metre);
    /// returns the horizontal force on the bridge, N.
    #[inline(always)]
    fn tick(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        if self.striking {
            self.tick_with::<true>(probed, bow_of)
        } else {
            self.tick_with::<false>(probed, bow_of)
        }
    }

    /// [`Core::tick`], with `STRIKING` while the bow's stick strikes some string.
    #[inline(always)]
    fn tick_with<const STRIKING: bool>(
        &mut self,
        probed: usize,
        mut bow_of: impl FnMut(usize) -> StringBow,
    ) -> f64 {
        for (i, string) in self.strings.iter_mut().enumerate() {
            let bow = bow_of(i);
            if STRIKING && string.is_struck() {
                let velocity = string.strike_contact(bow.position_beta);
                if i == probed {
                    self.probe = (velocity, None);
                }
                self.arriving[i] = string.arriving_at_bridge();
                continue;
            }
            // A pressing force only (the force parameter is never negative; this keeps a
            // stray sign from pulling the hair off the string).
            let force = bow.force.max(0.0);
            // Lifted, cleared and cooled: the contact has nothing to compute. Only the
            // probed string's velocity is read, and a sleeping one's is zero (its lines
            // hold zeros; it still takes, or drops, what the bridge sends back).
            if force <= 0.0 && string.contact_idle() && (i != probed || string.is_asleep()) {
                self.arriving[i] = string.arriving_at_bridge();
                if i == probed {
                    self.probe = (0.0, None);
                }
                continue;
            }
            let velocity = string.tick_contact(ThermalBowControl {
                velocity_m_per_s: bow.velocity_m_per_s,
                force_n_per_m: force,
                position_beta: bow.position_beta,
            });
            if i == probed {
                self.probe = (velocity, Some(i));
            }
            self.arriving[i] = string.arriving_at_bridge();
        }
        let (_, force) = solve_junction(
            &mut self.bridge,
            &self.arriving,
            &self.impedances,
            &mut self.leaving,
        );
        if self.touching {
            for string in &mut self.strings {
                string.touch_junction();
            }
        }
        for (string, leaving) in self.strings.iter_mut().zip(&self.leaving) {
            string.finish_sample(*leaving);
        }
        if STRIKING {
            self.striking = self.strings.iter().any(ThermalString::is_struck);
        }
        force[0]
    }
}

/// The internal samples one host sample needs, through the resampler, compiled for AVX2:
/// the whole internal sample (bows, waves, nodes, bridge, resampler), so the gathers and
/// scatters under the bow use four lanes (no FMA: the results are the same bits as
/// without).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn render_avx2(
    bank: &mut ThermalBank,
    resampler: &mut Resampler,
    out: &mut [f64],
    mut step: impl InternalSample<ThermalBank>,
) {
    resampler.process(|| step.tick(bank), out);
}

/// Paper B's strings and modal bridge at the internal rate, with the bow's
/// discretisation (see the module doc).
#[derive(Debug, Clone)]
pub struct ThermalBank {
    kind: InstrumentKind,
    settings: ThermalSettings,
    core: Core,
    /// Wave speed of each string, m/s.
    wave_speeds: [f64; STRINGS],
    /// The bow's width on the lowest string at the current settings, m (the force is
    /// spread over it).
    contact_width_m: f64,
    output_scale: f64,
    awake: bool,
    /// AVX2 detected at run time ([`render_avx2`]).
    wide_simd: bool,
    /// A mute on the bridge (con sordino, [`super::body::muted_bridge_mode`]).
    muted: bool,
}

/// Paper B's four-string instrument at the host rate (see the module doc):
/// [`FourStrings`] over [`ThermalBank`].
pub type ThermalInstrument = FourStrings<ThermalBank>;

impl ThermalBank {
    /// `c_low N_B / w`, or the floor [`MIN_SAMPLES_PER_TOP_PERIOD`] sets by the highest
    /// playable note.
    fn internal_rate(
        kind: InstrumentKind,
        wave_speeds: &[f64; STRINGS],
        settings: ThermalSettings,
    ) -> f64 {
        let top = kind.note_range().1 as f64 + HIGHEST_TUNING_SEMITONES;
        (wave_speeds[0] * settings.nodes as f64 / settings.width_m)
            .max(MIN_SAMPLES_PER_TOP_PERIOD * midi_to_hz(top))
    }

    /// Width of the bow on the lowest string, m: the settings' width, or less where the
    /// rate floor made the node spacing finer.
    fn contact_width(&self, settings: ThermalSettings) -> f64 {
        let rate = Self::internal_rate(self.kind, &self.wave_speeds, settings);
        settings.nodes as f64 * self.wave_speeds[0] / rate
    }

    /// Nodes on string `i` for these settings: about the same width on every string.
    fn nodes_on(&self, i: usize, settings: ThermalSettings) -> usize {
        ((settings.nodes as f64 * self.wave_speeds[0] / self.wave_speeds[i]).round() as usize)
            .max(1)
    }

    /// Phase delay (internal samples) that the bridge adds, over a rigid end, to the
    /// horizontal wave of string `i` reflecting at `f0_hz`: with every string's impedance
    /// on the bridge (`Z_s`), a wave arriving on string `i` leaves as
    /// `r = -(1 + (Z_s - 2 Z_i) Y) / (1 + Z_s Y)` times itself, `Y = Y_hh(e^jw)`.
    fn bridge_delay(&self, i: usize, f0_hz: f64) -> f64 {
        let y = self.core.bridge.response(f0_hz)[0][0];
        let z_s: f64 = self.core.impedances.iter().sum();
        let z_i = self.core.impedances[i];
        let num = (1.0 + (z_s - 2.0 * z_i) * y.0, (z_s - 2.0 * z_i) * y.1);
        let den = (1.0 + z_s * y.0, z_s * y.1);
        let phase = num.1.atan2(num.0) - den.1.atan2(den.0);
        let w = 2.0 * std::f64::consts::PI * f0_hz / self.internal_rate_hz();
        -phase / w
    }

    /// Tunes string `i` to `f0_hz` with the bridge's delay accounted for (at the touched
    /// partial's frequency while a finger touches the string for a harmonic).
    fn tune(&mut self, i: usize, f0_hz: f64) -> bool {
        let partial = self.core.strings[i].touched_partial() as f64;
        let delay = self.bridge_delay(i, f0_hz * partial);
        self.core.strings[i].set_fundamental_with_delay(f0_hz, delay)
    }
}

impl StringBank for ThermalBank {
    type Settings = ThermalSettings;
    const WEIGHT_REFERENCE_Z0: f64 = THERMAL_WEIGHT_REFERENCE_Z0;
    const FREE_PITCH_ROW: Option<usize> = Some(intonation::THERMAL_FREE_ROW);

    fn internal_rate_hz(&self) -> f64 {
        Self::internal_rate(self.kind, &self.wave_speeds, self.settings)
    }

    /// The mute's mass on the bridge's modes from the bridge hill up, as on the point-bow
    /// body: the bridge keeps its ringing state, and each string is retuned at its pitch
    /// for the bridge's new phase delay.
    fn set_mute(&mut self, on: bool) {
        if on == self.muted {
            return;
        }
        self.muted = on;
        let scale = self.kind.spec().body_scale;
        self.core.bridge.transform_modes(|mode| {
            if on {
                super::body::muted_bridge_mode(mode, scale)
            } else {
                mode
            }
        });
        for i in 0..STRINGS {
            let f0 = self.core.strings[i].fundamental_hz();
            if f0 > 0.0 {
                self.tune(i, f0);
            }
        }
    }

    /// The force in newtons is spread evenly over the bow's width: `F_b = F / w` (N/m).
    fn force_divisor(&self) -> f64 {
        self.contact_width_m
    }

    fn output_gain(&self) -> f64 {
        self.output_scale
    }

    fn stop(&mut self, i: usize, hz: f64) -> bool {
        self.tune(i, hz)
    }

    fn bend(&mut self, i: usize, hz: f64) -> bool {
        self.tune(i, hz)
    }

    fn release_finger(&mut self, i: usize, hz: f64) -> bool {
        let delay = self.bridge_delay(i, hz);
        self.core.strings[i].release_to_with_delay(hz, delay)
    }

    fn set_finger_reflection(&mut self, i: usize, reflection: f64) {
        self.core.strings[i].set_finger_reflection(reflection);
    }

    const PLUCKABLE: bool = true;

    /// Plucks string `i` ([`ThermalString::pluck`]).
    fn pluck(&mut self, i: usize, displacement_m: f64, position_beta: f64, width: f64) -> bool {
        let plucked = self.core.strings[i].pluck(displacement_m, position_beta, width);
        self.awake |= plucked;
        plucked
    }

    /// Strikes string `i` with the bow's stick at its bow's middle node
    /// ([`ThermalString::strike`]).
    fn strike(&mut self, i: usize, strike: Strike) -> bool {
        let struck = self.core.strings[i].strike(strike.mass_kg, strike.velocity_m_per_s);
        self.core.striking |= struck;
        self.awake |= struck;
        struck
    }

    const TOUCHABLE: bool = true;
    /// Chosen by measurement (docs/articulations.md#harmonics): bowed at the touched
    /// part's own place (a `n`-th of the asked position), the thermal contact on the
    /// violin's and viola's 8th partials, 1-2 % of the string from the bridge, sticks
    /// without sounding (4 of their 38 test harmonics silent, 12 with the octave below
    /// stronger); at `sqrt(n)` none is silent and 4 are.
    const HARMONIC_BOW_AT_ROOT: bool = true;

    /// The light finger on both polarisations of string `i`, at the node of `partial`
    /// nearest the bridge ([`ThermalString::set_touch`]), of [`THERMAL_FINGER_Z0`]; the
    /// string is retuned at its stopped pitch with the loop matched at the partial.
    fn touch(&mut self, i: usize, partial: Option<u32>) {
        let string = &mut self.core.strings[i];
        let resistance = THERMAL_FINGER_Z0 * string.z0_kg_per_s();
        let before = string.touched_partial();
        string.set_touch(partial.map(|n| (n, resistance)));
        let f0 = string.fundamental_hz();
        if (before > 1 || string.touched_partial() > 1) && f0 > 0.0 {
            self.tune(i, f0);
        }
        self.core.touching = self.core.strings.iter().any(|s| s.touched_partial() > 1);
    }

    fn wake(&mut self, _i: usize) {
        self.awake = true;
    }

    /// The strings ring together through the bridge: one is awake while any is.
    fn string_awake(&self, _i: usize) -> bool {
        self.awake
    }

    #[inline(always)]
    fn is_awake(&self) -> bool {
        self.awake
    }

    fn strings_awake(&self) -> bool {
        self.awake
    }

    /// A lifted bow already costs no contact or thermal work; the strings sleep whole.
    fn set_skipping(&mut self, _skipping: bool) {}

    #[inline(always)]
    fn sample(&mut self, probed: usize, bow_of: impl FnMut(usize) -> StringBow) -> f64 {
        self.core.tick(probed, bow_of)
    }

    #[inline(always)]
    fn render(
        &mut self,
        resampler: &mut Resampler,
        out: &mut [f64],
        mut step: impl InternalSample<Self>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.wide_simd {
            // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
            unsafe { render_avx2(self, resampler, out, step) };
            return;
        }
        resampler.process(|| step.tick(self), out);
    }

    fn probe(&self) -> (f64, f64) {
        let (velocity, string) = self.core.probe;
        let force = string.map_or(0.0, |i| self.core.strings[i].friction_force_n());
        (velocity, force)
    }

    /// Each polarisation of a lifted string whose waves fall below half of
    /// [`SLEEP_ENERGY_J`] sleeps until what the bridge sends it adds up to as much
    /// ([`ThermalString::sleep_quiet_polarisations`]); once every polarisation sleeps and
    /// the bridge has rung out, the whole instrument sleeps.
    fn sleep(&mut self, lifted: &[bool; STRINGS]) -> bool {
        if !self.awake {
            return false;
        }
        let mut all_asleep = true;
        for (&lifted, string) in lifted.iter().zip(&mut self.core.strings) {
            if lifted {
                string.sleep_quiet_polarisations(SLEEP_ENERGY_J);
            }
            all_asleep &= string.is_asleep();
        }
        if all_asleep && self.core.bridge.is_quiet(1e-12) {
            for s in &mut self.core.strings {
                s.reset();
            }
            self.core.bridge.reset();
            self.core.probe = (0.0, None);
            self.awake = false;
            return true;
        }
        false
    }

    /// Every string counts (the bridge keeps them coupled), each at its fundamental's
    /// decay rate ([`super::vocabulary::ring_out_s`]).
    fn ring_out_s(&self, lifted: &[bool; STRINGS]) -> Option<f64> {
        if !self.awake {
            return Some(0.0);
        }
        if lifted.iter().any(|l| !l) {
            return None;
        }
        let longest = self
            .core
            .strings
            .iter()
            .map(|s| super::vocabulary::ring_out_s(s.energy_j(), s.fundamental_hz(), s.q1()))
            .fold(0.0, f64::max);
        Some(longest)
    }

    /// Energy of the strings (waves, end filters, hair) and the bridge, J. With every bow
    /// lifted it never grows from one internal sample to the next: the strings lose at the
    /// bridge what it gains ([`ModalBridge::energy_j`]), and everything else is lossless
    /// or lossy.
    fn energy_j(&self) -> f64 {
        self.core.strings.iter().map(|s| s.energy_j()).sum::<f64>() + self.core.bridge.energy_j()
    }

    fn reset(&mut self) {
        for s in &mut self.core.strings {
            s.reset();
        }
        self.core.bridge.reset();
        self.core.probe = (0.0, None);
        self.core.striking = false;
        self.awake = false;
    }

    fn settings(&self) -> ThermalSettings {
        self.settings
    }

    fn configure(&mut self, settings: ThermalSettings) -> Result<(), String> {
        let rate = Self::internal_rate(self.kind, &self.wave_speeds, settings);
        for i in 0..STRINGS {
            let nodes = self.nodes_on(i, settings);
            if let Err(e) = self.core.strings[i].configure(nodes, settings.width_m, rate) {
                // Put every string back on the settings that worked.
                let old = self.settings;
                let old_rate = Self::internal_rate(self.kind, &self.wave_speeds, old);
                for j in 0..=i {
                    let n = self.nodes_on(j, old);
                    let _ = self.core.strings[j].configure(n, old.width_m, old_rate);
                }
                return Err(e.to_string());
            }
        }
        self.settings = settings;
        self.contact_width_m = self.contact_width(settings);
        self.core.bridge.set_sample_rate(rate);
        self.awake = false;
        Ok(())
    }
}

impl ThermalInstrument {
    /// Allocates for every setting within the limits ([`MAX_NODES`], [`MIN_WIDTH_M`]) and
    /// every playable note; later changes never allocate. `bridge` is the instrument's
    /// modal bridge (validated here).
    pub fn new(
        kind: InstrumentKind,
        bridge: &[BridgeMode],
        host_rate_hz: f64,
        settings: ThermalSettings,
    ) -> Result<Self, String> {
        Self::with_contact(
            kind,
            bridge,
            host_rate_hz,
            settings,
            ThermalParams::default(),
        )
    }

    /// [`ThermalInstrument::new`] with the thermal contact's constants `thermal` instead
    /// of [`ThermalParams::default`] (the tools compare candidate sets:
    /// `colophony bench thermal-constants`).
    pub fn with_contact(
        kind: InstrumentKind,
        bridge: &[BridgeMode],
        host_rate_hz: f64,
        settings: ThermalSettings,
        thermal: ThermalParams,
    ) -> Result<Self, String> {
        thermal.validate()?;
        if !(host_rate_hz.is_finite() && host_rate_hz > 0.0) {
            return Err(format!("invalid sample rate {host_rate_hz}"));
        }
        let open = kind.strings();
        let length = kind.string_length_m();
        let wave_speeds: [f64; STRINGS] = std::array::from_fn(|i| 2.0 * length * open[i].open_hz);
        let max_rate = wave_speeds[0] * MAX_NODES as f64 / MIN_WIDTH_M;
        let lowest_hz = open[0].open_hz * 2f64.powf(LOWEST_TUNING_SEMITONES / 12.0) * 0.99;
        let strings = open
            .iter()
            .map(|s| {
                let spec = ThermalStringSpec {
                    f0_hz: s.open_hz,
                    z0_kg_per_s: s.z0_kg_per_s,
                    length_m: length,
                    q1: s.q1,
                    q_hi: s.q_hi,
                    ..ThermalStringSpec::cello_c()
                };
                ThermalString::with_capacity(
                    spec,
                    thermal,
                    HairParams::default(),
                    ThermalCapacity {
                        max_nodes: MAX_NODES,
                        max_rate_hz: max_rate,
                        lowest_hz,
                    },
                )
                .map(|mut string| {
                    string.use_modal_bridge();
                    string
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let settings = settings.clamped();
        let rate = ThermalBank::internal_rate(kind, &wave_speeds, settings);
        let bank = ThermalBank {
            kind,
            settings,
            core: Core {
                strings,
                bridge: ModalBridge::new(bridge, rate)?,
                arriving: [[0.0; 2]; STRINGS],
                leaving: [[0.0; 2]; STRINGS],
                impedances: std::array::from_fn(|i| open[i].z0_kg_per_s),
                touching: false,
                striking: false,
                probe: (0.0, None),
            },
            wave_speeds,
            contact_width_m: settings.width_m,
            output_scale: kind.output_scale_per_n(),
            awake: false,
            wide_simd: super::detect_wide_simd(),
            muted: false,
        };
        let resampler = Box::new(Resampler::with_capacity(rate, host_rate_hz, max_rate)?);
        let mut instrument = Self::from_bank(
            bank,
            kind,
            host_rate_hz,
            Some(resampler),
            intonation::TunedModel::Thermal.row(),
        );
        instrument.apply_settings(settings)?;
        Ok(instrument)
    }

    /// Asks for new bow settings (clamped to the limits). If the instrument sounds, the
    /// output fades out first and the change lands after [`RECONFIGURE_FADE_S`].
    pub fn set_settings(&mut self, settings: ThermalSettings) {
        self.request_settings(settings.clamped());
    }

    pub fn settings(&self) -> ThermalSettings {
        self.bank.settings
    }

    /// Nodes on each string at the current settings.
    pub fn nodes_per_string(&self) -> [usize; STRINGS] {
        std::array::from_fn(|i| self.bank.core.strings[i].nodes())
    }

    /// The string a note went to last (for the editor's views and the tests).
    pub fn probed_string(&self) -> &ThermalString {
        &self.bank.core.strings[self.hands.probed]
    }

    pub fn string(&self, i: usize) -> &ThermalString {
        &self.bank.core.strings[i]
    }

    /// The bow's stick plays the strings instead of its hair (`true`, col legno tratto,
    /// [`ThermalString::set_stick`]) or the hair again (`false`). Real-time safe.
    pub fn set_stick_contact(&mut self, stick: bool) {
        for string in &mut self.bank.core.strings {
            string.set_stick(stick);
        }
    }

    /// Polarisations asleep now, of eight (all eight while the whole instrument sleeps).
    pub fn asleep_polarisations(&self) -> usize {
        if !self.bank.awake {
            return 2 * STRINGS;
        }
        self.bank
            .core
            .strings
            .iter()
            .map(|s| s.asleep().iter().filter(|a| **a).count())
            .sum()
    }
}
