//! MIDI decoding: the pitch wheel and its range (RPN 0), channel pressure, and controllers
//! through the MIDI map to their targets.

use super::*;

/// MIDI's null registered parameter number (CC101 and CC100 at 127).
pub(super) const RPN_NULL: u8 = 127;

impl Performer {
    /// The pitch-bend wheel (0..=1) on `channel`: an MPE member channel's bends its own
    /// notes, any other channel's every note ([`Performer::set_pitch_wheel`]).
    pub fn set_pitch_wheel_channel(&mut self, channel: u8, value: f32) {
        if self.mpe.pitch_bend(channel, wheel_position(value)) {
            self.express_channel(Some(channel));
        } else {
            self.set_pitch_wheel(value);
        }
    }

    /// Channel pressure (0..=1) on `channel`: an MPE member channel's presses its own
    /// notes' strings, any other's is the dynamics ([`Performer::set_pressure`]).
    pub fn set_pressure_channel(&mut self, channel: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        if self.mpe.pressure(channel, value as f64) {
            self.express_channel(Some(channel));
        } else {
            self.set_pressure(value);
        }
    }

    /// A controller (0..=1) on `channel`: the MPE Configuration Message, and CC74 or
    /// RPN 0 on a member channel, are MPE's ([`mpe`]); everything else is
    /// [`Performer::set_controller`]'s.
    pub fn set_controller_channel(&mut self, channel: u8, cc: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        match self.mpe.controller(channel, cc, value as f64) {
            Handled::Shared => self.set_controller(cc, value),
            Handled::Configured => self.express_channel(None),
            Handled::Expression => self.express_channel(None),
        }
    }

    /// The pitch-bend wheel at `value` (0..=1, 0.5 = centre, as nice-plug delivers it):
    /// bends by the bend range at its ends.
    pub fn set_pitch_wheel(&mut self, value: f32) {
        self.gesture.wheel_position = wheel_position(value);
        self.set_bend(self.gesture.wheel_position * self.bend_range());
    }

    /// The pitch-bend range, semitones: MIDI RPN 0's if one came, else the setup's
    /// (clamped to 0..=[`MAX_BEND_RANGE_SEMITONES`]).
    pub fn bend_range(&self) -> f64 {
        midi_over_setup(
            self.gesture.rpn_bend_range,
            self.setup.bend_range_semitones,
            PITCH_BEND_SEMITONES,
            0.0..=MAX_BEND_RANGE_SEMITONES,
        )
    }

    /// Pitch bend in semitones, for every engine with pitch (the vibrato adds to it).
    pub(super) fn set_bend(&mut self, semitones: f64) {
        self.gesture.bend_semitones = semitones;
        self.bend_engines(semitones + self.gesture.vibrato_now);
    }

    pub(super) fn bend_engines(&mut self, semitones: f64) {
        for engine in self.engines() {
            engine.set_pitch_bend(semitones);
        }
    }

    /// Controllers move what `map` says from now on ([`midi_map`]). Real-time safe.
    pub fn set_midi_map(&mut self, map: &MidiMap) {
        self.midi_map = *map;
    }

    /// A MIDI controller at `value` (0..=1, as nice-plug delivers it). CC101 and CC100
    /// select a registered parameter and CC6 / CC38 set it (RPN 0: the pitch-bend range,
    /// semitones and cents); every other controller does what the MIDI map says
    /// ([`midi_map`]; by default CC1 the vibrato depth, CC2 and CC11 the dynamics, CC19
    /// the vibrato rate, CC21-23 the bow's speed, force and position ([`direct`]), CC65
    /// portamento), or nothing.
    pub fn set_controller(&mut self, cc: u8, value: f32) {
        if !value.is_finite() {
            return;
        }
        self.steady = None;
        let v = (value as f64).clamp(0.0, 1.0);
        // The 7-bit value of a data byte.
        let byte = (v * 127.0).round() as u8;
        match cc {
            101 => return self.gesture.rpn.0 = byte,
            100 => return self.gesture.rpn.1 = byte,
            6 | 38 if self.gesture.rpn == (0, 0) => {
                let range = self.bend_range();
                let (semitones, cents) = (range.trunc(), (range.fract() * 100.0).round());
                let range = if cc == 6 {
                    byte as f64 + cents / 100.0
                } else {
                    semitones + byte.min(99) as f64 / 100.0
                };
                self.gesture.rpn_bend_range = Some(range.min(MAX_BEND_RANGE_SEMITONES));
                self.set_bend(self.gesture.wheel_position * self.bend_range());
                return;
            }
            _ => {}
        }
        let map = self.midi_map;
        for (target, x) in map.route(cc, v) {
            self.move_target(target, x);
        }
    }

    /// A mapped controller's value `x` (0..=1 of the target's range) lands on `target`.
    pub(super) fn move_target(&mut self, target: Target, x: f64) {
        match target {
            Target::Dynamics => self.gesture.set_expression(x),
            Target::VibratoDepth => self.gesture.vibrato_cents = x * MAX_VIBRATO_CENTS,
            Target::VibratoRate => {
                self.gesture.cc_rate_hz =
                    Some(VIBRATO_RATE_MIN_HZ + x * (VIBRATO_RATE_MAX_HZ - VIBRATO_RATE_MIN_HZ))
            }
            Target::BowVelocity => {
                self.direct.set_controller(direct::CC_BOW_VELOCITY, x);
            }
            Target::BowForce => {
                self.direct.set_controller(direct::CC_BOW_FORCE, x);
            }
            Target::BowPosition => {
                self.direct.set_controller(direct::CC_BOW_POSITION, x);
            }
            Target::Portamento => self.gesture.portamento_pedal = (x * 127.0).round() >= 64.0,
            Target::Pizzicato
            | Target::Tremolo
            | Target::Spiccato
            | Target::ColLegno
            | Target::Sautille
            | Target::Harmonics
            | Target::ColLegnoTratto => {
                let on = match target {
                    Target::Pizzicato => Articulation::Pizzicato,
                    Target::Tremolo => Articulation::Tremolo,
                    Target::Spiccato => Articulation::Spiccato,
                    Target::Sautille => Articulation::Sautille,
                    Target::Harmonics => Articulation::Harmonics,
                    Target::ColLegnoTratto => Articulation::ColLegnoTratto,
                    _ => Articulation::ColLegno,
                };
                let down = (x * 127.0).round() >= 64.0;
                self.set_articulation(if down { on } else { Articulation::Arco })
            }
            Target::ConSordino => self.set_con_sordino((x * 127.0).round() >= 64.0),
            Target::Sustain => {
                let held = (x * 127.0).round() >= 64.0;
                for engine in self.engines() {
                    engine.set_fingers_held(held);
                }
            }
        }
    }

    /// Channel pressure (aftertouch), 0..=1: the dynamics, as CC11.
    pub fn set_pressure(&mut self, value: f32) {
        self.steady = None;
        if value.is_finite() {
            self.gesture.set_expression(value as f64);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::performer::testing::*;

    #[test]
    fn direct_bow_controllers_move_the_played_bow_until_the_parameter_moves() {
        let mut p = cello();
        p.note_on(50, 0.5);
        let bow = BowControl::default();
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        // CC22 at 100: the force knob's curve, 10 (100/127)^4 = 3.8 N.
        p.set_controller(direct::CC_BOW_FORCE, 100.0 / 127.0);
        for _ in 0..(0.2 * FS) as usize {
            p.tick(bow);
        }
        let want = direct::force_at((100.0f32 / 127.0) as f64);
        // Within a millionth the smoothing snaps to its target (about 14 time constants,
        // 0.14 s): after 0.2 s the force is the curve's value to rounding.
        assert!((p.bow().force_n - want).abs() < 1e-9, "{:?}", p.bow());
        // The parameter moves (automation): the force is the parameter's again.
        let automated = BowControl {
            force_n: 2.0,
            ..bow
        };
        p.tick(automated);
        assert_eq!(p.bow().force_n, 2.0);
    }

    #[test]
    fn a_custom_midi_map_routes_a_controller_to_its_targets_and_unmaps_the_rest() {
        // CC74 drives the bow force over the lower half of its controller range and the
        // vibrato depth; CC22 and CC11, unmapped, do nothing.
        let mut map = MidiMap::empty();
        let mut force = midi_map::Mapping::new(74, Target::BowForce);
        force.max = 0.5;
        map.add(force);
        map.add(midi_map::Mapping::new(74, Target::VibratoDepth));
        let mut p = cello();
        p.set_midi_map(&map);
        p.note_on(50, 0.5);
        let bow = BowControl::default();
        let run = |p: &mut Performer| {
            for _ in 0..(0.2 * FS) as usize {
                p.tick(bow);
            }
        };
        run(&mut p);
        let before = p.bow();
        p.set_controller(direct::CC_BOW_FORCE, 1.0);
        p.set_controller(11, 0.2);
        run(&mut p);
        assert_eq!(p.bow(), before, "an unmapped controller moved the bow");
        assert_eq!(p.gesture.vibrato_cents, 0.0);
        p.set_controller(74, 1.0);
        run(&mut p);
        // The force controller's curve at half its travel (the mapping's top).
        // Snapped to the target after 0.2 s, as above: rounding only.
        assert!(
            (p.bow().force_n - direct::force_at(0.5)).abs() < 1e-9,
            "{:?}",
            p.bow()
        );
        assert_eq!(p.gesture.vibrato_cents, MAX_VIBRATO_CENTS);
        // Back to the default map: CC22 is the force again.
        p.set_midi_map(&MidiMap::default());
        p.set_controller(direct::CC_BOW_FORCE, 1.0);
        run(&mut p);
        // Snapped to the target after 0.2 s, as above.
        assert!((p.bow().force_n - direct::force_at(1.0)).abs() < 1e-9);
    }

    #[test]
    fn the_bend_range_follows_the_setup_and_midi_rpn_0() {
        let string = InstrumentKind::Cello.string_for_note(50).unwrap();
        // The pitch `note` sounds at when stopped on D3's string, unbent.
        let stopped_hz = |note: u8| {
            let setup = Setup {
                preferred_string: Some(string),
                ..Setup::default()
            };
            let mut p = cello_with(&setup);
            p.note_on(note, 0.8);
            p.strings().string(string).fundamental_hz()
        };
        let mut p = cello();
        p.note_on(50, 0.8);
        let hz = |p: &Performer| p.strings().string(string).fundamental_hz();
        // The bent string stops where the stopped note does: the same place and table
        // correction, so rounding only.
        let same = |a: f64, b: f64| (1200.0 * (a / b).log2()).abs() < 0.01;
        p.set_pitch_wheel(1.0);
        assert!(same(hz(&p), stopped_hz(52)), "default range: two semitones");
        let setup = Setup {
            bend_range_semitones: 7.0,
            ..Setup::default()
        };
        p.configure(&setup);
        assert!(
            same(hz(&p), stopped_hz(57)),
            "the parameter: seven semitones"
        );
        // RPN 0 (CC101 0, CC100 0, CC6 12, CC38 0): twelve semitones, over the parameter.
        for (cc, v) in [(101, 0), (100, 0), (6, 12), (38, 0)] {
            p.set_controller(cc, v as f32 / 127.0);
        }
        assert!(same(hz(&p), stopped_hz(62)), "RPN 0: twelve semitones");
        // Down: D3 is the open D string, which a bend cannot take further below its open
        // pitch than the tuning margin (within 10 cents: the intonation table moves each
        // place on the string by a few cents).
        p.set_pitch_wheel(0.0);
        let open = midi_to_hz(50.0);
        let cents = 1200.0 * (hz(&p) / open).log2();
        assert!(
            (cents + 100.0 * PITCH_BEND_SEMITONES).abs() < 10.0,
            "{cents}"
        );
        // A data entry for another RPN changes nothing.
        for (cc, v) in [(101, 0), (100, 1), (6, 3)] {
            p.set_controller(cc, v as f32 / 127.0);
        }
        assert_eq!(p.bend_range(), 12.0);
    }
}
