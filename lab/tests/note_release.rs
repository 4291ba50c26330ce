//! What a note-off does, through the performer at the plugin's defaults: the bow lifts and
//! so does the finger. A stopped note's leaving finger damps its string (it then rings
//! open, quietly); an open string has no finger and rings on.
//!

use colophony::analysis::{partial_amplitude, rms};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::intonation::TunedModel;
use colophony::dsp::vocabulary::InstrumentKind;
use colophony::performer::stroke::StrokeMode;
use colophony_lab::midi_file::{perform, MidiEvent, Performance, Timed};

const FS: f64 = 48_000.0;

fn at(t: f64) -> u64 {
    (t * FS).round() as u64
}

fn play(
    kind: InstrumentKind,
    law: Option<FrictionModel>,
    notes: &[(u8, f64, f64)],
    seconds: f64,
) -> Vec<f64> {
    let mut events = Vec::new();
    for &(note, on, off) in notes {
        events.push(Timed {
            sample: at(on),
            channel: 0,
            event: MidiEvent::NoteOn(note, 90),
        });
        events.push(Timed {
            sample: at(off),
            channel: 0,
            event: MidiEvent::NoteOff(note),
        });
    }
    events.sort_by_key(|e| (e.sample, matches!(e.event, MidiEvent::NoteOn(..))));
    let mut how = Performance::plugin_defaults(kind, law, FS);
    // Every note a down-bow from rest, so the next note is the same stroke with and
    // without the released one before it.
    how.setup.bow_strokes = StrokeMode::Down;
    let mut audio: Vec<f64> = perform(&events, &how, |_, _| {})
        .expect("the part plays")
        .into_iter()
        .map(f64::from)
        .collect();
    audio.resize(at(seconds) as usize, 0.0);
    audio
}

fn rms_db(x: &[f64]) -> f64 {
    20.0 * rms(x).max(1e-15).log10()
}

/// Every model: the point laws, then paper B's thermal bow (`None`).
const LAWS: [Option<FrictionModel>; TunedModel::COUNT] = {
    let mut laws = [None; TunedModel::COUNT];
    let mut i = 0;
    while i < TunedModel::COUNT {
        laws[i] = TunedModel::ALL[i].point_law();
        i += 1;
    }
    laws
};

/// Cases known to miss the criterion, with the law: the cello's F3 after Bb2 with the
/// point laws. The released Bb2 falls 14-15 dB in its first 50 ms, but the new F3 is still
/// 8-10 dB under its own steady level there (it speaks slowly: docs/testing.md), so the
/// Bb2 is only 5.2-7.0 dB under it. With paper B's thermal bow, whose sound leaves
/// through the same body: the released note rings on in the body's modes (it falls
/// 14-21 dB in 50 ms, as the point laws' do) while the new note is slower to speak (4-10
/// dB under the point laws' there), so the cello's F3 after Bb2 reads +2.2 dB, its B2
/// after E2 -6.8, its B3 after E3 -11.8, and the viola's Bb3 after D#3 -10.6 (measured
/// at 48 kHz). The test fails if one of them comes to pass, so the list is kept true.
const KNOWN_SLOW_NEXT: [(InstrumentKind, u8, &str); 8] = [
    (InstrumentKind::Cello, 46, "hyperbolic"),
    (InstrumentKind::Cello, 46, "static"),
    (InstrumentKind::Cello, 46, "lugre"),
    (InstrumentKind::Cello, 46, "elasto-plastic"),
    (InstrumentKind::Cello, 46, "thermal"),
    (InstrumentKind::Cello, 40, "thermal"),
    (InstrumentKind::Cello, 52, "thermal"),
    (InstrumentKind::Viola, 51, "thermal"),
];

#[test]
fn a_released_stopped_note_falls_12_db_under_the_next_note_on_another_string_within_50_ms() {
    // (instrument, released stopped note, next note on the neighbouring string), the next
    // note landing as the first is released (legato across strings, as in a phrase).
    let cases = [
        (InstrumentKind::Cello, 46, 53),  // Bb2 on G, then F3 on D
        (InstrumentKind::Cello, 40, 47),  // E2 on C, then B2 on G
        (InstrumentKind::Cello, 52, 59),  // E3 on D, then B3 on A
        (InstrumentKind::Viola, 51, 58),  // Eb3 on C, then Bb3 on G
        (InstrumentKind::Violin, 60, 66), // C4 on G, then F#4 on D
        (InstrumentKind::Violin, 71, 78), // B4 on A, then F#5 on E
    ];
    let mut failures = Vec::new();
    for (kind, first, next) in cases {
        for law in LAWS {
            // The released note on its own (with paper B's bridge the strings couple, so
            // the difference of two renders would also hold the new note's own change),
            // and the new note landing as it is released, on its own too.
            let released = play(kind, law, &[(first, 0.0, 1.0)], 1.6);
            let new = play(kind, law, &[(next, 1.0, 1.6)], 1.6);
            // The levels 50 ms after the change (RMS over 40-60 ms, more than a period of
            // the lowest note here), and the released note's level just before it.
            let window = at(1.04) as usize..at(1.06) as usize;
            let before = rms_db(&released[at(0.9) as usize..at(1.0) as usize]);
            let left = rms_db(&released[window.clone()]);
            let new = rms_db(&new[window]);
            let name = law.map_or("thermal", |l| l.name());
            println!(
                "{} {first} -> {next} {name:>14}: released note {before:6.1} -> {left:6.1} dB, the new note {new:6.1} dB: {:+.1} dB",
                kind.name(),
                left - new
            );
            // The criterion: 12 dB under the new note within 50 ms. A released note only
            // 3-6 dB under the next one stays the strongest pitch through it in cello
            // phrases; 12 dB leaves the new note clearly the stronger.
            let missed = left > new - 12.0;
            let known = KNOWN_SLOW_NEXT.contains(&(kind, first, name));
            if missed != known {
                failures.push(format!(
                    "{} {first} -> {next} {name}: {:+.1} dB{}",
                    kind.name(),
                    left - new,
                    if known {
                        " (passes: remove it from KNOWN_SLOW_NEXT)"
                    } else {
                        ""
                    }
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_released_open_string_rings_on_at_its_own_losses() {
    // The cello's open D and the violin's open A, bowed 1 s and released: no finger to
    // lift. The fundamental then decays at the string's own losses and the bridge's (T60
    // of seconds), so from 0.1-0.2 s to 0.3-0.4 s after the release it loses less than
    // 6 dB (a T60 above 2 s); a released stopped note loses 12 dB and more in its first
    // 50 ms (the test above), over 200 dB/s.
    for (kind, note) in [(InstrumentKind::Cello, 50), (InstrumentKind::Violin, 69)] {
        let f1 = 440.0 * 2f64.powf((note as f64 - 69.0) / 12.0);
        for law in LAWS {
            let out = play(kind, law, &[(note, 0.0, 1.0)], 1.5);
            let level = |from: f64, to: f64| {
                let a = partial_amplitude(&out[at(from) as usize..at(to) as usize], FS, f1);
                20.0 * a.max(1e-15).log10()
            };
            let (early, late) = (level(1.1, 1.2), level(1.3, 1.4));
            let name = law.map_or("thermal", |l| l.name());
            assert!(
                late > early - 6.0,
                "{} {note} {name}: fundamental {early:.1} dB, then {late:.1} dB 0.2 s later",
                kind.name()
            );
        }
    }
}
