//! What the host's note events (nice-plug's [`NoteEvent`]) mean to the performer: the one
//! place the plugin framework's event type is read.

use crate::performer::Event;
use nice_plug::midi::Key;
use nice_plug::prelude::*;

/// The performer's event for a host's, `None` for what it does not play.
pub fn performer_event(event: NoteEvent<()>) -> Option<Event> {
    Some(match event {
        NoteEvent::NoteOn {
            key: Key::Number(note),
            velocity,
            channel,
            ..
        } => Event::NoteOn {
            channel: channel.number().unwrap_or(0),
            note,
            velocity,
        },
        NoteEvent::NoteOff {
            key: Key::Number(note),
            ..
        } => Event::NoteOff { note },
        NoteEvent::NoteOff {
            key: Key::Wildcard, ..
        }
        | NoteEvent::Choke { .. } => Event::AllNotesOff,
        NoteEvent::MidiPitchBend { channel, value, .. } => Event::PitchWheel { channel, value },
        NoteEvent::MidiCC {
            channel, cc, value, ..
        } => Event::Controller { channel, cc, value },
        NoteEvent::MidiChannelPressure {
            channel, pressure, ..
        } => Event::ChannelPressure { channel, pressure },
        // CLAP note expressions and polyphonic aftertouch, per note.
        NoteEvent::PolyTuning {
            key: Key::Number(note),
            tuning,
            ..
        } => Event::NoteTuning {
            note,
            semitones: tuning,
        },
        NoteEvent::PolyPressure {
            key: Key::Number(note),
            pressure,
            ..
        } => Event::NotePressure { note, pressure },
        NoteEvent::PolyBrightness {
            key: Key::Number(note),
            brightness,
            ..
        } => Event::NoteBrightness { note, brightness },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nice_plug::midi::{Channel, VoiceID};

    #[test]
    fn host_events_become_the_performers_and_unplayed_ones_are_dropped() {
        let on = NoteEvent::NoteOn {
            timing: 5,
            voice_id: VoiceID::Wildcard,
            channel: Channel::Number(3),
            key: Key::Number(60),
            velocity: 0.5,
        };
        assert_eq!(
            performer_event(on),
            Some(Event::NoteOn {
                channel: 3,
                note: 60,
                velocity: 0.5
            })
        );
        let cc = NoteEvent::MidiCC {
            timing: 0,
            channel: 1,
            cc: 11,
            value: 0.25,
        };
        assert_eq!(
            performer_event(cc),
            Some(Event::Controller {
                channel: 1,
                cc: 11,
                value: 0.25
            })
        );
        let tuning = NoteEvent::PolyTuning {
            timing: 0,
            voice_id: VoiceID::Wildcard,
            channel: Channel::Number(0),
            key: Key::Number(62),
            tuning: -0.5,
        };
        assert_eq!(
            performer_event(tuning),
            Some(Event::NoteTuning {
                note: 62,
                semitones: -0.5
            })
        );
        let program: NoteEvent<()> = NoteEvent::MidiProgramChange {
            timing: 0,
            channel: 0,
            program: 4,
        };
        assert_eq!(performer_event(program), None);
    }
}
