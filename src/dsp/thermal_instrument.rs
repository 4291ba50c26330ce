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
//! **Notes.** As in [`super::instrument::Instrument`]: a note goes to the highest open
//! string at or below it, stopped to sound it (the wave speed stays, the vibrating length
//! shortens); the bow lands and lifts over [`BOW_RAMP_S`]. Every playable note speaks: the
//! internal rate never falls below [`MIN_SAMPLES_PER_TOP_PERIOD`] samples per period of
//! the highest note, and where a stopped string is too short for the whole bow the contact
//! is narrowed to the nodes that fit, keeping the total force
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
//! use colophony::dsp::instrument::{BowControl, InstrumentKind};
//! use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
//! let bridge = colophony::dsp::bridge_data::shipped_cello_bridge().modes;
//! let mut cello = ThermalInstrument::new(InstrumentKind::Cello, &bridge, 48_000.0, ThermalSettings::default()).unwrap();
//! cello.note_on(50);
//! let frame = cello.tick(BowControl::default());
//! assert!(frame.audio.is_finite());
//! ```

use super::bridge::{solve_junction, BridgeMode, ModalBridge};
use super::filters::flush_tiny;
use super::fingering::{BowEnvelope, Fingering};
use super::instrument::{
    midi_to_hz, BowControl, Frame, InstrumentKind, NoteExpression, BOW_RAMP_S,
    HIGHEST_TUNING_SEMITONES, LOWEST_TUNING_SEMITONES, MAX_NOTE_BETA, MIN_NOTE_BETA,
    SLEEP_ENERGY_J, STRINGS,
};
use super::intonation::{self, IntonationTable};
use super::resample::Resampler;
use super::thermal::{
    HairParams, ThermalBowControl, ThermalCapacity, ThermalConfigError, ThermalParams,
    ThermalString, ThermalStringSpec,
};

/// Most bow nodes on the lowest string (paper B's Figure 6 uses 60).
pub const MAX_NODES: usize = 60;
/// Narrowest and widest bow, m (a tilted bow touches with a few mm of hair; a flat
/// violin bow with about 1 cm, paper B's value).
pub const MIN_WIDTH_M: f64 = 0.005;
pub const MAX_WIDTH_M: f64 = 0.02;
/// Fade-out before the grid is rebuilt for a new node count or width, s.
pub const RECONFIGURE_FADE_S: f64 = 0.01;
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

/// The strings and bridge at the internal rate.
#[derive(Debug, Clone)]
struct Core {
    strings: Vec<ThermalString>,
    bridge: ModalBridge,
    arriving: [[f64; 2]; STRINGS],
    leaving: [[f64; 2]; STRINGS],
    impedances: [f64; STRINGS],
    bows: [ThermalBowControl; STRINGS],
    probed: usize,
    /// The probed string's last internal sample: string velocity at the bow's middle node
    /// and total friction force.
    probe: (f64, f64),
}

impl Core {
    /// One internal sample; returns the horizontal force on the bridge, N.
    #[inline(always)]
    fn tick(&mut self) -> f64 {
        for (i, string) in self.strings.iter_mut().enumerate() {
            // Lifted, cleared and cooled: the contact has nothing to compute. Only the
            // probed string's velocity is read, and a sleeping one's is zero (its lines
            // hold zeros; it still takes, or drops, what the bridge sends back).
            if self.bows[i].force_per_m <= 0.0
                && string.contact_idle()
                && (i != self.probed || string.is_asleep())
            {
                self.arriving[i] = string.arriving_at_bridge();
                if i == self.probed {
                    self.probe = (0.0, 0.0);
                }
                continue;
            }
            let f = string.tick_contact(self.bows[i]);
            if i == self.probed {
                self.probe = (f.string_velocity_m_per_s, f.friction_force_n);
            }
            self.arriving[i] = string.arriving_at_bridge();
        }
        let (_, force) = solve_junction(
            &mut self.bridge,
            &self.arriving,
            &self.impedances,
            &mut self.leaving,
        );
        for (string, leaving) in self.strings.iter_mut().zip(&self.leaving) {
            string.finish_sample(*leaving);
        }
        force[0]
    }
}

/// Runs the internal samples one host sample needs, through the resampler. With AVX2
/// the whole internal sample (waves, nodes, bridge, resampler) is compiled for it, so the
/// gathers and scatters under the bow use four lanes (no FMA: the results are the same
/// bits as without).
#[inline(always)]
fn run_core(wide_simd: bool, resampler: &mut Resampler, core: &mut Core, out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if wide_simd {
        // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
        unsafe { run_core_avx2(resampler, core, out) };
        return;
    }
    let _ = wide_simd;
    resampler.process(|| core.tick(), out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_core_avx2(resampler: &mut Resampler, core: &mut Core, out: &mut [f64]) {
    resampler.process(|| core.tick(), out);
}

/// Paper B's four-string instrument at the host rate (see the module doc).
#[derive(Debug, Clone)]
pub struct ThermalInstrument {
    kind: InstrumentKind,
    settings: ThermalSettings,
    /// Settings waiting for the fade-out to end.
    pending: Option<ThermalSettings>,
    fade: f64,
    fade_step: f64,
    core: Core,
    resampler: Resampler,
    /// The bow on each string.
    bows: [BowEnvelope; STRINGS],
    /// Notes, fingers and tuning ([`Fingering`]).
    fingering: Fingering,
    /// Wave speed of each string, m/s.
    wave_speeds: [f64; STRINGS],
    /// The bow's width on the lowest string at the current settings, m (the force is
    /// spread over it).
    contact_width_m: f64,
    ramp_step: f64,
    output_scale: f64,
    awake: bool,
    /// Whether the instrument sleeps when silent (the default; off only to measure what
    /// sleeping saves: `colophony bench scenes`).
    skipping: bool,
    /// AVX2 detected at run time ([`run_core`]).
    wide_simd: bool,
    /// Times the non-finite guard in [`ThermalInstrument::tick`] reset the instrument.
    recoveries: u64,
    /// The rate [`ThermalInstrument::tick`] is called at, Hz.
    host_rate_hz: f64,
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
        let rate = Self::internal_rate(kind, &wave_speeds, settings);
        let mut instrument = Self {
            kind,
            settings,
            pending: None,
            fade: 1.0,
            fade_step: 1.0 / (RECONFIGURE_FADE_S * host_rate_hz).max(1.0),
            core: Core {
                strings,
                bridge: ModalBridge::new(bridge, rate)?,
                arriving: [[0.0; 2]; STRINGS],
                leaving: [[0.0; 2]; STRINGS],
                impedances: std::array::from_fn(|i| open[i].z0_kg_per_s),
                bows: [ThermalBowControl {
                    velocity_m_per_s: 0.0,
                    force_per_m: 0.0,
                    position_beta: 0.1,
                }; STRINGS],
                probed: 0,
                probe: (0.0, 0.0),
            },
            resampler: Resampler::with_capacity(rate, host_rate_hz, max_rate)?,
            bows: [BowEnvelope::default(); STRINGS],
            fingering: Fingering::new(kind, Some(intonation::THERMAL_ROW)),
            wave_speeds,
            contact_width_m: settings.width_m,
            ramp_step: 1.0 / (BOW_RAMP_S * host_rate_hz).max(1.0),
            output_scale: kind.output_scale_per_n(),
            awake: false,
            skipping: true,
            wide_simd: super::detect_wide_simd(),
            recoveries: 0,
            host_rate_hz,
        };
        instrument
            .apply_settings(settings)
            .map_err(|e| e.to_string())?;
        Ok(instrument)
    }

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

    /// Tunes string `i` to `f0_hz` with the bridge's delay accounted for.
    fn tune(&mut self, i: usize, f0_hz: f64) -> bool {
        let delay = self.bridge_delay(i, f0_hz);
        self.core.strings[i].set_fundamental_with_delay(f0_hz, delay)
    }

    /// Reconfigures everything now (strings silenced, held notes re-landed).
    fn apply_settings(&mut self, settings: ThermalSettings) -> Result<(), ThermalConfigError> {
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
                return Err(e);
            }
        }
        self.settings = settings;
        self.contact_width_m = self.contact_width(settings);
        self.core.bridge.set_sample_rate(rate);
        // Within capacity by construction (rate <= the maximum rate).
        let _ = self.resampler.set_input_rate(rate);
        for i in 0..STRINGS {
            self.bows[i].gain = 0.0;
            let f0 = match self.fingering.note(i) {
                Some(_) => self.fingering.tuned_hz(i),
                None => {
                    self.kind.strings()[i].open_hz
                        * 2f64.powf(self.fingering.reference_semitones() / 12.0)
                }
            };
            if !self.tune(i, f0) {
                self.bows[i] = BowEnvelope::default();
                self.fingering.clear_string(i);
            }
        }
        self.awake = self.bows.iter().any(|b| b.bowed);
        Ok(())
    }

    /// Asks for new bow settings (clamped to the limits). If the instrument sounds, the
    /// output fades out first and the change lands after [`RECONFIGURE_FADE_S`].
    pub fn set_settings(&mut self, settings: ThermalSettings) {
        let settings = settings.clamped();
        if settings == self.settings && self.pending.is_none() {
            return;
        }
        if self.awake {
            self.pending = Some(settings);
        } else {
            // Within the limits every setting is valid; keep the old one if not.
            let _ = self.apply_settings(settings);
        }
    }

    pub fn settings(&self) -> ThermalSettings {
        self.settings
    }

    pub fn kind(&self) -> InstrumentKind {
        self.kind
    }

    pub fn internal_rate_hz(&self) -> f64 {
        Self::internal_rate(self.kind, &self.wave_speeds, self.settings)
    }

    /// Nodes on each string at the current settings.
    pub fn nodes_per_string(&self) -> [usize; STRINGS] {
        std::array::from_fn(|i| self.core.strings[i].nodes())
    }

    /// Stops the string for `note` and lands the bow. `None` (ignored) if no string can
    /// play it with this bow.
    pub fn note_on(&mut self, note: u8) -> Option<usize> {
        let index = self.fingering.string_for_note_on(note)?;
        let before = (self.fingering.note(index), self.fingering.expression(index));
        self.fingering.start(index, note);
        let f0 = self.fingering.tuned_hz(index);
        if !self.tune(index, f0) {
            self.fingering.restore(index, before.0, before.1);
            return None;
        }
        self.bows[index].bowed = true;
        self.core.probed = index;
        self.awake = true;
        Some(index)
    }

    /// As [`ThermalInstrument::note_on`], but where the note's string is bowed with
    /// another note the stopping point glides from that note's place to this one over
    /// `glide_s` seconds (linearly in semitones, retuned every [`GLIDE_EVERY`](super::fingering::GLIDE_EVERY) host
    /// samples), as the waveguide instrument's finger does; otherwise, or with `glide_s`
    /// not positive, as [`ThermalInstrument::note_on`].
    pub fn note_on_gliding(&mut self, note: u8, glide_s: f64) -> Option<usize> {
        let index = self.fingering.string_for_note_on(note)?;
        let from = match self.fingering.note(index) {
            Some(old)
                if self.bows[index].bowed
                    && self.awake
                    && self.pending.is_none()
                    && glide_s > 0.0
                    && glide_s.is_finite() =>
            {
                old as f64 + self.fingering.glide(index)
            }
            _ => return self.note_on(note),
        };
        let distance = from - note as f64;
        self.fingering
            .glide_to(index, note, distance, glide_s, self.host_rate_hz);
        self.core.probed = index;
        let f0 = self.fingering.tuned_hz(index);
        if !self.tune(index, f0) {
            self.bows[index].bowed = false;
        }
        Some(index)
    }

    /// Lifts the bow from the string playing `note`, if any.
    pub fn note_off(&mut self, note: u8) {
        for (i, bow) in self.bows.iter_mut().enumerate() {
            if self.fingering.note(i) == Some(note) {
                bow.bowed = false;
            }
        }
    }

    pub fn all_notes_off(&mut self) {
        for bow in &mut self.bows {
            bow.bowed = false;
        }
    }

    /// Asks later notes to go to string `preferred` (0 = the lowest) where it can play
    /// them ([`InstrumentKind::string_for_note_on`]); `None` restores the usual choice.
    /// Notes already sounding stay where they are.
    pub fn set_preferred_string(&mut self, preferred: Option<usize>) {
        self.fingering.set_preferred_string(preferred);
    }

    /// Pitch bend in semitones (clamped to the bend range).
    pub fn set_pitch_bend(&mut self, semitones: f64) {
        if self.fingering.set_pitch_bend(semitones) {
            self.retune();
        }
    }

    /// Gives string `index` its note's own expression (sanitized; see [`NoteExpression`]):
    /// a changed bend retunes it (a bend the bow cannot follow lifts it, as the shared
    /// bend does). A new note on the string starts neutral again.
    pub fn set_note_expression(&mut self, index: usize, expression: NoteExpression) {
        if self.fingering.set_expression(index, expression) {
            let f0 = self.fingering.tuned_hz(index);
            if !self.tune(index, f0) {
                self.bows[index].bowed = false;
            }
        }
    }

    /// Tunes every note from the reference pitch `a4_hz` (415..466 Hz; see
    /// [`reference_semitones`]); sounding notes follow at once.
    pub fn set_reference_pitch(&mut self, a4_hz: f64) {
        if self.fingering.set_reference_pitch(a4_hz) {
            self.retune();
        }
    }

    /// Tunes by the bowed sound with `table` (the default is the shipped one), or by the
    /// free decay with `None`. Sounding notes follow at once.
    pub fn set_intonation(&mut self, table: Option<&'static IntonationTable>) {
        self.fingering.set_intonation(table);
        self.retune();
    }

    /// Moves every stopped note to its pitch under the current bend and reference.
    fn retune(&mut self) {
        for i in 0..STRINGS {
            if self.fingering.note(i).is_some() {
                let f0 = self.fingering.tuned_hz(i);
                if !self.tune(i, f0) {
                    // Tuned out of what the bow allows: lift it, the string rings on.
                    self.bows[i].bowed = false;
                }
            }
        }
    }

    pub fn reset(&mut self) {
        for s in &mut self.core.strings {
            s.reset();
        }
        self.core.bridge.reset();
        self.resampler.reset();
        self.bows = [BowEnvelope::default(); STRINGS];
        self.fingering.clear();
        self.core.probe = (0.0, 0.0);
        self.awake = false;
    }

    /// Whether anything sounds (a bow down or a string still ringing).
    pub fn is_sounding(&self) -> bool {
        self.awake
    }

    /// Whether anything still rings (the bridge rings with the strings: as
    /// [`ThermalInstrument::is_sounding`]).
    pub fn is_ringing(&self) -> bool {
        self.awake
    }

    /// The string a note went to last (for the editor's views and the tests).
    pub fn probed_string(&self) -> &ThermalString {
        &self.core.strings[self.core.probed]
    }

    pub fn string(&self, i: usize) -> &ThermalString {
        &self.core.strings[i]
    }

    /// Energy of the strings (waves, end filters, hair) and the bridge, J. With every bow
    /// lifted it never grows from one internal sample to the next: the strings lose at the
    /// bridge what it gains ([`ModalBridge::energy_j`]), and everything else is lossless
    /// or lossy.
    pub fn energy_j(&self) -> f64 {
        self.core.strings.iter().map(|s| s.energy_j()).sum::<f64>() + self.core.bridge.energy_j()
    }

    /// Seconds until the instrument would fall asleep if no bow lands again (the host's
    /// tail), or `None` while a bow is on or a setting change is pending. Every string
    /// counts (the bridge keeps them coupled), each at its fundamental's decay rate
    /// ([`super::instrument::ring_out_s`]). Walks the delay lines: call once per block.
    pub fn ring_out_s(&self) -> Option<f64> {
        if !self.awake {
            return Some(0.0);
        }
        if self.pending.is_some() || self.bows.iter().any(|b| !b.is_lifted()) {
            return None;
        }
        let longest = self
            .core
            .strings
            .iter()
            .map(|s| super::instrument::ring_out_s(s.energy_j(), s.fundamental_hz(), s.q1()))
            .fold(0.0, f64::max);
        Some(longest)
    }

    /// Called once per block (it walks the lifted strings' delay lines). Each polarisation
    /// of a lifted string whose waves fall below half of [`SLEEP_ENERGY_J`] sleeps until
    /// what the bridge sends it adds up to as much
    /// ([`ThermalString::sleep_quiet_polarisations`]); once every polarisation sleeps and
    /// the bridge has rung out, the whole instrument sleeps.
    pub fn update_sleep(&mut self) {
        if !self.skipping || !self.awake || self.pending.is_some() {
            return;
        }
        let mut all_asleep = true;
        for (bow, string) in self.bows.iter().zip(&mut self.core.strings) {
            if bow.is_lifted() {
                string.sleep_quiet_polarisations(SLEEP_ENERGY_J);
            }
            all_asleep &= string.is_asleep();
        }
        if all_asleep && self.core.bridge.is_quiet(1e-12) {
            for s in &mut self.core.strings {
                s.reset();
            }
            self.core.bridge.reset();
            self.resampler.reset();
            self.core.probe = (0.0, 0.0);
            self.awake = false;
        }
    }

    /// One host sample.
    #[inline]
    pub fn tick(&mut self, bow: BowControl) -> Frame {
        if !self.awake && self.skipping {
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
        if let Some(retune) = self.fingering.glide_tick() {
            for (i, hz) in retune.into_iter().enumerate() {
                if let Some(f0) = hz {
                    if !self.tune(i, f0) {
                        self.bows[i].bowed = false;
                    }
                }
            }
        }
        let force_per_m = bow.force_n.max(0.0) / self.contact_width_m;
        for (i, (envelope, control)) in self
            .bows
            .iter_mut()
            .zip(self.core.bows.iter_mut())
            .enumerate()
        {
            let bow_gain = envelope.advance(self.ramp_step);
            let e = self.fingering.expression(i);
            *control = if e == NoteExpression::NEUTRAL {
                ThermalBowControl {
                    velocity_m_per_s: bow.velocity_m_per_s,
                    force_per_m: force_per_m * bow_gain,
                    position_beta: bow.position_beta,
                }
            } else {
                ThermalBowControl {
                    velocity_m_per_s: bow.velocity_m_per_s,
                    force_per_m: force_per_m * e.force_scale * bow_gain,
                    position_beta: (bow.position_beta * e.position_scale)
                        .clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
                }
            };
        }
        let mut out = [0.0];
        run_core(
            self.wide_simd,
            &mut self.resampler,
            &mut self.core,
            &mut out,
        );
        let audio = flush_tiny(out[0] * self.output_scale * self.fade);
        if !audio.is_finite() {
            // Cannot happen with finite inputs; recover to silence rather than emit garbage.
            self.reset();
            self.recoveries += 1;
            return Frame::default();
        }
        Frame {
            audio,
            bow_point_velocity_m_per_s: self.core.probe.0,
            friction_force_n: self.core.probe.1,
        }
    }

    /// How late the output is behind the strings, host samples (the resampler's delay).
    pub fn latency_samples(&self) -> f64 {
        self.resampler.latency_samples()
    }

    /// How often the non-finite guard in [`ThermalInstrument::tick`] has fired (it never
    /// should: the stress suite asserts zero).
    pub fn recoveries(&self) -> u64 {
        self.recoveries
    }

    /// Polarisations asleep now, of eight (all eight while the whole instrument sleeps).
    pub fn asleep_polarisations(&self) -> usize {
        if !self.awake {
            return 2 * STRINGS;
        }
        self.core
            .strings
            .iter()
            .map(|s| s.asleep().iter().filter(|a| **a).count())
            .sum()
    }

    /// Turns sleeping off (everything is computed every sample, silent or not) or on.
    pub fn set_skipping(&mut self, skipping: bool) {
        self.skipping = skipping;
    }

    /// A loop over [`ThermalInstrument::tick`] with constant bow settings.
    pub fn process(&mut self, bow: BowControl, out: &mut [f64]) {
        for sample in out {
            *sample = self.tick(bow).audio;
        }
    }
}
