//! `colophony render --midi` against the plugin: the same MIDI events through the CLAP
//! build in the headless host (`../tests/host`, shared with the plugin's tests) and through
//! the renderer's performer give the same bits.

#[allow(dead_code)]
#[path = "../../tests/host/mod.rs"]
mod host;

use colophony::analysis::rms;
use host::{channel_f64, Event, HostedPlugin, Score};

const FS: f64 = 48_000.0;
const BLOCK: usize = 512;

fn active_plugin(sample_rate: f64, max_block: usize) -> HostedPlugin {
    HostedPlugin::active_test_build(sample_rate, max_block)
}

#[test]
fn a_midi_file_rendered_offline_gives_the_plugins_bits() {
    use colophony_lab::midi_file::{perform, MidiEvent, Performance, Timed};
    // The same notes, bends and controllers, at the same samples and block size, through
    // the CLAP build in the host and through `colophony render --midi`'s performer.
    let bend = |amount: f64| (8192.0 + amount * 8192.0).round().clamp(0.0, 16383.0) as u16;
    let at = |sample: u64, event: MidiEvent| Timed {
        sample,
        channel: 0,
        event,
    };
    let events = [
        at(0, MidiEvent::NoteOn(50, 100)),
        at(24_000, MidiEvent::PitchBend(bend(0.5))),
        at(36_001, MidiEvent::PitchBend(bend(-1.0))),
        at(48_000, MidiEvent::NoteOff(50)),
        at(48_000, MidiEvent::NoteOn(57, 127)),
        // Dynamics down and back up (CC11), and the mod wheel's vibrato (CC1).
        at(50_000, MidiEvent::Controller(11, 40)),
        at(55_000, MidiEvent::Controller(1, 100)),
        at(60_123, MidiEvent::PitchBend(bend(0.0))),
        at(66_000, MidiEvent::Controller(11, 127)),
        at(72_000, MidiEvent::NoteOff(57)),
    ];
    let params = colophony::params::ColophonyParams::default();
    let how = Performance {
        setup: params.setup(),
        bow: params.bow(),
        gain: nice_plug::util::db_to_gain(params.gain.value()) as f64,
        sample_rate_hz: FS,
        block: BLOCK,
        bridge: None,
    };
    let offline = perform(&events, &how, |_, _| {}).unwrap();
    let mut score = Score::new();
    for e in &events {
        let event = match e.event {
            MidiEvent::NoteOn(key, v) => Event::NoteOn {
                key,
                velocity: v as f64 / 127.0,
            },
            MidiEvent::NoteOff(n) => Event::note_off(n),
            MidiEvent::PitchBend(raw) => Event::pitch_bend((raw as f64 - 8192.0) / 8192.0),
            MidiEvent::Controller(cc, value) => host::Event::Controller { cc, value },
            MidiEvent::Pressure(_) | MidiEvent::Tempo(_) => unreachable!("not in this score"),
        };
        score.push(e.sample, event);
    }
    let frames = 96_000;
    assert!(
        offline.len() >= frames,
        "offline render of {} frames",
        offline.len()
    );
    let mut plugin = active_plugin(FS, BLOCK);
    let hosted = plugin.render(frames, BLOCK, &score);
    let differing = (0..frames)
        .filter(|&i| hosted[0][i].to_bits() != offline[i].to_bits())
        .count();
    // -60 dBFS: a bowed note is far louder.
    assert!(
        rms(&channel_f64(&hosted, 0)) > 1e-3,
        "the hosted plugin was silent"
    );
    let first = (0..frames).find(|&i| hosted[0][i].to_bits() != offline[i].to_bits());
    assert_eq!(
        differing, 0,
        "{differing} of {frames} samples differ, the first at {first:?}"
    );
}
