//! Note velocity shapes the attack, through the performer at the plugin's defaults: a
//! separate note at velocity 120 starts audibly louder than one at velocity 30 (the stroke's
//! onset level: a faster and heavier bow, scaled together so the bow keeps its place in
//! Schelleng's window), and both still speak, at the note's pitch, soon after they land.

use colophony::analysis::{cents, partial_amplitude, peak_frequency_hz, rms};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::intonation::TunedModel;
use colophony::dsp::vocabulary::InstrumentKind;
use colophony_lab::midi_file::one_note_audio;

const FS: f64 = 48_000.0;

/// How long each note is held, s: long enough for [`pitch_window_s`] on the lowest note.
const HELD_S: f64 = 1.4;

/// Where a note's pitch is measured, s after it lands: from 0.6 s or 40 of its periods,
/// whichever is later (the low strings' attacks last more periods: the double bass's E1
/// has 25 periods in 0.6 s), for 0.3 s.
fn pitch_window_s(note: u8) -> (f64, f64) {
    let from = (40.0 / hz(note)).max(0.6);
    (from, from + 0.3)
}

/// One separate note at `velocity` (1..=127), held [`HELD_S`]: the audio.
fn play(kind: InstrumentKind, law: Option<FrictionModel>, note: u8, velocity: u8) -> Vec<f64> {
    one_note_audio(kind, law, note, velocity, HELD_S, FS)
}

/// The peak level, dB: the largest RMS over 10 ms windows (hop 2.5 ms), the level a
/// listener hears, not one sample of a transient's spike.
fn peak_db(x: &[f64]) -> f64 {
    let (w, hop) = ((0.01 * FS) as usize, (0.0025 * FS) as usize);
    let best = (0..x.len().saturating_sub(w) + 1)
        .step_by(hop)
        .map(|i| rms(&x[i..i + w]))
        .fold(0.0f64, f64::max);
    20.0 * best.max(1e-12).log10()
}

/// Spectral centroid, Hz, of `x`: the partial amplitudes (Hann-windowed DTFT) every 10 Hz
/// up to 8 kHz, weighted by frequency (the attack's brightness).
fn centroid_hz(x: &[f64]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for k in 1..800 {
        let f = 10.0 * k as f64;
        let mag = partial_amplitude(x, FS, f);
        num += f * mag;
        den += mag;
    }
    num / den.max(1e-30)
}

fn hz(note: u8) -> f64 {
    440.0 * 2f64.powf((note as f64 - 69.0) / 12.0)
}

/// Notes known to miss their pitch here, with the law: the double bass's open E1 with the
/// hyperbolic and static laws sits 6-18 cents off at 0.97-1.27 s and has not settled by
/// 2 s (the static law +17 cents at 1.7-2.0 s, measured): its attack through
/// the performer ends in another limit cycle than the landing the intonation table was
/// measured with. The test fails if one of them comes back in tune, so the list is kept
/// true.
const KNOWN_OFF_PITCH: [(InstrumentKind, u8, &str); 2] = [
    (InstrumentKind::DoubleBass, 28, "hyperbolic"),
    (InstrumentKind::DoubleBass, 28, "static"),
];

/// Notes whose hard attack is known to differ too little from the soft one, with the law:
/// the cello's A3 (LuGre) peaks 2.75 dB over velocity 30's gentle start in its first
/// 80 ms, its centroid x0.91 (measured at 48 kHz): under the criterion by a quarter of a
/// decibel, its hard attack caught at `0.8 F_max` (`src/performer/catch.rs`) and the
/// gentle start reaching nearly the same level. The test fails if it comes to pass, so the
/// list is kept true.
const KNOWN_SLOW_HARD_ATTACK: [(InstrumentKind, u8, &str); 1] =
    [(InstrumentKind::Cello, 57, "lugre")];

#[test]
fn a_harder_note_velocity_starts_louder_and_both_speak_at_the_notes_pitch() {
    let laws = TunedModel::ALL.map(TunedModel::point_law);
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for kind in InstrumentKind::ALL {
        let (low, high) = kind.note_range();
        // The open strings' span and an octave above: every string, stopped and open.
        for note in (low..=(high - 19).min(low + 31)).step_by(7) {
            for law in laws {
                let soft = play(kind, law, note, 30);
                let hard = play(kind, law, note, 120);
                let first = (0.08 * FS) as usize;
                let louder = peak_db(&hard[..first]) - peak_db(&soft[..first]);
                let brighter = centroid_hz(&hard[..first]) / centroid_hz(&soft[..first]);
                // At the note's pitch once sounding (`pitch_window_s`), within 15 cents
                // (the repertoire criterion for a sustained note).
                let (from, to) = pitch_window_s(note);
                let pitch = |x: &[f64]| {
                    let w = &x[(from * FS) as usize..(to * FS) as usize];
                    cents(peak_frequency_hz(w, FS, hz(note), 80.0), hz(note))
                };
                let (c_soft, c_hard) = (pitch(&soft), pitch(&hard));
                let name = law.map_or("thermal", |l| l.name());
                report.push(format!(
                    "{:>11} {note:>3} {name:>14}: first 80 ms {louder:+5.2} dB, centroid x{brighter:4.2}; pitch at {from:.2}-{to:.2} s {c_soft:+6.1} / {c_hard:+6.1} cents",
                    kind.name()
                ));
                // An audible difference between velocities 30 and 120: 3 dB in the first
                // 80 ms' peak, or 20 % in their spectral centroid (each several times the
                // just-noticeable difference of level, about 1 dB, and of brightness).
                let faint = louder < 3.0 && brighter < 1.2;
                let known_faint = KNOWN_SLOW_HARD_ATTACK.contains(&(kind, note, name));
                if faint != known_faint {
                    failures.push(format!(
                        "{} {note} {name}: {louder:+.2} dB, x{brighter:.2}{}",
                        kind.name(),
                        if known_faint {
                            " (audible: remove it from KNOWN_SLOW_HARD_ATTACK)"
                        } else {
                            ""
                        }
                    ));
                }
                let off = c_soft.abs() > 15.0 || c_hard.abs() > 15.0;
                let known = KNOWN_OFF_PITCH.contains(&(kind, note, name));
                if off != known {
                    failures.push(format!(
                        "{} {note} {name}: {} ({c_soft:+.1} / {c_hard:+.1} cents)",
                        kind.name(),
                        if off {
                            "off its pitch"
                        } else {
                            "in tune: remove it from KNOWN_OFF_PITCH"
                        }
                    ));
                }
            }
        }
    }
    println!("{}", report.join("\n"));
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
