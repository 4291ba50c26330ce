//! What both string instruments (the point-bow [`super::instrument::Instrument`] and
//! paper B's [`super::thermal_instrument::ThermalInstrument`], both a
//! [`super::strings::FourStrings`]) hold between a note and their strings: which string a
//! note goes to, where the finger stops it (equal temperament under the pitch bend, the
//! note's own bend, a finger glide and the reference pitch, moved by the intonation
//! table), and the bow's envelope on each string. The string banks keep what differs:
//! their strings, how a string is retuned, and how they sleep.
//!
//! ```
//! use colophony::dsp::fingering::{BowEnvelope, Fingering};
//! use colophony::dsp::vocabulary::InstrumentKind;
//! let mut f = Fingering::new(InstrumentKind::Cello, Some(0));
//! let string = f.string_for_note_on(50).unwrap(); // D3: the D string
//! f.start(string, 50);
//! let free = f.tuned_hz(string);
//! assert!(f.set_pitch_bend(1.0)); // a changed bend: the instrument retunes
//! assert!(f.tuned_hz(string) > free);
//! let mut bow = BowEnvelope::default();
//! bow.bowed = true;
//! assert_eq!(bow.tick(0.5), 0.5);
//! ```

use super::intonation::{self, IntonationTable};
use super::vocabulary::{
    reference_semitones, InstrumentKind, NoteExpression, MAX_BEND_RANGE_SEMITONES, STRINGS,
};

/// The bow on one string: whether it is down, and how far it rests on the string, 0
/// (lifted) to 1 (full force), ramping between.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BowEnvelope {
    pub bowed: bool,
    pub gain: f64,
}

impl BowEnvelope {
    /// Whether the ramp has arrived: [`BowEnvelope::tick`] then changes nothing.
    pub fn is_settled(&self) -> bool {
        self.gain == if self.bowed { 1.0 } else { 0.0 }
    }

    /// One step of the ramp toward 1 (bowed) or 0 (lifted) by `step`; returns the gain.
    #[inline(always)]
    pub fn tick(&mut self, step: f64) -> f64 {
        let target = if self.bowed { 1.0 } else { 0.0 };
        if self.gain != target {
            self.gain = if self.bowed {
                (self.gain + step).min(1.0)
            } else {
                (self.gain - step).max(0.0)
            };
        }
        self.gain
    }

    /// Lifted and at rest.
    pub fn is_lifted(&self) -> bool {
        !self.bowed && self.gain == 0.0
    }
}

/// Ticks between two retunes of a gliding finger at 48 kHz (1.3 ms); at another tick
/// rate, as many as make the same time ([`Fingering::glide_to`]), so a string at a high
/// internal rate (paper B's at N_B 60: 542 kHz) is not retuned eleven times as often.
pub const GLIDE_EVERY: u32 = 64;
/// The smallest move of the dynamics' expression the performer retunes the strings for
/// while the dynamics glide (the correction moves by a cent or two over it, and a move
/// retunes a few times, not every sample); it retunes again where they come to rest.
pub const DYNAMICS_INTONATION_STEP: f64 = 1.0 / 64.0;

/// Notes, fingers and tuning of the four strings (see the module doc).
#[derive(Debug, Clone)]
pub struct Fingering {
    kind: InstrumentKind,
    notes: [Option<u8>; STRINGS],
    /// Each note's own expression ([`NoteExpression::NEUTRAL`] until one arrives).
    expressions: [NoteExpression; STRINGS],
    /// A finger glide under way: semitones still to go to the note (0: none).
    glides: [f64; STRINGS],
    /// Semitones a glide moves per step ([`Fingering::glide_tick`]).
    glide_steps: [f64; STRINGS],
    /// Whether a finger glides, and the ticks to its next step.
    gliding: bool,
    glide_countdown: u32,
    /// Ticks between two retunes at the glide's tick rate.
    glide_every: u32,
    /// The string the player asks notes to go to (0 = lowest), `None` for the usual choice.
    preferred_string: Option<usize>,
    bend_semitones: f64,
    /// The reference pitch's offset from A4 = 440 Hz ([`reference_semitones`]).
    reference_semitones: f64,
    /// Tuning by the bowed sound; `None` tunes by the free decay.
    intonation: Option<&'static IntonationTable>,
    /// The intonation table's row (the friction model).
    intonation_row: usize,
    /// The dynamics' expression the intonation follows (1: full, the defaults).
    dynamics: f64,
    /// Whether each string was plucked (or struck): it sounds its free pitch, which the
    /// bowed rows of the table do not move.
    plucked: [bool; STRINGS],
    /// The table's row that tunes a plucked string's free pitch (`None`: its free decay
    /// is its pitch, [`intonation::THERMAL_FREE_ROW`] for paper B's thermal strings).
    free_row: Option<usize>,
    /// The partial each string's note sounds: 1 (its fundamental), or more for a harmonic
    /// (the string stopped that many times under the note, a finger touching it).
    partials: [u8; STRINGS],
}

impl Fingering {
    /// `kind`'s strings with no note, tuned by the shipped intonation table's row
    /// `intonation_row` (`None`: by the free decay).
    pub fn new(kind: InstrumentKind, intonation_row: Option<usize>) -> Self {
        Self {
            kind,
            notes: [None; STRINGS],
            expressions: [NoteExpression::NEUTRAL; STRINGS],
            glides: [0.0; STRINGS],
            glide_steps: [0.0; STRINGS],
            gliding: false,
            glide_countdown: 0,
            glide_every: GLIDE_EVERY,
            preferred_string: None,
            bend_semitones: 0.0,
            reference_semitones: 0.0,
            intonation: intonation_row.map(|_| intonation::shipped()),
            intonation_row: intonation_row.unwrap_or(0),
            dynamics: 1.0,
            plucked: [false; STRINGS],
            free_row: None,
            partials: [1; STRINGS],
        }
    }

    /// The intonation table's row that tunes plucked and struck notes (`None`: they are
    /// stopped at their equal-tempered free pitch).
    pub fn set_free_row(&mut self, row: Option<usize>) {
        self.free_row = row;
    }

    /// Another instrument: every note forgotten (the bend, the reference and the
    /// expressions stay; a new note starts neutral).
    pub fn set_kind(&mut self, kind: InstrumentKind) {
        self.kind = kind;
        self.notes = [None; STRINGS];
    }

    /// Every note and glide forgotten (the expressions stay; a new note starts neutral).
    pub fn release_all(&mut self) {
        self.notes = [None; STRINGS];
        self.glides = [0.0; STRINGS];
        self.gliding = false;
    }

    /// The string a new note goes to ([`InstrumentKind::string_for_note_on`], with the
    /// preferred string), `None` if no string can play it.
    pub fn string_for_note_on(&self, note: u8) -> Option<usize> {
        self.kind.string_for_note_on(note, self.preferred_string)
    }

    /// Asks later notes to go to string `preferred` (0 = the lowest) where it can play
    /// them; `None` restores the usual choice. Notes already sounding stay where they are.
    pub fn set_preferred_string(&mut self, preferred: Option<usize>) {
        self.preferred_string = preferred.filter(|&p| p < STRINGS);
    }

    /// Whether `string` is plucked (tuned by its free pitch) or bowed, until set again.
    pub fn set_plucked(&mut self, string: usize, plucked: bool) {
        if let Some(p) = self.plucked.get_mut(string) {
            *p = plucked;
        }
    }

    /// `string`'s note sounds its `partial` (a harmonic; 1: its fundamental), until set
    /// again.
    pub fn set_partial(&mut self, string: usize, partial: u8) {
        if let Some(p) = self.partials.get_mut(string) {
            *p = partial.max(1);
        }
    }

    /// The partial `string`'s note sounds (1 unless a harmonic).
    pub fn partial(&self, string: usize) -> u8 {
        self.partials[string.min(STRINGS - 1)]
    }

    /// The note `string` is stopped at: its note, or for a harmonic the note its
    /// partial sounds over.
    pub fn stopped_note(&self, string: usize) -> Option<u8> {
        let partial = self.partial(string);
        self.notes[string.min(STRINGS - 1)]
            .map(|n| n.saturating_sub(crate::dsp::vocabulary::partial_semitones(partial)))
    }

    /// How `note` is played as a harmonic on these strings, the player's preferred string
    /// first ([`InstrumentKind::harmonic_for`]).
    pub fn harmonic_for(&self, note: u8) -> Option<crate::dsp::vocabulary::HarmonicFingering> {
        self.kind.harmonic_for(note, self.preferred_string)
    }

    /// A new note on `string`: neutral expression, no glide.
    pub fn start(&mut self, string: usize, note: u8) {
        self.notes[string] = Some(note);
        self.expressions[string] = NoteExpression::NEUTRAL;
        self.glides[string] = 0.0;
    }

    /// `string`'s note becomes `note` with the finger `glide` semitones away from it,
    /// keeping the note's expression (a legato glide), to arrive after `glide_s` seconds of
    /// [`Fingering::glide_tick`] called at `rate_hz` (linearly in semitones, a step every
    /// [`GLIDE_EVERY`] ticks at 48 kHz, the same time at `rate_hz`).
    pub fn glide_to(&mut self, string: usize, note: u8, glide: f64, glide_s: f64, rate_hz: f64) {
        let every = (GLIDE_EVERY as f64 * rate_hz / 48_000.0).round();
        self.glide_every = if every.is_finite() {
            every.clamp(1.0, 1e6) as u32
        } else {
            GLIDE_EVERY
        };
        let steps = (glide_s * rate_hz / self.glide_every as f64).max(1.0);
        self.notes[string] = Some(note);
        self.glides[string] = glide;
        self.glide_steps[string] = glide.abs() / steps;
        self.gliding = glide != 0.0;
        self.glide_countdown = 0;
    }

    /// One tick of the instrument (a sample at the rate given to
    /// [`Fingering::glide_to`]): every [`GLIDE_EVERY`] ticks (at 48 kHz; the same time at
    /// another rate) while a finger glides, moves every gliding finger one step and
    /// returns the pitch (Hz) each string that moved and holds a note should now be tuned
    /// to.
    #[inline]
    pub fn glide_tick(&mut self) -> Option<[Option<f64>; STRINGS]> {
        if !self.gliding {
            return None;
        }
        let due = self.glide_countdown == 0;
        let retune = due.then(|| {
            self.glide_countdown = self.glide_every;
            self.tick_glides()
        });
        self.glide_countdown -= 1;
        retune
    }

    /// Whether a finger is gliding (a retune due within the next samples).
    pub fn is_gliding(&self) -> bool {
        self.gliding
    }

    /// The note on `string`, if any.
    pub fn note(&self, string: usize) -> Option<u8> {
        self.notes.get(string).copied().flatten()
    }

    /// Semitones `string`'s finger still has to glide.
    pub fn glide(&self, string: usize) -> f64 {
        self.glides[string]
    }

    /// Moves every gliding finger one step toward its note. Returns the pitch (Hz) each
    /// string that moved and holds a note should now be tuned to.
    fn tick_glides(&mut self) -> [Option<f64>; STRINGS] {
        let mut retune = [None; STRINGS];
        let mut any = false;
        for i in 0..STRINGS {
            let g = self.glides[i];
            if g == 0.0 {
                continue;
            }
            let step = self.glide_steps[i];
            self.glides[i] = if g > 0.0 {
                (g - step).max(0.0)
            } else {
                (g + step).min(0.0)
            };
            any |= self.glides[i] != 0.0;
            if self.notes[i].is_some() {
                retune[i] = Some(self.tuned_hz(i));
            }
        }
        self.gliding = any;
        retune
    }

    /// `string`'s note expression.
    pub fn expression(&self, string: usize) -> NoteExpression {
        self.expressions
            .get(string)
            .copied()
            .unwrap_or(NoteExpression::NEUTRAL)
    }

    /// Gives `string` its note's own expression (sanitized; see [`NoteExpression`]).
    /// Returns whether a sounding note must be retuned (its bend changed); `false` for a
    /// string that does not exist.
    pub fn set_expression(&mut self, string: usize, expression: NoteExpression) -> bool {
        let Some(e) = self.expressions.get_mut(string) else {
            return false;
        };
        e.replace(expression) && self.notes[string].is_some()
    }

    /// Puts `string`'s note and expression back (a note the string refused).
    pub fn restore(&mut self, string: usize, note: Option<u8>, expression: NoteExpression) {
        self.notes[string] = note;
        self.expressions[string] = expression;
    }

    /// `string` with no note, a neutral expression and no glide.
    pub fn clear_string(&mut self, string: usize) {
        self.notes[string] = None;
        self.expressions[string] = NoteExpression::NEUTRAL;
        self.glides[string] = 0.0;
    }

    /// Every string cleared ([`Fingering::clear_string`]).
    pub fn clear(&mut self) {
        for i in 0..STRINGS {
            self.clear_string(i);
        }
        self.gliding = false;
    }

    /// The reference pitch's offset from A4 = 440 Hz, semitones.
    pub fn reference_semitones(&self) -> f64 {
        self.reference_semitones
    }

    /// Pitch bend in semitones (clamped to [`MAX_BEND_RANGE_SEMITONES`]; NaN ignored).
    /// Returns whether it changed (every sounding note must be retuned).
    pub fn set_pitch_bend(&mut self, semitones: f64) -> bool {
        if semitones.is_nan() {
            return false;
        }
        let semitones = semitones.clamp(-MAX_BEND_RANGE_SEMITONES, MAX_BEND_RANGE_SEMITONES);
        if semitones == self.bend_semitones {
            return false;
        }
        self.bend_semitones = semitones;
        true
    }

    /// Tunes every note from the reference pitch `a4_hz` (415..466 Hz; see
    /// [`reference_semitones`]). Returns whether it changed.
    pub fn set_reference_pitch(&mut self, a4_hz: f64) -> bool {
        let semitones = reference_semitones(a4_hz);
        if semitones == self.reference_semitones {
            return false;
        }
        self.reference_semitones = semitones;
        true
    }

    /// Tunes by the bowed sound with `table`, or by the free decay with `None`. Every
    /// sounding note must then be retuned.
    pub fn set_intonation(&mut self, table: Option<&'static IntonationTable>) {
        self.intonation = table;
    }

    /// The dynamics' expression the bow is played at (0..=1: the intonation table's
    /// correction follows it, [`intonation::SOFT_EXPRESSIONS`]); returns whether it
    /// changed, so the instrument retunes.
    pub fn set_dynamics(&mut self, expression: f64) -> bool {
        let e = if expression.is_finite() {
            expression.clamp(0.0, 1.0)
        } else {
            1.0
        };
        let changed = e != self.dynamics;
        self.dynamics = e;
        changed
    }

    /// The intonation table's row in use (the friction model); returns whether it changed.
    pub fn set_intonation_row(&mut self, row: usize) -> bool {
        let changed = row != self.intonation_row;
        self.intonation_row = row;
        changed
    }

    /// The free-decay pitch `string` is stopped at for its note (0 Hz for none): equal
    /// temperament under the bend, the note's own bend, the glide and the reference,
    /// moved by the intonation table ([`intonation::tuned_hz`]) unless it is plucked.
    pub fn tuned_hz(&self, string: usize) -> f64 {
        match self.notes[string] {
            Some(note) => self.tuned_hz_for(string, note),
            None => 0.0,
        }
    }

    /// As [`Fingering::tuned_hz`] for `note` on `string`.
    pub fn tuned_hz_for(&self, string: usize, note: u8) -> f64 {
        let s = string.min(STRINGS - 1);
        if self.partials[s] > 1 {
            return self.harmonic_hz(s, note);
        }
        let (table, row) = match (self.plucked[s], self.free_row) {
            (false, _) => (self.intonation, self.intonation_row),
            (true, Some(row)) => (self.intonation, row),
            (true, None) => (None, 0),
        };
        intonation::tuned_hz(
            table,
            row,
            self.kind,
            string,
            note,
            self.bends_semitones(string),
            self.reference_semitones,
            self.dynamics,
        )
    }

    /// Every bend on `string`'s note, semitones: the pitch bend, its glide and its own
    /// expression's bend.
    fn bends_semitones(&self, string: usize) -> f64 {
        self.bend_semitones + self.glides[string] + self.expressions[string].bend_semitones
    }

    /// A harmonic `note` on string `s`: the pitch its string is stopped at, the note's
    /// (with its bends) over its partial. The intonation table does not move it: a touched
    /// string bowed at its partial does not sound where a stopped string bowed at that
    /// pitch does, so the stopped notes' corrections do not carry over
    /// (docs/articulations.md#harmonics).
    fn harmonic_hz(&self, s: usize, note: u8) -> f64 {
        let played = note as f64 + self.bends_semitones(s);
        crate::dsp::vocabulary::midi_to_hz(played + self.reference_semitones)
            / self.partials[s] as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_intonation_follows_the_dynamics_by_the_tables_soft_corrections() {
        let kind = InstrumentKind::Cello;
        let mut table = IntonationTable::zero();
        // F#3 on the D string (4 semitones up): +2 cents at full expression, +14 at a third.
        table.set(0, kind, 2, 4, 2.0);
        table.set_soft(
            0,
            kind,
            2,
            4,
            intonation::soft_level(1.0 / 3.0).unwrap(),
            14.0,
        );
        let mut f = Fingering::new(kind, Some(0));
        f.set_intonation(Some(Box::leak(Box::new(table))));
        let string = f.string_for_note_on(54).unwrap();
        assert_eq!(string, 2);
        f.start(string, 54);
        let full = f.tuned_hz(string);
        assert!(f.set_dynamics(1.0 / 3.0), "a new expression retunes");
        let soft = f.tuned_hz(string);
        // The string is stopped 12 cents lower so that the soft bow's sharper pitch lands
        // on the note (1e-9: rounding).
        let cents = 1200.0 * (soft / full).log2();
        assert!((cents + 12.0).abs() < 1e-9, "{cents}");
        assert!(
            !f.set_dynamics(1.0 / 3.0),
            "the same expression does not retune"
        );
        // Out of range and NaN are full expression or clamped, never a NaN pitch.
        f.set_dynamics(f64::NAN);
        assert_eq!(f.tuned_hz(string), full);
        f.set_dynamics(-3.0);
        assert!(f.tuned_hz(string).is_finite());
    }

    /// A plucked note is stopped by the free-ring row where the strings have one (paper
    /// B's thermal strings), at its equal-tempered free pitch where they do not, and a
    /// bowed note by the bowed row either way.
    #[test]
    fn a_plucked_note_is_tuned_by_the_free_ring_row_where_the_strings_have_one() {
        let kind = InstrumentKind::Cello;
        let mut table = IntonationTable::zero();
        // F#3 on the D string: bowed row +3 cents, free row -8 cents.
        table.set(0, kind, 2, 4, 3.0);
        table.set(intonation::THERMAL_FREE_ROW, kind, 2, 4, -8.0);
        let table: &'static IntonationTable = Box::leak(Box::new(table));
        let equal = crate::dsp::vocabulary::midi_to_hz(54.0);
        let cents_from_equal = |free_row: Option<usize>, plucked: bool| {
            let mut f = Fingering::new(kind, Some(0));
            f.set_intonation(Some(table));
            f.set_free_row(free_row);
            f.start(2, 54);
            f.set_plucked(2, plucked);
            1200.0 * (f.tuned_hz(2) / equal).log2()
        };
        // The correction is subtracted: a note that sounds sharp is stopped lower (1e-9:
        // rounding).
        let free = Some(intonation::THERMAL_FREE_ROW);
        assert!((cents_from_equal(free, true) - 8.0).abs() < 1e-9);
        assert!(cents_from_equal(None, true).abs() < 1e-9);
        assert!((cents_from_equal(free, false) + 3.0).abs() < 1e-9);
        assert!((cents_from_equal(None, false) + 3.0).abs() < 1e-9);
    }

    /// A glide takes the time asked and retunes about every 1.3 ms at any tick rate: 64
    /// ticks at 48 kHz, 128 at 96 kHz, 1445 at paper B's 1.08 MHz ceiling.
    #[test]
    fn a_glide_retunes_at_the_same_time_step_and_arrives_on_time_at_every_rate() {
        for rate in [48_000.0, 96_000.0, 541_600.0, 1_084_000.0] {
            let mut f = Fingering::new(InstrumentKind::Cello, None);
            let string = f.string_for_note_on(50).unwrap();
            f.start(string, 50);
            // From two semitones below, over 0.1 s.
            f.glide_to(string, 52, -2.0, 0.1, rate);
            let (mut retunes, mut arrived) = (Vec::new(), None);
            for tick in 0..(0.2 * rate) as usize {
                if f.glide_tick().is_some() {
                    retunes.push(tick);
                }
                if arrived.is_none() && f.glide(string) == 0.0 {
                    arrived = Some(tick as f64 / rate);
                }
            }
            let step_s = (retunes[1] - retunes[0]) as f64 / rate;
            // The step is rounded to whole ticks: within one tick of 64/48000 s.
            assert!(
                (step_s - 64.0 / 48_000.0).abs() <= 1.0 / rate,
                "{rate} Hz: a retune every {step_s} s"
            );
            // Arrives within one step of the 0.1 s asked.
            let arrived = arrived.expect("the glide arrives");
            assert!(
                (arrived - 0.1).abs() <= step_s,
                "{rate} Hz: arrived after {arrived} s"
            );
        }
    }
}
