//! Real repertoire through the performer, as a musician plays it from MIDI at the plugin's
//! defaults (note velocity 90, legato): public-domain phrases on each instrument, every
//! friction model, each note's pitch measured where it is sustained (from 40 % of the note,
//! at least 100 ms after it lands, to 20 ms before the next), in cents from equal
//! temperament at A4 = 440 Hz. 15 cents is the criterion for a sustained note of a
//! real part (issue 16: the thermal model played 5 % of a quartet's violin notes within it).

use colophony::analysis::{cents, peak_frequency_hz};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::InstrumentKind;
use colophony_lab::midi_file::{perform, MidiEvent, Performance, Timed};

const FS: f64 = 48_000.0;

/// A phrase: (MIDI note, beats) pairs played legato (each note-off on the next note-on) at
/// `tempo` beats a minute.
struct Phrase {
    name: &'static str,
    /// Slow enough (half a second a note and more) that every note must be in tune.
    cantabile: bool,
    kind: InstrumentKind,
    tempo: f64,
    notes: &'static [(u8, f64)],
}

#[rustfmt::skip]
const PHRASES: [Phrase; 5] = [
    // Bach, cello suite no. 1, BWV 1007, prelude, bars 1-2 (sixteenths).
    Phrase {
        name: "Bach BWV 1007 prelude, bars 1-2",
        cantabile: false,
        kind: InstrumentKind::Cello,
        tempo: 240.0,
        notes: &[
            (43, 1.0), (50, 1.0), (59, 1.0), (57, 1.0), (59, 1.0), (50, 1.0), (59, 1.0), (50, 1.0),
            (43, 1.0), (50, 1.0), (59, 1.0), (57, 1.0), (59, 1.0), (50, 1.0), (59, 1.0), (50, 1.0),
            (43, 1.0), (52, 1.0), (60, 1.0), (59, 1.0), (60, 1.0), (52, 1.0), (60, 1.0), (52, 1.0),
            (43, 1.0), (52, 1.0), (60, 1.0), (59, 1.0), (60, 1.0), (52, 1.0), (60, 1.0), (52, 1.0),
        ],
    },
    // A slow cello line over its range: C major, two beats a note.
    Phrase {
        name: "cello scale C2-C5, slow",
        cantabile: true,
        kind: InstrumentKind::Cello,
        tempo: 120.0,
        notes: &[
            (36, 2.0), (38, 2.0), (40, 2.0), (41, 2.0), (43, 2.0), (45, 2.0), (47, 2.0), (48, 2.0),
            (50, 2.0), (52, 2.0), (53, 2.0), (55, 2.0), (57, 2.0), (59, 2.0), (60, 2.0), (62, 2.0),
            (64, 2.0), (65, 2.0), (67, 2.0), (69, 2.0), (71, 2.0), (72, 2.0),
        ],
    },
    // Beethoven, symphony no. 9, finale, "Ode to Joy" theme, in G for the viola.
    Phrase {
        name: "Beethoven op. 125 theme (viola)",
        cantabile: true,
        kind: InstrumentKind::Viola,
        tempo: 100.0,
        notes: &[
            (59, 1.0), (59, 1.0), (60, 1.0), (62, 1.0), (62, 1.0), (60, 1.0), (59, 1.0), (57, 1.0),
            (55, 1.0), (55, 1.0), (57, 1.0), (59, 1.0), (59, 1.5), (57, 0.5), (57, 2.0),
        ],
    },
    // The same theme in D for the violin, an octave up on the A and E strings.
    Phrase {
        name: "Beethoven op. 125 theme (violin)",
        cantabile: true,
        kind: InstrumentKind::Violin,
        tempo: 100.0,
        notes: &[
            (78, 1.0), (78, 1.0), (79, 1.0), (81, 1.0), (81, 1.0), (79, 1.0), (78, 1.0), (76, 1.0),
            (74, 1.0), (74, 1.0), (76, 1.0), (78, 1.0), (78, 1.5), (76, 0.5), (76, 2.0),
        ],
    },
    // A violin line up the E string: A major from A5 to A6 and down.
    Phrase {
        name: "violin A5-A6 and back",
        cantabile: true,
        kind: InstrumentKind::Violin,
        tempo: 120.0,
        notes: &[
            (81, 1.0), (83, 1.0), (85, 1.0), (86, 1.0), (88, 1.0), (90, 1.0), (92, 1.0), (93, 2.0),
            (92, 1.0), (90, 1.0), (88, 1.0), (86, 1.0), (85, 1.0), (83, 1.0), (81, 2.0),
        ],
    },
];

/// (note, bowed pitch in cents from equal temperament) for each note of `phrase` played with
/// `law` (`None`: paper B's thermal model).
fn play(phrase: &Phrase, law: Option<FrictionModel>) -> Vec<(u8, f64)> {
    let beat = 60.0 / phrase.tempo * FS;
    let mut events = Vec::new();
    let mut spans = Vec::new();
    let mut t = 0.0;
    for &(note, beats) in phrase.notes {
        let start = t as u64;
        t += beats * beat;
        let end = t as u64;
        events.push(Timed {
            sample: start,
            channel: 0,
            event: MidiEvent::NoteOn(note, 90),
        });
        events.push(Timed {
            sample: end,
            channel: 0,
            event: MidiEvent::NoteOff(note),
        });
        spans.push((note, start as usize, end as usize));
    }
    // Offs before ons at the same sample: legato, one bow.
    events.sort_by_key(|e| (e.sample, matches!(e.event, MidiEvent::NoteOn(..))));
    let how = Performance::plugin_defaults(phrase.kind, law, FS);
    let audio: Vec<f64> = perform(&events, &how, |_, _| {})
        .expect("the phrase plays")
        .into_iter()
        .map(f64::from)
        .collect();
    spans
        .iter()
        .map(|&(note, start, end)| {
            // The sustained part: after the attack (40 % of the note, at least 100 ms),
            // to 20 ms before the next note.
            let from = start + ((end - start) as f64 * 0.4).max(0.1 * FS) as usize;
            let to = end.saturating_sub((0.02 * FS) as usize).min(audio.len());
            let f0 = 440.0 * 2f64.powf((note as f64 - 69.0) / 12.0);
            let f = peak_frequency_hz(&audio[from..to], FS, f0, 100.0);
            (note, cents(f, f0))
        })
        .collect()
}

const LAWS: [(&str, Option<FrictionModel>); 5] = [
    ("hyperbolic", Some(FrictionModel::Hyperbolic)),
    ("static", Some(FrictionModel::Stribeck)),
    ("lugre", Some(FrictionModel::LuGre)),
    ("elasto-plastic", Some(FrictionModel::ElastoPlastic)),
    ("thermal", None),
];

/// Plays the phrases with every model; returns one line per phrase and model, and the notes
/// more than 15 cents off.
fn survey(phrases: impl Iterator<Item = &'static Phrase>) -> (Vec<String>, Vec<String>) {
    let mut lines = Vec::new();
    let mut off = Vec::new();
    for phrase in phrases {
        for (name, law) in LAWS {
            let notes = play(phrase, law);
            let within = notes.iter().filter(|(_, c)| c.abs() <= 15.0).count();
            let list: Vec<String> = notes.iter().map(|(n, c)| format!("{n}:{c:+.0}")).collect();
            lines.push(format!(
                "{} / {name}: {within} of {} within 15 cents: {}",
                phrase.name,
                notes.len(),
                list.join(" ")
            ));
            off.extend(
                notes
                    .iter()
                    .filter(|(_, c)| !(c.abs() <= 15.0))
                    .map(|(n, c)| format!("{} / {name}: note {n} at {c:+.1} cents", phrase.name)),
            );
        }
    }
    (lines, off)
}

/// The slow phrases (a cello scale over two and a half octaves, Beethoven's theme on the
/// viola and high on the violin's A and E strings, the violin up its E string from A5 to
/// A6 at two notes a second): every note of every model within 15 cents. Before paper B's
/// strings were weighted, the thermal violin played 8 of the theme's 15 notes within it
/// (1 N is near `F_max` on the A and E strings: -55 to +22 cents); after, all within 2
/// cents. Before the violin's point strings ran at 96 kHz, the point laws played 11-15 of
/// the E-string line's notes within it (+16 to +52 cents on E6-G#6, the sample-grid
/// lock); after, all within 6 cents.
#[test]
fn slow_phrases_play_every_note_in_tune_with_every_model() {
    let (lines, off) = survey(PHRASES.iter().filter(|p| p.cantabile));
    println!("{}", lines.join("\n"));
    assert!(
        off.is_empty(),
        "{} notes off:\n{}",
        off.len(),
        off.join("\n")
    );
}

/// The fast phrase too (Bach's prelude in sixteenths): printed, not asserted. On
/// 2026-11-26 every model played 29-31 of the prelude's 32 notes within 15 cents (the
/// misses: the crossings to the open G, attack transients at 0.25 s a note). `cargo test
/// --release --test repertoire -- --ignored --nocapture`.
#[test]
#[ignore]
fn repertoire_survey() {
    let (lines, off) = survey(PHRASES.iter());
    println!(
        "{}\n{} notes more than 15 cents off",
        lines.join("\n"),
        off.len()
    );
}
