//! Survey (ignored; `cargo test --release -p colophony-lab --test mute_survey --
//! --ignored --nocapture`): what the mute (Con Sordino) takes out of each instrument's
//! long-term spectrum, against what a real mute takes out of a real one. Each instrument
//! plays the timbre benchmark's notes (docs/timbre.md) open and muted at the plugin's
//! defaults (hyperbolic law, 48 kHz); the muted minus the open long-term spectrum, band by
//! band, is printed beside SHARC's (the same violin, viola, cello and double bass played
//! open and muted, by the same method: docs/articulations.md, "Measured mute", made by
//! `scripts/sharc_mute.py`), each less its mean, with their RMS distance.

use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::InstrumentKind;
use colophony_lab::midi_file::{one_note_performed, Performance};
use colophony_lab::timbre::{
    bands, long_term_spectrum, measured, notes, reference, NOTE_S, VELOCITY,
};

const FS: f64 = 48_000.0;

/// SHARC's muted minus open long-term spectrum, dB, from each instrument's lowest band up
/// to 5 kHz (docs/articulations.md, "Measured mute").
fn sharc_mute(kind: InstrumentKind) -> Vec<f64> {
    match kind {
        InstrumentKind::Violin => vec![3, 0, 3, 3, 2, 1, 3, 2, 2, -1, -3, -11, -10, -6, -5],
        InstrumentKind::Viola => vec![7, 10, 6, 3, 1, 0, -1, 7, 4, -1, -6, -7, -3, 1, 5, 2, 3],
        InstrumentKind::Cello => vec![
            12, 2, 1, 3, -1, 0, 1, 5, 0, 2, -4, -4, -8, -3, -15, -12, -8, -11, -9, -1,
        ],
        InstrumentKind::DoubleBass => vec![
            -8, 3, 5, 7, 1, 0, -4, -4, 1, -1, 4, -1, 2, 1, -3, -3, -4, -7, 0, -2, -4, -2,
        ],
    }
    .into_iter()
    .map(f64::from)
    .collect()
}

fn less_mean(x: &[f64]) -> Vec<f64> {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| v - mean).collect()
}

#[test]
#[ignore = "survey: about 20 s in release"]
fn the_mutes_loss_against_a_real_mutes() {
    let law = Some(FrictionModel::Hyperbolic);
    for kind in InstrumentKind::ALL {
        let chosen = notes(kind, &reference(kind));
        let bands = bands(kind);
        let mut spectra = Vec::new();
        for mute in [false, true] {
            let mut how = Performance::plugin_defaults(kind, law, FS);
            how.setup.con_sordino = mute;
            let played: Vec<_> = chosen
                .iter()
                .map(|&note| measured(&one_note_performed(&how, note, VELOCITY, NOTE_S), FS, note))
                .collect();
            let refs: Vec<_> = played.iter().collect();
            spectra.push(long_term_spectrum(&refs, &bands));
        }
        let model: Vec<f64> = spectra[1]
            .iter()
            .zip(&spectra[0])
            .map(|(m, o)| m - o)
            .collect();
        let real = sharc_mute(kind);
        assert_eq!(model.len(), real.len(), "{}: bands", kind.name());
        let (model, real) = (less_mean(&model), less_mean(&real));
        let distance = (model
            .iter()
            .zip(&real)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / model.len() as f64)
            .sqrt();
        let row = |x: &[f64]| {
            x.iter()
                .map(|v| format!("{v:+.0}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!(
            "{:12} {} notes, RMS distance {distance:.1} dB\n  model {}\n  SHARC {}",
            kind.name(),
            chosen.len(),
            row(&model),
            row(&real)
        );
        assert!(model.iter().all(|v| v.is_finite()));
    }
}
