//! The DSP's shared vocabulary: the instruments and their data ([`InstrumentKind`]), the
//! bow as the performer hands it to an engine ([`BowControl`]), what an engine gives back
//! each sample ([`Frame`]), a note's own expression ([`NoteExpression`]), and the tuning
//! and range constants. A leaf: it imports only the string and body data types it is
//! made of, never an engine.

/// Largest correction the intonation table may hold, cents (the tuning margins of the
/// instruments' buffers include it).
pub const MAX_CORRECTION_CENTS: f64 = 50.0;

/// The rate the point-bow strings and their body run at, whatever the host's: the output
/// is resampled to the host rate ([`super::resample::Resampler`]). The bowed string's regime (Helmholtz
/// motion or a double slip: both are stable over much of the window, and which one an
/// attack falls into changes with any detail of the discretisation) and its pitch then do
/// not depend on the project's rate, and the intonation table, measured at this rate,
/// holds at every rate. 48 kHz: the commonest host rate (no resampling there), and twice
/// the hearing range. Measured in docs/precision.md. The violin's and
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

/// Physical data of one string, open (the waveguide string's, [`super::waveguide`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StringSpec {
    pub open_hz: f64,
    pub z0_kg_per_s: f64,
    /// `B` of the open string; a stopped string of length `L'` has `B (L / L')^2`.
    pub inharmonicity_open: f64,
    pub q1: f64,
    pub q_hi: f64,
}

/// One mode of the point-bow instrument's body ([`super::body`]): centre frequency, quality factor, gain relative to the direct path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMode {
    pub freq_hz: f64,
    pub q: f64,
    pub gain: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InstrumentKind {
    Violin,
    Viola,
    Cello,
    /// The orchestral double bass, tuned in fourths E1 A1 D2 G2.
    DoubleBass,
}

/// All of an instrument's data, read everywhere the instrument is played ([`SPECS`], one
/// per [`InstrumentKind`], in [`InstrumentKind::ALL`]'s order). Its shipped bridge for
/// paper B's model is its data file in `src/dsp/bridge_data.rs`
/// ([`super::bridge_data::shipped_bridge`]), its intonation rows are in
/// `assets/intonation.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InstrumentSpec {
    /// Its name in presets, saved states, the renderer's `--instrument` and the data files.
    pub name: &'static str,
    /// MIDI notes of the open strings, low to high, equal-tempered from A4 = 440 Hz.
    pub open_notes: [u8; STRINGS],
    /// Each string's characteristic impedance `sqrt(T mu)`, kg/s, low to high.
    pub z0_kg_per_s: [f64; STRINGS],
    /// Each string's inharmonicity `B` (`f_n = n f_1 sqrt(1 + B n^2)`), low to high.
    pub inharmonicity: [f64; STRINGS],
    /// Quality factor of every string's fundamental, and at ten times it.
    pub q1: f64,
    pub q_hi: f64,
    /// Vibrating length of the open strings, m.
    pub string_length_m: f64,
    /// The generic body's modal frequencies over the violin's (`InstrumentKind::body_modes`).
    pub body_scale: f64,
    /// How many times [`INTERNAL_RATE_HZ`] each point-bow string runs at
    /// ([`InstrumentKind::point_oversampling`]).
    pub point_oversampling: [usize; STRINGS],
    /// Where the body's radiation falls above the bridge's resonances, Hz: the corner of
    /// a fourth-order Butterworth low-pass after the modes ([`super::body::TopFall`]),
    /// or `None` where the measured body falls no faster than the violin's within 5 kHz.
    pub top_fall_hz: Option<f64>,
}

/// Every instrument's data (docs/literature-values.md §1.4: the Desvages/NESS string sets;
/// the viola's G, D, A inharmonicities are not in the table and are chosen between the
/// neighbouring violin and viola values; lengths violin 0.32, viola 0.38, cello 0.69 m;
/// the double bass below).
pub const SPECS: [InstrumentSpec; InstrumentKind::COUNT] = [
    InstrumentSpec {
        name: "violin",
        open_notes: [55, 62, 69, 76],
        z0_kg_per_s: [0.350, 0.303, 0.203, 0.173],
        inharmonicity: [2.7e-4, 2.3e-4, 2.1e-4, 4.8e-5],
        q1: 500.0,
        q_hi: 250.0,
        string_length_m: 0.32,
        body_scale: 1.0,
        point_oversampling: [2; STRINGS],
        top_fall_hz: None,
    },
    InstrumentSpec {
        name: "viola",
        open_notes: [48, 55, 62, 69],
        z0_kg_per_s: [0.484, 0.323, 0.281, 0.274],
        inharmonicity: [3.4e-4, 2.7e-4, 2.3e-4, 2.1e-4],
        q1: 500.0,
        q_hi: 250.0,
        string_length_m: 0.38,
        body_scale: 0.8,
        point_oversampling: [2; STRINGS],
        top_fall_hz: None,
    },
    InstrumentSpec {
        name: "cello",
        open_notes: [36, 43, 50, 57],
        z0_kg_per_s: [1.91, 0.833, 0.506, 0.504],
        inharmonicity: [5.7e-4, 1.7e-4, 1.5e-4, 5.3e-5],
        q1: 500.0,
        q_hi: 250.0,
        string_length_m: 0.69,
        body_scale: 0.42,
        point_oversampling: [1, 1, 1, 2],
        top_fall_hz: Some(3450.0),
    },
    // Tension and linear density from Russo, Ducceschi and Zambon's double bass strings
    // (DAFx 2022, 1.06 m; docs/literature-values.md §1.4): Z0 = sqrt(T mu). Their strings
    // are solid steel of the wound string's mass, whose bending stiffness overstates a
    // wound string's (its core bends, the winding adds mass): B is theirs times 1/16, a
    // core of half the outer radius (chosen, not measured). The body's modes sit at 0.23
    // of the violin's (A0 near 63 Hz).
    InstrumentSpec {
        name: "double-bass",
        open_notes: [28, 33, 38, 43],
        z0_kg_per_s: [3.56, 2.58, 1.87, 1.38],
        inharmonicity: [7.6e-4, 2.3e-4, 7.1e-5, 2.2e-5],
        q1: 500.0,
        q_hi: 250.0,
        string_length_m: 1.06,
        body_scale: 0.23,
        point_oversampling: [1; STRINGS],
        top_fall_hz: None,
    },
];

impl InstrumentKind {
    /// How many instruments there are.
    pub const COUNT: usize = 4;
    pub const ALL: [InstrumentKind; Self::COUNT] =
        [Self::Violin, Self::Viola, Self::Cello, Self::DoubleBass];

    /// The lowest open string of any instrument, MIDI note: what every string bank is
    /// sized for, so that an instrument switch never reallocates.
    pub const LOWEST_OPEN_NOTE: u8 = {
        let mut lowest = u8::MAX;
        let mut i = 0;
        while i < Self::COUNT {
            if SPECS[i].open_notes[0] < lowest {
                lowest = SPECS[i].open_notes[0];
            }
            i += 1;
        }
        lowest
    };

    /// Its place in [`Self::ALL`] and [`SPECS`].
    pub const fn index(self) -> usize {
        self as usize
    }

    /// All of its data.
    pub const fn spec(self) -> &'static InstrumentSpec {
        &SPECS[self.index()]
    }

    pub fn name(self) -> &'static str {
        self.spec().name
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(name))
    }

    /// MIDI notes of the open strings, low to high.
    pub fn open_notes(self) -> [u8; STRINGS] {
        self.spec().open_notes
    }

    /// String data, low to high ([`InstrumentSpec`]). Open pitches are equal-tempered from
    /// A4 = 440 Hz.
    pub fn strings(self) -> [StringSpec; STRINGS] {
        let spec = self.spec();
        std::array::from_fn(|i| StringSpec {
            open_hz: midi_to_hz(spec.open_notes[i] as f64),
            z0_kg_per_s: spec.z0_kg_per_s[i],
            inharmonicity_open: spec.inharmonicity[i],
            q1: spec.q1,
            q_hi: spec.q_hi,
        })
    }

    /// Generic body modes (see [`super::body`]); the last is the bridge hill
    /// ([`InstrumentKind::bridge_hill`]).
    pub(crate) fn body_modes(self) -> [BodyMode; 5] {
        let scale = self.spec().body_scale;
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

    /// The bridge hill: the bridge rocking on its feet, the last of
    /// [`InstrumentKind::body_modes`] (its frequency and Q are what a mute loads,
    /// [`super::body::Biquad::mute_load`]).
    pub fn bridge_hill(self) -> BodyMode {
        self.body_modes()[4]
    }

    /// The body's air resonance A0, Hz: its first mode, where its radiation turns on
    /// ([`super::radiation`]).
    pub fn a0_hz(self) -> f64 {
        self.body_modes()[0].freq_hz
    }

    /// What the bow force is multiplied by on string `index` when the strings are weighted
    /// ([`super::strings::FourStrings::set_string_weighting`]): the string's impedance over
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
        self.spec().point_oversampling
    }

    /// Output scale: bridge force to a sample value, so that a default note of any
    /// instrument peaks near -12 dBFS.
    pub fn output_scale_per_n(self) -> f64 {
        let mean_z0: f64 =
            self.strings().iter().map(|s| s.z0_kg_per_s).sum::<f64>() / STRINGS as f64;
        0.1 / mean_z0
    }

    /// Vibrating length of the open strings, m.
    pub fn string_length_m(self) -> f64 {
        self.spec().string_length_m
    }

    /// The string a note goes to, if the instrument can play it.
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

    /// How `note` is played as a harmonic: a natural harmonic (an open string's partial in
    /// [`NATURAL_HARMONICS`], the lowest partial first, on the highest string that has
    /// it, or the `preferred` string's if it has one), or else an artificial one (the
    /// note two octaves down stopped, on the string [`Self::string_for_note_on`] gives it,
    /// touched a fourth above: its 4th partial). `None` if neither plays it.
    pub fn harmonic_for(self, note: u8, preferred: Option<usize>) -> Option<HarmonicFingering> {
        let open = self.open_notes();
        let strings = || {
            (0..STRINGS)
                .rev()
                .filter(move |s| preferred.is_none_or(|p| p == *s))
        };
        for partial in NATURAL_HARMONICS {
            for string in strings() {
                if open[string] as u16 + partial_semitones(partial) as u16 == note as u16 {
                    return Some(HarmonicFingering {
                        string,
                        stopped: open[string],
                        partial,
                    });
                }
            }
        }
        let stopped = note.checked_sub(partial_semitones(ARTIFICIAL_HARMONIC))?;
        let string = self.string_for_note_on(stopped, preferred)?;
        Some(HarmonicFingering {
            string,
            stopped,
            partial: ARTIFICIAL_HARMONIC,
        })
    }

    /// Playable notes, inclusive.
    pub fn note_range(self) -> (u8, u8) {
        let open = self.open_notes();
        (open[0], open[STRINGS - 1] + MAX_STOP_SEMITONES)
    }
}

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

/// The partials a natural harmonic is played on: those within 2 cents of equal
/// temperament (the 5th and 7th sit 14 and 31 cents flat of it, so a note there is played
/// as an artificial harmonic instead), in the order they are tried.
pub const NATURAL_HARMONICS: [u8; 5] = [2, 3, 4, 6, 8];
/// The artificial harmonic's partial: the stopped note's 4th, touched a fourth above the
/// stopping finger, two octaves above the stopped note.
pub const ARTIFICIAL_HARMONIC: u8 = 4;

/// How a harmonic is fingered: the string, the note it is stopped at (its open note for
/// a natural harmonic), and the partial a light finger at its node nearest the bridge
/// leaves sounding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HarmonicFingering {
    pub string: usize,
    pub stopped: u8,
    pub partial: u8,
}

/// Semitones from a fundamental up to its partial `n` in equal temperament, rounded.
pub fn partial_semitones(n: u8) -> u8 {
    (12.0 * (n.max(1) as f64).log2()).round() as u8
}

/// A finger's pluck (pizzicato): the string pulled aside at one point and let go from rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pluck {
    /// How far the finger pulls the string aside, m.
    pub displacement_m: f64,
    /// Where, as a distance from the bridge, m (the plucking hand stays near the
    /// fingerboard's end whatever note the other hand stops).
    pub from_bridge_m: f64,
    /// The finger's contact width, m: the kink the finger leaves is rounded over it (a
    /// fingertip's pad about a centimetre, a nail a few millimetres), which takes the
    /// partials whose half-wavelength is shorter than it out of the pluck.
    pub width_m: f64,
}

/// The bow's stick striking the string at the bow point (col legno battuto).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strike {
    /// The stick's effective mass at the point of impact, kg.
    pub mass_kg: f64,
    /// How fast it arrives, m/s.
    pub velocity_m_per_s: f64,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_instrument_reads_its_own_spec_and_its_name_finds_it() {
        for (i, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            assert_eq!(kind.index(), i);
            assert_eq!(InstrumentKind::from_name(kind.name()), Some(kind));
            let spec = kind.spec();
            // Open strings rise, and every string has a positive impedance and length.
            assert!(
                spec.open_notes.windows(2).all(|w| w[0] < w[1]),
                "{}",
                spec.name
            );
            assert!(spec.z0_kg_per_s.iter().all(|&z| z > 0.0) && spec.string_length_m > 0.0);
            assert!(spec
                .point_oversampling
                .iter()
                .all(|&o| (1..=MAX_POINT_OVERSAMPLING).contains(&o)));
        }
    }
}
