//! Note routing: which string takes a key, separate and legato notes, double stops on one
//! bow, the finger glide, and each key's own note expression.

use super::*;

/// What the performer remembers of a key's note for its per-note expression.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct NoteSlot {
    pub(super) channel: u8,
    pub(super) string: Option<u8>,
    pub(super) state: NoteState,
}

impl Performer {
    /// A key goes down with `velocity` (0..=1). A note that lands while no key is held
    /// starts a new bow stroke ([`stroke`]: direction by the setup's stroke mode, attack
    /// by the velocity); one that lands while another is held is legato (the stroke goes
    /// on; on the same string the finger moves and the bow stays on). A legato note below
    /// [`PORTAMENTO_BELOW_VELOCITY`], or any with CC65 down, glides the finger over the
    /// setup's glide time.
    pub fn note_on(&mut self, note: u8, velocity: f32) {
        self.note_on_channel(0, note, velocity);
    }

    /// A note on MIDI channel `channel` (0..=15): on an MPE member channel it takes that
    /// channel's bend, pressure and timbre as its own ([`mpe`]).
    pub fn note_on_channel(&mut self, channel: u8, note: u8, velocity: f32) {
        if self.take_keyswitch(note) {
            return;
        }
        self.notes[note as usize & 127] = NoteSlot {
            channel: channel & 15,
            string: None,
            state: NoteState::default(),
        };
        self.steady = None;
        if !matches!(self.source, Source::Rubbed(_)) {
            match self.articulation() {
                Articulation::Pizzicato => return self.pluck_note(note, velocity),
                Articulation::ColLegno => return self.strike_note(note, velocity),
                _ => {}
            }
        }
        let separate = !self.held.iter().any(|&h| h);
        if separate {
            self.land_dynamics();
        }
        // Portamento: a legato note played softly, or any legato note with CC65 down,
        // slides the finger there on the waveguide strings.
        let glide = !separate
            && (self.gesture.portamento_pedal
                || stroke::velocity_step(velocity) < PORTAMENTO_BELOW_VELOCITY);
        self.land(note, glide.then_some(self.setup.glide_s));
        // A note the source refused moves no bow.
        if separate && self.held[note as usize & 127] {
            self.stroke
                .start(self.setup.bow_strokes, stroke::velocity_step(velocity));
            self.stroke.limit_onset(self.onset_floor());
            let velocity = stroke::velocity_step(velocity);
            self.stroke.set_tremolo(self.tremolo_stroke());
            let spiccato = self.articulation() == Articulation::Spiccato;
            self.stroke.set_spiccato(spiccato, velocity);
            self.stroke
                .set_sautille(self.sautille_stroke().map(|s| (s, velocity)));
            self.catch = self.catch_for(note, velocity);
        }
    }

    /// The attack's catch for a separate note `note` of velocity `velocity` (a
    /// [`stroke::velocity_step`]): above mezzo, bowed arco on the strings (waveguide or
    /// thermal), on the string the note took ([`catch`]).
    fn catch_for(&self, note: u8, velocity: f64) -> Option<catch::Catch> {
        if !catch::catches(velocity) || self.articulation() != Articulation::Arco {
            return None;
        }
        let thermal = match self.source {
            Source::Strings => false,
            Source::Thermal(_) => true,
            Source::Rubbed(_) => return None,
        };
        let string = self.notes[note as usize & 127].string? as usize;
        // The bow position is the bow's own, sample by sample.
        let window = crate::measure::window::SchellengWindow::for_model(
            self.setup.instrument,
            string,
            MIN_NOTE_BETA,
            thermal,
            self.setup.string_weight,
        );
        catch::Catch::new(
            window,
            catch::CatchRule::for_law(if thermal { None } else { self.setup.point_law }),
            midi_to_hz(note as f64),
            self.sample_rate_hz,
        )
    }

    /// The note reaches the source (no new stroke); with `glide` (seconds), the strings
    /// (waveguide or thermal) slide the finger there.
    pub(super) fn land(&mut self, note: u8, glide: Option<f64>) {
        // A bow lands: whatever tail was estimated no longer holds.
        self.tail = None;
        self.gesture.since_note = 0;
        let key = note as usize & 127;
        match self.source {
            // Notes the instrument cannot play are ignored.
            Source::Strings => {
                self.instrument
                    .set_stick_contact(self.articulation() == Articulation::ColLegnoTratto);
                let landed = match glide {
                    // A note no harmonic plays (under two octaves above the lowest
                    // string, and no open string's partial) is played stopped.
                    _ if self.articulation() == Articulation::Harmonics => self
                        .instrument
                        .harmonic(note)
                        .or_else(|| self.instrument.note_on(note)),
                    Some(seconds) => self.instrument.note_on_gliding(note, seconds),
                    None => self.instrument.note_on(note),
                };
                self.took(note, landed);
            }
            Source::Thermal(k) => {
                self.choose_auto_nodes(note);
                let settings = self.thermal_settings();
                let harmonic = self.articulation() == Articulation::Harmonics;
                let stick = self.articulation() == Articulation::ColLegnoTratto;
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.set_stick_contact(stick);
                    // A new node count fades the instrument out and lands the note after.
                    engine.set_settings(settings);
                    let landed = match glide {
                        _ if harmonic => engine.harmonic(note).or_else(|| engine.note_on(note)),
                        Some(seconds) => engine.note_on_gliding(note, seconds),
                        None => engine.note_on(note),
                    };
                    self.took(note, landed);
                }
            }
            Source::Rubbed(_) => {
                if !self.held[key] {
                    self.held[key] = true;
                    self.rubbed.note_on();
                }
            }
        }
        if let Some(string) = self.notes[key].string.filter(|_| self.held[key]) {
            self.share_the_bow(note, string);
        }
        self.express(note);
        self.refresh_others();
    }

    /// The strings took `note` on `string` (nothing if `None`: the note is ignored): its
    /// key is held and remembers the string.
    pub(super) fn took(&mut self, note: u8, string: Option<usize>) {
        if let Some(string) = string {
            let key = note as usize & 127;
            self.held[key] = true;
            self.last_note = Some(note);
            self.notes[key].string = Some(string as u8);
        }
    }

    /// One bow touches at most two adjacent strings: a note landing on `string` lifts the
    /// bow from every other string more than one away (its note rings on, its key still
    /// down), as a chord played with one bow is rolled and its first notes left ringing.
    /// A double stop on neighbouring strings keeps both bowed.
    pub(super) fn share_the_bow(&mut self, note: u8, string: u8) {
        for other in 0..128u8 {
            let slot = &mut self.notes[other as usize];
            let far = slot.string.is_some_and(|s| s.abs_diff(string) > 1);
            if other == note || !self.held[other as usize] || !far {
                continue;
            }
            slot.string = None;
            match self.source {
                Source::Strings => self.instrument.note_off(other),
                Source::Thermal(k) => {
                    if let Some(engine) = self.thermal.get_mut(k) {
                        engine.note_off(other);
                    }
                }
                Source::Rubbed(_) => {}
            }
        }
    }

    /// Gives `note`'s string the note's expression: its MPE channel's, with its own note
    /// expressions over it. Nothing for a note not held or on no string.
    pub(super) fn express(&mut self, note: u8) {
        let key = note as usize & 127;
        let slot = self.notes[key];
        let (true, Some(string)) = (self.held[key], slot.string) else {
            return;
        };
        let expression = slot.state.over(self.mpe.expression(slot.channel));
        match self.source {
            Source::Strings => self
                .instrument
                .set_note_expression(string as usize, expression),
            Source::Thermal(k) => {
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.set_note_expression(string as usize, expression);
                }
            }
            Source::Rubbed(_) => {}
        }
    }

    /// Re-applies the expression of every held note on `channel` (`None`: every held
    /// note).
    pub(super) fn express_channel(&mut self, channel: Option<u8>) {
        for note in 0..128u8 {
            let slot = &self.notes[note as usize];
            if self.held[note as usize] && channel.is_none_or(|c| c == slot.channel) {
                self.express(note);
            }
        }
    }

    /// A CLAP note expression: `note`'s tuning, semitones (its finger).
    pub fn set_note_tuning(&mut self, note: u8, semitones: f32) {
        if semitones.is_finite() {
            self.notes[note as usize & 127].state.tuning_semitones = semitones as f64;
            self.express(note);
        }
    }

    /// A CLAP note expression (or polyphonic aftertouch): `note`'s pressure, 0..=1 (its
    /// string's bow force, [`mpe::pressure_to_force_scale`]).
    pub fn set_note_pressure(&mut self, note: u8, pressure: f32) {
        if pressure.is_finite() {
            self.notes[note as usize & 127].state.pressure = Some(pressure as f64);
            self.express(note);
        }
    }

    /// A CLAP note expression: `note`'s brightness, 0..=1 (its string's bow position,
    /// [`mpe::timbre_to_position_scale`]).
    pub fn set_note_brightness(&mut self, note: u8, brightness: f32) {
        if brightness.is_finite() {
            self.notes[note as usize & 127].state.brightness = Some(brightness as f64);
            self.express(note);
        }
    }

    pub fn note_off(&mut self, note: u8) {
        let was_held = std::mem::replace(&mut self.held[note as usize & 127], false);
        if !self.held.iter().any(|&h| h) {
            self.stroke.set_tremolo(None);
        }
        match self.source {
            Source::Strings => self.instrument.note_off(note),
            Source::Thermal(k) => {
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.note_off(note);
                }
                // A note struck with the stick plays the waveguide strings
                // ([`articulation`]).
                self.instrument.note_off(note);
            }
            Source::Rubbed(_) if was_held => self.rubbed.note_off(),
            Source::Rubbed(_) => {}
        }
    }

    pub fn all_notes_off(&mut self) {
        self.held = [false; 128];
        for engine in self.engines() {
            engine.all_notes_off();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::performer::testing::*;

    #[test]
    fn one_bow_plays_two_adjacent_strings_and_leaves_the_others_ringing() {
        let bow = BowControl::default();
        let settle = |p: &mut Performer| {
            for _ in 0..(0.1 * FS) as usize {
                p.tick(bow);
            }
        };
        let bowed = |p: &Performer| -> Vec<usize> {
            (0..4).filter(|&i| p.strings().bow_gain(i) > 0.0).collect()
        };
        // A double stop on the D and A strings (2, 3): both bowed.
        let mut p = cello();
        p.note_on(50, 0.8);
        p.note_on(57, 0.8);
        settle(&mut p);
        assert_eq!(bowed(&p), [2, 3]);
        // C and A strings (0, 3) cannot share a bow: the later one takes it, and the C
        // string, bowed for 0.1 s first, rings on.
        let mut p = cello();
        p.note_on(36, 0.8);
        settle(&mut p);
        p.note_on(57, 0.8);
        settle(&mut p);
        assert_eq!(bowed(&p), [3]);
        assert!(
            p.strings().string(0).energy_j() > 0.0,
            "the C string rings on"
        );
        // A four-note chord, low to high: the bow ends on the top two strings.
        let mut p = cello();
        for note in [36, 43, 50, 57] {
            p.note_on(note, 0.8);
        }
        settle(&mut p);
        assert_eq!(bowed(&p), [2, 3]);
    }

    #[test]
    fn alternate_bow_strokes_reverse_the_stick_velocity() {
        let mut p = cello();
        let mut sticks = Vec::new();
        for note in [50, 52, 53, 55] {
            p.note_on(note, 0.8);
            // 0.3 s into each 0.5 s note: past the attack.
            sticks.push(stick_velocity(
                &mut p,
                (0.3 * FS) as usize,
                (0.5 * FS) as usize,
            ));
            p.note_off(note);
        }
        println!("stick velocities {sticks:?}");
        // The string sticks to the bow, which moves at 0.1 m/s down, up, down, up (10 %:
        // the probe's velocity while sticking includes small ripples).
        for (k, v) in sticks.iter().enumerate() {
            let want = if k % 2 == 0 { 0.1 } else { -0.1 };
            assert!((v - want).abs() < 0.01, "note {k}: {v}");
        }
    }

    #[test]
    fn a_legato_note_on_one_string_keeps_the_stroke_and_the_bow_on() {
        let mut p = cello();
        let bow = BowControl::default();
        p.note_on(50, 0.8);
        // Past the attack and its accent.
        for _ in 0..(0.4 * FS) as usize {
            p.tick(bow);
        }
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // E3 lands before D3 lifts: the same string, so the finger moves and the bow goes
        // on: no new attack (the played bow stays the parameters'), no force dip.
        p.note_on(52, 0.8);
        p.note_off(50);
        assert_eq!(InstrumentKind::Cello.string_for_note(52), Some(string));
        for _ in 0..(0.3 * FS) as usize {
            p.tick(bow);
            assert_eq!(p.bow(), bow);
            assert_eq!(p.strings().bow_gain(string), 1.0);
        }
        // A separate note after both lift starts an up-bow from rest.
        p.note_off(52);
        p.note_on(53, 0.8);
        p.tick(bow);
        // One sample into the stroke's ramp from rest (about 17 ms long,
        // docs/playing-space.md): about 1e-4 m/s.
        assert!(p.bow().velocity_m_per_s.abs() < 0.01);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        assert_eq!(p.bow().velocity_m_per_s, -bow.velocity_m_per_s);
    }

    #[test]
    fn a_soft_legato_note_glides_the_finger_and_a_firm_one_jumps() {
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // D3 bowed, then F3 legato on the same string at `velocity`; the string's pitch
        // (cents above D3) every 64 samples for 0.3 s.
        let slide = |velocity: f32| {
            let mut p = cello();
            let bow = BowControl::default();
            p.note_on(50, 0.8);
            for _ in 0..(0.3 * FS) as usize {
                p.tick(bow);
            }
            let d3 = p.strings().string(string).fundamental_hz();
            p.note_on(53, velocity);
            p.note_off(50);
            assert_eq!(InstrumentKind::Cello.string_for_note(53), Some(string));
            let mut cents = Vec::new();
            for i in 0..(0.3 * FS) as usize {
                p.tick(bow);
                if i % 64 == 0 {
                    cents.push(1200.0 * (p.strings().string(string).fundamental_hz() / d3).log2());
                }
            }
            cents
        };
        let firm = slide(0.8);
        // The intonation table moves each place on the string by a few cents.
        assert!(
            (firm[0] - 300.0).abs() < 10.0,
            "a firm legato jumps: {}",
            firm[0]
        );
        let soft = slide(0.3);
        // Rises monotonically from D3 to F3 over the glide time (0.12 s), then stays.
        // 1e-9 cents: rounding.
        assert!(soft.windows(2).all(|w| w[1] >= w[0] - 1e-9));
        let at = |t: f64| soft[(t * FS / 64.0) as usize];
        // The first 1.3 ms step of the 0.12 s glide moves about 3 cents, the table a few
        // more.
        assert!(at(0.0) < 20.0, "{}", at(0.0));
        let half = at(0.5 * GLIDE_S_DEFAULT);
        // Halfway in time, halfway in semitones (within 20 cents: the intonation table
        // moves each place on the string by a few cents, and steps are 1.3 ms).
        assert!((half - 150.0).abs() < 20.0, "{half}");
        // The glide is over (0.12 s): both sit on F3's stopped pitch, to rounding.
        assert!((at(0.25) - firm[firm.len() - 1]).abs() < 0.01);
    }

    #[test]
    fn a_soft_legato_note_glides_the_thermal_finger_too() {
        // Paper B's thermal cello: D3 bowed, then F3 legato and soft on the same string;
        // the string's tuning (cents above D3) every 64 samples.
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        let setup = Setup {
            point_law: None,
            ..Setup::default()
        };
        let mut p = cello_with(&setup);
        let bow = BowControl::default();
        let tuned = |p: &Performer| {
            p.thermal(InstrumentKind::Cello)
                .unwrap()
                .string(string)
                .fundamental_hz()
        };
        p.note_on(50, 0.8);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        let d3 = tuned(&p);
        p.note_on(53, 0.3);
        p.note_off(50);
        let (mut cents, mut audio) = (Vec::new(), Vec::new());
        for i in 0..(0.25 * FS) as usize {
            audio.push(p.tick(bow).audio);
            if i % 64 == 0 {
                cents.push(1200.0 * (tuned(&p) / d3).log2());
            }
        }
        // The bow stays on through the glide: every 10 ms of it sounds.
        // -60 dBFS: a bowed note is far louder.
        assert!(audio.chunks(480).all(|c| crate::analysis::rms(c) > 1e-3));
        let at = |t: f64| cents[(t * FS / 64.0) as usize];
        // Rises monotonically from D3 to F3 over the glide time, then stays.
        // 1e-9 cents: rounding.
        assert!(cents.windows(2).all(|w| w[1] >= w[0] - 1e-9));
        // The first 1.3 ms step of the glide moves about 3 cents, the table a few more.
        assert!(at(0.0) < 20.0, "{}", at(0.0));
        // Halfway in time, halfway in semitones (within 20 cents: the intonation table
        // moves each place on the string by a few cents, and steps are 1.3 ms).
        let half = at(0.5 * GLIDE_S_DEFAULT);
        assert!((half - 150.0).abs() < 20.0, "{half}");
        let end = cents[cents.len() - 1];
        // The thermal intonation table moves each place on the string by a few cents.
        assert!((end - 300.0).abs() < 15.0, "{end}");
        // The glide is over by 0.2 s (it takes 0.12 s): the tuning stands still.
        assert!((at(0.2) - end).abs() < 0.01);
    }
}
