//! The timbre benchmark (`colophony bench timbre`): how close each instrument's played
//! notes come to a real instrument's, band by band.
//!
//! **Method** (docs/timbre.md). Each instrument plays every third semitone from its lowest
//! open string up to the top of its range that the reference also covers, one note at a
//! time through the performer at the plugin's defaults (velocity 100, 2 s). From the
//! steady part of each note (1.0 to 2.0 s) the amplitude of every harmonic up to 10 kHz
//! is read at multiples of the note's measured fundamental. The reference is the same
//! measurement of a real player's notes: SHARC's steady-state harmonic amplitudes of the
//! McGill recordings (`assets/timbre/sharc-arco.csv`), at the same notes. On both sides a
//! note's harmonic powers are normalised to unit total power up to the top of the 5 kHz
//! band and summed into base-10 third-octave bands; the bands are averaged over the notes
//! with equal weight (the long-term spectrum of a chromatic run) and given in dB, each
//! curve less its mean over the bands from the lowest open string's to 5 kHz. The RMS
//! distance is taken over those bands. The harmonic profile compares each note's first 16
//! harmonics in dB re its strongest (floored at -60 dB), averaged over harmonics and notes.

pub mod floor;

use colophony::analysis::{partial_amplitude, peak_frequency_hz};
use colophony::dsp::intonation::TunedModel;
use colophony::dsp::vocabulary::{midi_to_hz, InstrumentKind};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// SHARC's arco notes of the four instruments (see the file's header for the source).
const SHARC: &str = include_str!("../../assets/timbre/sharc-arco.csv");

/// The analysis's top band: its centre, Hz.
pub const TOP_BAND_HZ: f64 = 5000.0;
/// Harmonics read up to this frequency, Hz (SHARC's limit).
pub const MAX_HARMONIC_HZ: f64 = 10_000.0;
/// Harmonics in a note's profile.
pub const PROFILE_HARMONICS: usize = 16;
/// The profile's floor, dB re the strongest harmonic.
pub const PROFILE_FLOOR_DB: f64 = -60.0;
/// Semitones between the notes played.
pub const NOTE_STEP: usize = 3;
/// The note's MIDI velocity.
pub const VELOCITY: u8 = 100;
/// How long each note is held, s, and where its steady part starts.
pub const NOTE_S: f64 = 2.0;
pub const STEADY_FROM_S: f64 = 1.0;

/// One note's harmonic amplitudes (index 0: the fundamental), linear.
#[derive(Debug, Clone)]
pub struct NoteSpectrum {
    pub note: u8,
    pub fundamental_hz: f64,
    pub amplitudes: Vec<f64>,
}

/// The reference's notes of `kind` (SHARC's arco run).
pub fn reference(kind: InstrumentKind) -> Vec<NoteSpectrum> {
    let mut notes: Vec<NoteSpectrum> = Vec::new();
    for line in SHARC.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 6 || f[0] != kind.name() {
            continue;
        }
        let (Ok(note), Ok(f0), Ok(h), Ok(a)) = (
            f[2].parse::<u8>(),
            f[3].parse::<f64>(),
            f[4].parse::<usize>(),
            f[5].parse::<f64>(),
        ) else {
            continue;
        };
        if notes.last().is_none_or(|n| n.note != note) {
            notes.push(NoteSpectrum {
                note,
                fundamental_hz: f0,
                amplitudes: Vec::new(),
            });
        }
        let amplitudes = &mut notes.last_mut().expect("pushed above").amplitudes;
        if amplitudes.len() < h {
            amplitudes.resize(h, 0.0);
        }
        amplitudes[h - 1] = a;
    }
    notes
}

/// The notes played for `kind`: every [`NOTE_STEP`] semitones from its lowest open string
/// to its top, where the reference has the note too.
pub fn notes(kind: InstrumentKind, reference: &[NoteSpectrum]) -> Vec<u8> {
    let (low, high) = kind.note_range();
    (low..=high)
        .step_by(NOTE_STEP)
        .filter(|n| reference.iter().any(|r| r.note == *n))
        .collect()
}

/// `note` played on `kind` with `model` at `rate_hz` through the performer at the plugin's
/// defaults, its steady part's harmonics measured.
pub fn played(kind: InstrumentKind, model: TunedModel, rate_hz: f64, note: u8) -> NoteSpectrum {
    let out =
        crate::midi_file::one_note_audio(kind, model.point_law(), note, VELOCITY, NOTE_S, rate_hz);
    measured(&out, rate_hz, note)
}

/// The harmonics of `note` in `out` (a render of [`NOTE_S`] at `rate_hz`), read from its
/// steady part: the fundamental is the strongest peak within a semitone of the note's.
pub fn measured(out: &[f64], rate_hz: f64, note: u8) -> NoteSpectrum {
    let mut amplitudes = Vec::new();
    let from = ((STEADY_FROM_S * rate_hz) as usize).min(out.len());
    let steady = &out[from..];
    let fundamental_hz = peak_frequency_hz(steady, rate_hz, midi_to_hz(note as f64), 100.0);
    let top = MAX_HARMONIC_HZ.min(0.45 * rate_hz);
    let mut h = 1;
    while h as f64 * fundamental_hz <= top {
        amplitudes.push(partial_amplitude(
            steady,
            rate_hz,
            h as f64 * fundamental_hz,
        ));
        h += 1;
    }
    NoteSpectrum {
        note,
        fundamental_hz,
        amplitudes,
    }
}

/// The lowest frequency STK's `Bowed` is built for in the timbre bench, Hz (its
/// constructor's `lowestFrequency` in `assets/peers/stk_bowed.cpp`): lower notes are left
/// out of its row.
pub const STK_LOWEST_HZ: f64 = 50.0;

/// `note` played by STK's `stk::Bowed` at its own defaults (the driver `stk`, built by
/// [`crate::precision::peers::build_stk`]) for [`NOTE_S`] at `rate_hz`, measured as
/// [`measured`]; `None` if the driver fails.
pub fn played_by_stk(stk: &Path, dir: &Path, rate_hz: f64, note: u8) -> Option<NoteSpectrum> {
    let raw = dir.join(format!("stk-{note}.f32"));
    let status = std::process::Command::new(stk)
        .arg(format!("{NOTE_S}"))
        .arg(format!("{rate_hz}"))
        .arg(format!("{}", midi_to_hz(note as f64)))
        .arg(&raw)
        .arg("1")
        .stdout(std::process::Stdio::null())
        .status()
        .ok()?;
    if !status.success() {
        return None;
    }
    let bytes = std::fs::read(&raw).ok()?;
    let _ = std::fs::remove_file(&raw);
    let out: Vec<f64> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]) as f64)
        .collect();
    Some(measured(&out, rate_hz, note))
}

/// The index of the base-10 third-octave band holding `hz` (centre `10^(k/10)`).
pub fn band(hz: f64) -> i32 {
    (10.0 * hz.log10()).round() as i32
}

/// The analysis bands of `kind`: the lowest open string's band to [`TOP_BAND_HZ`]'s.
pub fn bands(kind: InstrumentKind) -> std::ops::RangeInclusive<i32> {
    band(midi_to_hz(kind.open_notes()[0] as f64))..=band(TOP_BAND_HZ)
}

/// The long-term spectrum of `notes` over `bands`, dB, less its mean: each note's
/// harmonic powers normalised to unit total power within the bands, summed per band,
/// averaged over the notes.
pub fn long_term_spectrum(
    notes: &[&NoteSpectrum],
    bands: &std::ops::RangeInclusive<i32>,
) -> Vec<f64> {
    let count = (bands.end() - bands.start() + 1).max(0) as usize;
    let mut power = vec![0.0; count];
    for n in notes {
        let mut note = vec![0.0; count];
        for (i, a) in n.amplitudes.iter().enumerate() {
            let b = band((i + 1) as f64 * n.fundamental_hz);
            if bands.contains(&b) {
                note[(b - bands.start()) as usize] += a * a;
            }
        }
        let total: f64 = note.iter().sum();
        if total > 0.0 {
            for (p, x) in power.iter_mut().zip(&note) {
                *p += x / total / notes.len() as f64;
            }
        }
    }
    let db: Vec<f64> = power.iter().map(|p| 10.0 * p.max(1e-12).log10()).collect();
    let mean = db.iter().sum::<f64>() / db.len().max(1) as f64;
    db.iter().map(|d| d - mean).collect()
}

/// A note's first [`PROFILE_HARMONICS`] harmonics (below [`MAX_HARMONIC_HZ`]) in dB re the
/// strongest of them, floored at [`PROFILE_FLOOR_DB`].
pub fn profile(n: &NoteSpectrum) -> Vec<f64> {
    let count = n
        .amplitudes
        .len()
        .min(PROFILE_HARMONICS)
        .min((MAX_HARMONIC_HZ / n.fundamental_hz) as usize);
    let a = &n.amplitudes[..count];
    let top = a.iter().copied().fold(0.0, f64::max);
    a.iter()
        .map(|x| (20.0 * (x / top).log10()).max(PROFILE_FLOOR_DB))
        .collect()
}

/// What one instrument scores.
#[derive(Debug, Clone)]
pub struct Score {
    pub kind: InstrumentKind,
    /// The model's name, or the peer's.
    pub model: &'static str,
    pub rate_hz: f64,
    pub notes: Vec<u8>,
    /// Band indices, the model's and the reference's curves, dB.
    pub bands: Vec<i32>,
    pub played: Vec<f64>,
    pub reference: Vec<f64>,
    /// RMS of the difference over the bands, dB, and the largest one.
    pub rms_db: f64,
    pub worst_db: f64,
    /// Mean absolute difference of the notes' harmonic profiles, dB.
    pub profile_db: f64,
    /// The same after the best smooth correction of the played notes (a level per note and
    /// harmonic number and a body curve with a knot every third of an octave,
    /// [`floor::after_smooth_correction`]): the detail part of `profile_db`.
    pub profile_detail_db: f64,
}

/// Plays and scores `kind` with `model` at `rate_hz`.
pub fn score(kind: InstrumentKind, model: TunedModel, rate_hz: f64) -> Score {
    let reference_notes = reference(kind);
    let notes = notes(kind, &reference_notes);
    let played_notes: Vec<NoteSpectrum> = notes
        .par_iter()
        .map(|&n| played(kind, model, rate_hz, n))
        .collect();
    scored(kind, model.name(), rate_hz, played_notes, &reference_notes)
}

/// Scores `played_notes` of `kind` (named `model`, at `rate_hz`) against the same notes of
/// `reference_notes` (the reference's, [`reference`]).
pub fn scored(
    kind: InstrumentKind,
    model: &'static str,
    rate_hz: f64,
    played_notes: Vec<NoteSpectrum>,
    reference_notes: &[NoteSpectrum],
) -> Score {
    let notes: Vec<u8> = played_notes.iter().map(|n| n.note).collect();
    let refs: Vec<&NoteSpectrum> = notes
        .iter()
        .filter_map(|n| reference_notes.iter().find(|r| r.note == *n))
        .collect();
    let range = bands(kind);
    let played = long_term_spectrum(&played_notes.iter().collect::<Vec<_>>(), &range);
    let reference = long_term_spectrum(&refs, &range);
    let diffs: Vec<f64> = played.iter().zip(&reference).map(|(p, r)| p - r).collect();
    let rms_db = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len().max(1) as f64).sqrt();
    let worst_db = diffs.iter().copied().fold(0.0, |m: f64, d| m.max(d.abs()));
    let mut profile_sum = 0.0;
    let mut profile_count = 0;
    for (p, r) in played_notes.iter().zip(&refs) {
        let (p, r) = (profile(p), profile(r));
        for (a, b) in p.iter().zip(&r) {
            profile_sum += (a - b).abs();
            profile_count += 1;
        }
    }
    let refs: Vec<NoteSpectrum> = refs.into_iter().cloned().collect();
    let profile_detail_db =
        floor::after_smooth_correction(&played_notes, &refs, 1.0 / 3.0).profile_db;
    Score {
        kind,
        model,
        rate_hz,
        notes,
        bands: range.collect(),
        played,
        reference,
        rms_db,
        worst_db,
        profile_db: profile_sum / profile_count.max(1) as f64,
        profile_detail_db,
    }
}

/// The band's nominal centre, Hz (`10^(k/10)`).
pub fn centre_hz(band: i32) -> f64 {
    10f64.powf(band as f64 / 10.0)
}

/// `colophony bench timbre`: every instrument with each of `models` at each of `rates`;
/// writes `timbre.csv` (band by band), `summary.csv` and `timbre.png` (the first model and
/// rate) into `out`, and returns the table.
pub fn run(
    out: &Path,
    models: &[TunedModel],
    rates: &[f64],
    kinds: &[InstrumentKind],
) -> Result<String, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut scores = Vec::new();
    for &rate in rates {
        for &model in models {
            for &kind in kinds {
                scores.push(score(kind, model, rate));
            }
        }
    }
    // STK's `Bowed` on the same notes at the first rate, where g++ and libstk-dev are
    // installed: its one string and body for every instrument.
    match crate::precision::peers::build_stk(out) {
        Ok(stk) => {
            let rate = rates[0];
            for &kind in kinds {
                let reference_notes = reference(kind);
                let notes: Vec<u8> = notes(kind, &reference_notes)
                    .into_iter()
                    .filter(|&n| midi_to_hz(n as f64) >= STK_LOWEST_HZ)
                    .collect();
                let played: Option<Vec<NoteSpectrum>> = notes
                    .par_iter()
                    .map(|&n| played_by_stk(&stk, out, rate, n))
                    .collect();
                match played {
                    Some(played) => {
                        scores.push(scored(kind, "stk-bowed", rate, played, &reference_notes))
                    }
                    None => eprintln!("STK's Bowed failed on {}: its row is left out", kind.name()),
                }
            }
            for name in ["stk_bowed", "stk_bowed.cpp"] {
                let _ = std::fs::remove_file(out.join(name));
            }
        }
        Err(e) => eprintln!(
            "STK's Bowed is not compared ({e}; scripts/install-peers.sh or apt-get install libstk-dev g++)"
        ),
    }
    let mut bands_csv =
        String::from("instrument,model,rate_hz,band_hz,reference_db,played_db,difference_db\n");
    let mut summary_csv = String::from(
        "instrument,model,rate_hz,notes,rms_db,worst_band_db,profile_db,profile_detail_db\n",
    );
    let mut table = String::from(
        "instrument    model           rate    notes  RMS dB  worst band dB  profile dB  (detail)  played minus reference, band by band (dB)\n",
    );
    for s in &scores {
        for ((b, p), r) in s.bands.iter().zip(&s.played).zip(&s.reference) {
            let _ = writeln!(
                bands_csv,
                "{},{},{},{:.0},{r:.2},{p:.2},{:.2}",
                s.kind.name(),
                s.model,
                s.rate_hz,
                centre_hz(*b),
                p - r
            );
        }
        let (kind, model, rate, notes) = (s.kind.name(), s.model, s.rate_hz, s.notes.len());
        let (rms, worst, profile, detail) =
            (s.rms_db, s.worst_db, s.profile_db, s.profile_detail_db);
        let _ = writeln!(
            summary_csv,
            "{kind},{model},{rate},{notes},{rms:.2},{worst:.2},{profile:.2},{detail:.2}"
        );
        let diffs: Vec<String> = s
            .played
            .iter()
            .zip(&s.reference)
            .map(|(p, r)| format!("{:+.0}", p - r))
            .collect();
        let _ = writeln!(
            table,
            "{kind:<13} {model:<15} {rate:<7} {notes:>5}  {rms:>6.1}  {worst:>13.1}  {profile:>10.1}  {detail:>8.1}  {}",
            diffs.join(" ")
        );
    }
    // What no smooth model can take out of the profile distance (`floor`).
    let _ = writeln!(
        table,
        "\nProfile floor: a level per note, per harmonic number and a body curve with a knot every \
         third (sixth) of an octave, fitted to the reference's own notes, scored as a played note:"
    );
    for &kind in kinds {
        let reference_notes = reference(kind);
        let refs: Vec<NoteSpectrum> = notes(kind, &reference_notes)
            .iter()
            .filter_map(|n| reference_notes.iter().find(|r| r.note == *n).cloned())
            .collect();
        let (third, sixth) = (
            floor::smooth_fit(&refs, 1.0 / 3.0),
            floor::smooth_fit(&refs, 1.0 / 6.0),
        );
        let _ = writeln!(
            table,
            "{:<13} {:.1} dB ({:.1} dB), {} and {} parameters on {} profile values",
            kind.name(),
            third.profile_db,
            sixth.profile_db,
            third.parameters,
            sixth.parameters,
            third.points
        );
    }
    let write = |name: &str, text: &str| {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))
    };
    write("timbre.csv", &bands_csv)?;
    write("summary.csv", &summary_csv)?;
    let first: Vec<&Score> = scores
        .iter()
        .filter(|s| s.model == models[0].name() && s.rate_hz == rates[0])
        .collect();
    let peers: Vec<&Score> = scores.iter().filter(|s| s.model == "stk-bowed").collect();
    figure(&out.join("timbre.png"), &first, &peers)?;
    Ok(table)
}

/// One panel per instrument: the model's long-term spectrum against the reference's, and
/// STK's where `peers` holds the instrument.
fn figure(out: &Path, scores: &[&Score], peers: &[&Score]) -> Result<(), String> {
    use plotters::prelude::*;
    crate::figures::fonts();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (w, h) = (1400u32, 900u32);
    let root = BitMapBackend::new(out, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((2, 2));
    for (panel, s) in panels.iter().zip(scores) {
        let lo = s.bands.first().copied().unwrap_or(0) as f64 / 10.0;
        let hi = s.bands.last().copied().unwrap_or(1) as f64 / 10.0;
        let mut chart = ChartBuilder::on(panel)
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .caption(
                format!(
                    "{} ({}): RMS {:.1} dB, profile {:.1} dB",
                    s.kind.name(),
                    s.model,
                    s.rms_db,
                    s.profile_db
                ),
                ("sans-serif", 18),
            )
            .build_cartesian_2d(lo - 0.05..hi + 0.05, -30.0..20.0)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("third-octave band (Hz)")
            .y_desc("dB re mean")
            .x_label_formatter(&|x| format!("{:.0}", 10f64.powf(*x)))
            .draw()
            .map_err(|e| err(&e))?;
        let pts = |v: &[f64]| -> Vec<(f64, f64)> {
            s.bands
                .iter()
                .zip(v)
                .map(|(b, d)| (*b as f64 / 10.0, *d))
                .collect()
        };
        chart
            .draw_series(LineSeries::new(pts(&s.reference), BLACK.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label("reference (SHARC, a real player)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(pts(&s.played), RED.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label("Colophony")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED.stroke_width(2)));
        if let Some(peer) = peers.iter().find(|p| p.kind == s.kind) {
            let colour = BLUE.mix(0.6);
            chart
                .draw_series(LineSeries::new(pts(&peer.played), colour.stroke_width(1)))
                .map_err(|e| err(&e))?
                .label(format!("STK Bowed: RMS {:.1} dB", peer.rms_db))
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(1))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference holds each instrument's chromatic run as SHARC lists it (violin G3-C7
    /// 42 notes, viola C3-D6 39, cello C2-G5 44, double bass C1-C#4 38), every note with
    /// harmonics.
    #[test]
    fn the_reference_holds_each_instruments_chromatic_run() {
        for (kind, count, low, high) in [
            (InstrumentKind::Violin, 42, 55, 96),
            (InstrumentKind::Viola, 39, 48, 86),
            (InstrumentKind::Cello, 44, 36, 79),
            (InstrumentKind::DoubleBass, 38, 24, 61),
        ] {
            let r = reference(kind);
            assert_eq!(r.len(), count, "{kind:?}");
            assert_eq!((r[0].note, r[count - 1].note), (low, high), "{kind:?}");
            assert!(r.iter().all(|n| n.amplitudes.iter().any(|&a| a > 0.0)));
        }
    }

    /// The long-term spectrum of one note of harmonics falling as `1/n` (a sawtooth) puts
    /// each harmonic's power in its band: with the fundamental at a band's centre, the
    /// bands an octave apart hold harmonics 1, 2, 4, 8 alone (powers 1, 1/4, 1/16, 1/64:
    /// 6 dB a band apart, as the sawtooth's 1/n^2 powers).
    #[test]
    fn a_sawtooths_harmonics_land_in_their_bands() {
        let f0 = centre_hz(20); // 100 Hz
        let note = NoteSpectrum {
            note: 43,
            fundamental_hz: f0,
            amplitudes: (1..=8).map(|n| 1.0 / n as f64).collect(),
        };
        let range = 20..=29;
        let ltas = long_term_spectrum(&[&note], &range);
        for (k, harmonic) in [(0, 1.0f64), (3, 2.0), (6, 4.0), (9, 8.0)] {
            let expected = ltas[0] - 20.0 * harmonic.log10();
            // Each band holds its harmonic alone: the dB differ by f64 rounding only.
            assert!((ltas[k] - expected).abs() < 1e-9, "band {k}: {}", ltas[k]);
        }
    }
}
