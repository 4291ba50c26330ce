//! One interface for everything a note can play: the waveguide instrument (paper A's
//! point laws), paper B's thermal instrument and the rubbed objects. The performer
//! ([`crate::performer`]) drives them through it, in SI units.
//!
//! ```
//! use colophony::dsp::engine::Engine;
//! use colophony::dsp::instrument::Instrument;
//! use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
//! let mut cello = Instrument::new(InstrumentKind::Cello, 48_000.0);
//! let engine: &mut dyn Engine = &mut cello;
//! engine.note_on(50);
//! let bow = BowControl { velocity_m_per_s: 0.1, force_n: 1.0, position_beta: 0.1 };
//! let sound: f64 = (0..4800).map(|_| engine.tick(bow).audio.abs()).sum();
//! assert!(sound > 0.0);
//! ```

use super::rubbed::RubbedInstrument;
use super::strings::{FourStrings, StringBank};
use super::vocabulary::{BowControl, Frame, NoteExpression, Pluck, Strike};

/// An instrument the notes play.
pub trait Engine {
    /// Lands the bow for `note`; the string (or object) it went to, `None` if ignored.
    fn note_on(&mut self, note: u8) -> Option<usize>;
    /// As [`Engine::note_on`], but a note landing on a string already bowed glides the
    /// finger there over `glide_s` seconds (portamento); engines without fingers land it.
    fn note_on_gliding(&mut self, note: u8, _glide_s: f64) -> Option<usize> {
        self.note_on(note)
    }
    /// Plucks `note` (pizzicato) with `pluck`: the string it went to, `None` if the
    /// engine cannot pluck it (engines without plucked strings: always).
    fn pluck(&mut self, _note: u8, _pluck: Pluck) -> Option<usize> {
        None
    }
    /// Strikes `note` with the bow's stick (col legno battuto): the string it went to,
    /// `None` if the engine cannot (engines without struck strings: always).
    fn strike(&mut self, _note: u8, _strike: Strike) -> Option<usize> {
        None
    }
    /// Lifts the bow from `note` (and, on strings, the finger that stops it).
    fn note_off(&mut self, note: u8);
    fn all_notes_off(&mut self);
    /// Whether released notes keep their fingers down (the sustain pedal): their strings
    /// ring on at the stopped pitch until it is let go (engines without fingers ignore it).
    fn set_fingers_held(&mut self, _held: bool) {}
    /// A mute on the bridge (con sordino) or none (engines without one ignore it).
    fn set_mute(&mut self, _on: bool) {}
    /// Pitch bend, semitones (engines without pitch ignore it).
    fn set_pitch_bend(&mut self, _semitones: f64) {}
    /// The dynamics' expression the Dynamics Guard plays the bow at (0..=1; engines
    /// without an intonation that follows it ignore it).
    fn set_dynamics(&mut self, _expression: f64) {}
    /// String `string`'s note's own expression (engines without strings ignore it).
    fn set_note_expression(&mut self, _string: usize, _expression: NoteExpression) {}
    /// The string later notes go to (0 = lowest), `None` for the usual choice.
    fn set_preferred_string(&mut self, _string: Option<usize>) {}
    /// Reference pitch A4, Hz.
    fn set_reference_pitch(&mut self, _a4_hz: f64) {}
    /// Once per block: what is lifted and quiet sleeps.
    fn update_sleep(&mut self);
    /// Whether anything is awake (bowed, or ringing on).
    fn is_sounding(&self) -> bool;
    /// Whether anything still rings, its resonators included.
    fn is_ringing(&self) -> bool {
        self.is_sounding()
    }
    /// Seconds until it would fall asleep with no new note (the host's tail), `None` while
    /// a bow is on. Walks delay lines: once per block.
    fn ring_out_s(&self) -> Option<f64>;
    /// One sample.
    fn tick(&mut self, bow: BowControl) -> Frame;
    /// How late the output is behind the model, host samples (a resampler's delay).
    fn latency_samples(&self) -> f64 {
        0.0
    }
    /// Silence and forget every note.
    fn reset(&mut self);
}

/// Both string instruments are [`FourStrings`]: every method is already there.
impl<B: StringBank> Engine for FourStrings<B> {
    fn note_on(&mut self, note: u8) -> Option<usize> {
        FourStrings::note_on(self, note)
    }
    fn note_on_gliding(&mut self, note: u8, glide_s: f64) -> Option<usize> {
        FourStrings::note_on_gliding(self, note, glide_s)
    }
    fn pluck(&mut self, note: u8, pluck: Pluck) -> Option<usize> {
        FourStrings::pluck(self, note, pluck)
    }
    fn strike(&mut self, note: u8, strike: Strike) -> Option<usize> {
        FourStrings::strike(self, note, strike)
    }
    fn note_off(&mut self, note: u8) {
        FourStrings::note_off(self, note)
    }
    fn all_notes_off(&mut self) {
        FourStrings::all_notes_off(self)
    }
    fn set_fingers_held(&mut self, held: bool) {
        FourStrings::set_fingers_held(self, held)
    }
    fn set_pitch_bend(&mut self, semitones: f64) {
        FourStrings::set_pitch_bend(self, semitones)
    }
    fn set_dynamics(&mut self, expression: f64) {
        FourStrings::set_dynamics(self, expression)
    }
    fn set_mute(&mut self, on: bool) {
        FourStrings::set_mute(self, on)
    }
    fn set_note_expression(&mut self, string: usize, expression: NoteExpression) {
        FourStrings::set_note_expression(self, string, expression)
    }
    fn set_preferred_string(&mut self, string: Option<usize>) {
        FourStrings::set_preferred_string(self, string)
    }
    fn set_reference_pitch(&mut self, a4_hz: f64) {
        FourStrings::set_reference_pitch(self, a4_hz)
    }
    fn update_sleep(&mut self) {
        FourStrings::update_sleep(self)
    }
    fn is_sounding(&self) -> bool {
        FourStrings::is_sounding(self)
    }
    fn is_ringing(&self) -> bool {
        FourStrings::is_ringing(self)
    }
    fn ring_out_s(&self) -> Option<f64> {
        FourStrings::ring_out_s(self)
    }
    fn tick(&mut self, bow: BowControl) -> Frame {
        FourStrings::tick(self, bow)
    }
    fn latency_samples(&self) -> f64 {
        FourStrings::latency_samples(self)
    }
    fn reset(&mut self) {
        FourStrings::reset(self)
    }
}

/// The rubbed objects take every note as one exciter on the active object (a note held
/// twice counts twice: the performer sends each held key once).
impl Engine for RubbedInstrument {
    fn note_on(&mut self, _note: u8) -> Option<usize> {
        RubbedInstrument::note_on(self);
        Some(0)
    }
    fn note_off(&mut self, _note: u8) {
        RubbedInstrument::note_off(self)
    }
    fn all_notes_off(&mut self) {
        RubbedInstrument::all_notes_off(self)
    }
    fn update_sleep(&mut self) {
        RubbedInstrument::update_sleep(self)
    }
    fn is_sounding(&self) -> bool {
        RubbedInstrument::is_sounding(self)
    }
    fn ring_out_s(&self) -> Option<f64> {
        self.ring_out_samples().map(|n| n / self.sample_rate_hz())
    }
    fn tick(&mut self, bow: BowControl) -> Frame {
        Frame {
            audio: self.tick(&bow),
            ..Frame::default()
        }
    }
    fn reset(&mut self) {
        RubbedInstrument::reset(self)
    }
}
