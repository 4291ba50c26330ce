//! MPE (MIDI Polyphonic Expression, MMA/AMEI RP-053) and per-note expression.
//!
//! An MPE controller plays each note on a channel of its own (a *member* channel) and
//! bends, presses and shapes it with that channel's pitch bend, channel pressure and CC74
//! (timbre); the zone's *master* channel carries what applies to every note. The
//! controller (or the DAW) announces a zone with the MPE Configuration Message: RPN 6
//! (CC101 0, CC100 6) with CC6 = the number of member channels, on channel 1 for the lower
//! zone (members 2, 3, ...) or on channel 16 for the upper zone (members 15, 14, ...); 0
//! members ends the zone. Until a zone is announced every channel plays as one (the usual
//! MIDI), so a keyboard on any channel works as before.
//!
//! What a member channel's messages do to its note (on the string the note plays):
//!
//! | message | the note's | mapping |
//! |---|---|---|
//! | pitch bend | finger (pitch) | +-48 semitones by default; RPN 0 on a member channel sets the zone's range |
//! | channel pressure | bow force on its string | `2^(2p - 1)`: 0.5x (no pressure) .. 2x, 1x at half pressure |
//! | CC74 (timbre) | bow position on its string | `beta 2^(1 - 2x)`: 2 beta (sul tasto) .. beta / 2 (toward the bridge, brighter), beta at 64 |
//!
//! The bow velocity stays shared (one bow). CLAP note expressions reach the same three
//! controls per note: tuning (semitones) the finger, pressure the force, brightness the
//! position, with the same mappings ([`NoteState`]); they add to (bend) or multiply
//! (scales) a member channel's.

use crate::dsp::vocabulary::NoteExpression;

/// MPE's default pitch-bend range of member channels, semitones.
pub const MEMBER_BEND_RANGE_SEMITONES: f64 = 48.0;
/// The registered parameter that configures a zone.
const RPN_MPE_CONFIGURATION: (u8, u8) = (0, 6);
/// The registered parameter of the pitch-bend range.
const RPN_BEND_RANGE: (u8, u8) = (0, 0);
/// "No registered parameter selected" (RPN null, 127 127).
const RPN_NONE: (u8, u8) = (127, 127);

/// Pressure `0..=1` to a force scale: `2^(2p - 1)`.
pub fn pressure_to_force_scale(pressure: f64) -> f64 {
    (2.0 * pressure.clamp(0.0, 1.0) - 1.0).exp2()
}

/// Timbre or brightness `0..=1` to a bow-position scale: `2^(1 - 2x)`.
pub fn timbre_to_position_scale(timbre: f64) -> f64 {
    (1.0 - 2.0 * timbre.clamp(0.0, 1.0)).exp2()
}

/// One channel's expression state.
#[derive(Debug, Clone, Copy)]
struct Channel {
    /// Pitch-bend wheel, -1..=1.
    wheel_position: f64,
    /// Channel pressure 0..=1, `None` until one arrives (neutral force).
    pressure: Option<f64>,
    /// CC74 0..=1, `None` until one arrives (neutral position).
    timbre: Option<f64>,
    /// The registered parameter selected (CC101, CC100).
    rpn: (u8, u8),
}

impl Default for Channel {
    fn default() -> Self {
        Self {
            wheel_position: 0.0,
            pressure: None,
            timbre: None,
            rpn: RPN_NONE,
        }
    }
}

/// What [`Mpe::controller`] did with a controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Handled {
    /// Not MPE's: the performer applies it to every note.
    Shared,
    /// MPE's: a zone was configured or a range set (nothing else to do).
    Configured,
    /// The channel's note expression changed: re-apply it to the channel's notes.
    Expression,
}

/// The MPE zones and every channel's expression.
#[derive(Debug, Clone)]
pub struct Mpe {
    /// Member channels of the lower zone (master channel 0, members 1..=lower).
    lower: u8,
    /// Member channels of the upper zone (master channel 15, members 15-upper..=14).
    upper: u8,
    /// Member-channel bend range of each zone (lower, upper), semitones.
    member_range: [f64; 2],
    channels: [Channel; 16],
}

impl Default for Mpe {
    fn default() -> Self {
        Self {
            lower: 0,
            upper: 0,
            member_range: [MEMBER_BEND_RANGE_SEMITONES; 2],
            channels: [Channel::default(); 16],
        }
    }
}

impl Mpe {
    /// Whether a zone is configured.
    pub fn is_active(&self) -> bool {
        self.lower > 0 || self.upper > 0
    }

    /// The zone (0 lower, 1 upper) whose member `channel` (0..=15) is, if any.
    fn zone_of_member(&self, channel: u8) -> Option<usize> {
        if (1..=self.lower).contains(&channel) {
            Some(0)
        } else if self.upper > 0 && (15 - self.upper..=14).contains(&channel) {
            Some(1)
        } else {
            None
        }
    }

    /// Whether `channel` is a member channel (its messages are its note's own).
    pub fn is_member(&self, channel: u8) -> bool {
        self.zone_of_member(channel).is_some()
    }

    /// A controller on `channel` (0..=15) at `value` (0..=1). Tracks the registered
    /// parameter each channel selects, configures a zone on the MPE Configuration
    /// Message, sets a zone's member bend range on RPN 0 sent to a member channel, and
    /// takes CC74 on a member channel as its note's timbre.
    pub fn controller(&mut self, channel: u8, cc: u8, value: f64) -> Handled {
        if channel > 15 {
            return Handled::Shared;
        }
        let member = self.is_member(channel);
        let state = &mut self.channels[channel as usize];
        let byte = (value.clamp(0.0, 1.0) * 127.0).round() as u8;
        match cc {
            101 => state.rpn.0 = byte,
            100 => state.rpn.1 = byte,
            6 if state.rpn == RPN_MPE_CONFIGURATION && (channel == 0 || channel == 15) => {
                self.configure(channel == 15, byte.min(15));
                return Handled::Configured;
            }
            6 | 38 if state.rpn == RPN_BEND_RANGE => {
                if let Some(zone) = self.zone_of_member(channel) {
                    let range = self.member_range[zone];
                    self.member_range[zone] = if cc == 6 {
                        byte as f64 + (range.fract() * 100.0).round() / 100.0
                    } else {
                        range.trunc() + byte.min(99) as f64 / 100.0
                    };
                    return Handled::Expression;
                }
            }
            74 if member => {
                state.timbre = Some(value.clamp(0.0, 1.0));
                return Handled::Expression;
            }
            _ => {}
        }
        if member && matches!(cc, 6 | 38 | 100 | 101) {
            // A member channel's own registered-parameter traffic.
            return Handled::Configured;
        }
        Handled::Shared
    }

    /// The MPE Configuration Message: `members` channels for the lower zone (channels
    /// 1.. from the bottom) or the upper one (from 14 down). A zone that would overlap the
    /// other shrinks the other (the specification's rule); 0 ends the zone. Every
    /// channel's expression and the member ranges restart.
    fn configure(&mut self, upper: bool, members: u8) {
        if upper {
            self.upper = members;
            self.lower = self.lower.min(14 - members.min(14));
        } else {
            self.lower = members;
            self.upper = self.upper.min(14 - members.min(14));
        }
        self.member_range = [MEMBER_BEND_RANGE_SEMITONES; 2];
        for c in &mut self.channels {
            *c = Channel {
                rpn: c.rpn,
                ..Channel::default()
            };
        }
    }

    /// A pitch-bend wheel on `channel` (-1..=1): `true` if it is a member channel's (its
    /// note's own), `false` if it bends every note.
    pub fn pitch_bend(&mut self, channel: u8, wheel_position: f64) -> bool {
        if !self.is_member(channel) {
            return false;
        }
        self.channels[channel as usize].wheel_position = wheel_position.clamp(-1.0, 1.0);
        true
    }

    /// Channel pressure on `channel` (0..=1): `true` if it is a member channel's.
    pub fn pressure(&mut self, channel: u8, pressure: f64) -> bool {
        if !self.is_member(channel) {
            return false;
        }
        self.channels[channel as usize].pressure = Some(pressure.clamp(0.0, 1.0));
        true
    }

    /// The expression a note on `channel` takes from its channel (neutral off a member
    /// channel).
    pub fn expression(&self, channel: u8) -> NoteExpression {
        let Some(zone) = self.zone_of_member(channel) else {
            return NoteExpression::NEUTRAL;
        };
        let c = &self.channels[channel as usize];
        NoteExpression {
            bend_semitones: c.wheel_position * self.member_range[zone],
            force_scale: c.pressure.map_or(1.0, pressure_to_force_scale),
            position_scale: c.timbre.map_or(1.0, timbre_to_position_scale),
        }
    }
}

/// One held note's CLAP note expressions (tuning, pressure, brightness), neutral until one
/// arrives; a new note on the key starts neutral.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoteState {
    pub tuning_semitones: f64,
    pub pressure: Option<f64>,
    pub brightness: Option<f64>,
}

impl NoteState {
    /// This note's expression on top of its channel's (`base`): bends add, scales
    /// multiply.
    pub fn over(&self, base: NoteExpression) -> NoteExpression {
        NoteExpression {
            bend_semitones: base.bend_semitones + self.tuning_semitones,
            force_scale: base.force_scale * self.pressure.map_or(1.0, pressure_to_force_scale),
            position_scale: base.position_scale
                * self.brightness.map_or(1.0, timbre_to_position_scale),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CC101 0, CC100 msb-lsb `param`, CC6 `value` on `channel`.
    fn rpn(mpe: &mut Mpe, channel: u8, param: (u8, u8), value: u8) -> Handled {
        mpe.controller(channel, 101, param.0 as f64 / 127.0);
        mpe.controller(channel, 100, param.1 as f64 / 127.0);
        mpe.controller(channel, 6, value as f64 / 127.0)
    }

    #[test]
    fn the_configuration_message_makes_member_channels_and_ends_them() {
        let mut mpe = Mpe::default();
        assert!(!mpe.is_active() && !mpe.is_member(1));
        assert_eq!(rpn(&mut mpe, 0, (0, 6), 7), Handled::Configured);
        assert!((1..=7).all(|c| mpe.is_member(c)));
        assert!(!mpe.is_member(0) && !mpe.is_member(8));
        // An upper zone of 9 shrinks the lower one to 5 (channels 2-6 of 16, 0-based 1-5).
        rpn(&mut mpe, 15, (0, 6), 9);
        assert!((6..=14).all(|c| mpe.is_member(c)), "upper members 6..=14");
        assert!((1..=5).all(|c| mpe.is_member(c)) && !mpe.is_member(15));
        rpn(&mut mpe, 0, (0, 6), 0);
        rpn(&mut mpe, 15, (0, 6), 0);
        assert!(!mpe.is_active());
    }

    #[test]
    fn member_messages_shape_their_own_note_only() {
        let mut mpe = Mpe::default();
        rpn(&mut mpe, 0, (0, 6), 15);
        assert!(mpe.pitch_bend(3, 0.25));
        assert!(mpe.pressure(3, 1.0));
        assert_eq!(mpe.controller(3, 74, 1.0), Handled::Expression);
        let e = mpe.expression(3);
        assert_eq!(e.bend_semitones, 12.0, "a quarter of +-48");
        assert_eq!(e.force_scale, 2.0);
        assert_eq!(e.position_scale, 0.5);
        assert_eq!(mpe.expression(4), NoteExpression::NEUTRAL);
        // The master channel's are shared.
        assert!(!mpe.pitch_bend(0, 1.0));
        assert_eq!(mpe.controller(0, 74, 1.0), Handled::Shared);
        // RPN 0 on a member channel sets the zone's member range.
        assert_eq!(rpn(&mut mpe, 5, (0, 0), 24), Handled::Expression);
        assert_eq!(mpe.expression(3).bend_semitones, 6.0);
    }

    #[test]
    fn without_a_zone_every_channel_is_shared() {
        let mut mpe = Mpe::default();
        for channel in 0..16 {
            assert!(!mpe.pitch_bend(channel, 1.0));
            assert!(!mpe.pressure(channel, 1.0));
            assert_eq!(mpe.controller(channel, 74, 1.0), Handled::Shared);
            assert_eq!(mpe.expression(channel), NoteExpression::NEUTRAL);
        }
    }

    #[test]
    fn note_expressions_add_to_the_channels() {
        let base = NoteExpression {
            bend_semitones: 1.0,
            force_scale: 2.0,
            position_scale: 1.0,
        };
        let note = NoteState {
            tuning_semitones: -0.5,
            pressure: Some(0.0),
            brightness: Some(0.0),
        };
        let e = note.over(base);
        assert_eq!(e.bend_semitones, 0.5);
        assert_eq!(e.force_scale, 1.0);
        assert_eq!(e.position_scale, 2.0);
        assert_eq!(
            NoteState::default().over(NoteExpression::NEUTRAL),
            NoteExpression::NEUTRAL
        );
    }

    mod through_the_performer {
        use crate::dsp::vocabulary::{BowControl, InstrumentKind};
        use crate::performer::{Performer, Setup};

        fn cello() -> Performer {
            let setup = Setup::default();
            let mut p = Performer::new(InstrumentKind::Cello);
            p.activate(&setup, 48_000.0).unwrap();
            p.configure(&setup);
            p
        }

        /// The MPE Configuration Message for a lower zone of `members` channels.
        fn lower_zone(p: &mut Performer, members: u8) {
            p.set_controller_channel(0, 101, 0.0);
            p.set_controller_channel(0, 100, 6.0 / 127.0);
            p.set_controller_channel(0, 6, members as f32 / 127.0);
        }

        fn hz(p: &Performer, string: usize) -> f64 {
            p.strings().string(string).fundamental_hz()
        }

        #[test]
        fn two_mpe_notes_on_two_strings_each_take_their_channels_bend() {
            // D3 on the D string (2), A3 on the A string (3), each on its own channel.
            let mut mpe = cello();
            lower_zone(&mut mpe, 15);
            // The zone's member bend range to +-2 semitones (RPN 0 on a member channel),
            // so the wheel values below are exact in f32 as the shared wheel's are.
            mpe.set_controller_channel(3, 101, 0.0);
            mpe.set_controller_channel(3, 100, 0.0);
            mpe.set_controller_channel(3, 6, 2.0 / 127.0);
            mpe.set_pitch_wheel_channel(1, 0.75); // +1 semitone
            mpe.set_pitch_wheel_channel(2, 0.375); // -0.5 semitone
            mpe.note_on_channel(1, 50, 0.8);
            mpe.note_on_channel(2, 57, 0.8);
            // The same bends through the shared wheel (+-2 semitones), one note at a time.
            let shared = |note: u8, value: f32, string: usize| {
                let mut p = cello();
                p.set_pitch_wheel(value);
                p.note_on(note, 0.8);
                hz(&p, string)
            };
            let up = shared(50, 0.75, 2);
            let down = shared(57, 0.375, 3);
            // The same inputs to the same tuning: equal to rounding.
            assert!(
                (hz(&mpe, 2) / up - 1.0).abs() < 1e-12,
                "{} vs {up}",
                hz(&mpe, 2)
            );
            assert!(
                (hz(&mpe, 3) / down - 1.0).abs() < 1e-12,
                "{} vs {down}",
                hz(&mpe, 3)
            );
            // A later bend on channel 2 moves only its note.
            let before = hz(&mpe, 2);
            mpe.set_pitch_wheel_channel(2, 0.5);
            assert_eq!(hz(&mpe, 2), before);
            let unbent = {
                let mut p = cello();
                p.note_on(57, 0.8);
                hz(&p, 3)
            };
            assert!((hz(&mpe, 3) / unbent - 1.0).abs() < 1e-12);
            // Both sound.
            let bow = BowControl::default();
            let out: Vec<f64> = (0..24_000).map(|_| mpe.tick(bow).audio).collect();
            assert!(out.iter().all(|x| x.is_finite()));
            // -60 dBFS: two bowed notes are far louder.
            assert!(crate::analysis::rms(&out[12_000..]) > 1e-3);
        }

        #[test]
        fn member_pressure_and_timbre_press_and_move_the_bow_on_their_string_only() {
            let mut p = cello();
            lower_zone(&mut p, 15);
            p.note_on_channel(1, 50, 0.8);
            p.note_on_channel(2, 57, 0.8);
            p.set_pressure_channel(1, 1.0);
            p.set_controller_channel(2, 74, 1.0);
            let d = p.strings().note_expression(2);
            let a = p.strings().note_expression(3);
            assert_eq!((d.force_scale, d.position_scale), (2.0, 1.0));
            assert_eq!((a.force_scale, a.position_scale), (1.0, 0.5));
            // The master channel's pressure is the shared dynamics, not a note's.
            p.set_pressure_channel(0, 0.0);
            assert_eq!(p.strings().note_expression(3).force_scale, 1.0);
        }

        #[test]
        fn without_a_zone_any_channels_bend_moves_every_note() {
            let mut p = cello();
            p.note_on_channel(1, 50, 0.8);
            p.note_on_channel(2, 57, 0.8);
            let before = [hz(&p, 2), hz(&p, 3)];
            p.set_pitch_wheel_channel(5, 1.0);
            assert!(hz(&p, 2) > before[0] && hz(&p, 3) > before[1]);
            assert_eq!(
                p.strings().note_expression(2),
                super::NoteExpression::NEUTRAL
            );
        }

        #[test]
        fn a_note_tuning_expression_moves_only_its_note() {
            let mut p = cello();
            p.note_on(50, 0.8);
            p.note_on(57, 0.8);
            let a = hz(&p, 3);
            p.set_note_tuning(50, 1.0);
            let mut shared = cello();
            shared.set_pitch_wheel(0.75);
            shared.note_on(50, 0.8);
            assert!((hz(&p, 2) / hz(&shared, 2) - 1.0).abs() < 1e-12);
            assert_eq!(hz(&p, 3), a);
            // A new note on the key starts without it.
            p.note_off(50);
            p.note_on(50, 0.8);
            assert_eq!(
                p.strings().note_expression(2),
                super::NoteExpression::NEUTRAL
            );
        }
    }
}
