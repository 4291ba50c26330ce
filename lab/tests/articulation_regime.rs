//! The regime the strings play in tremolo, spiccato and sautillé, through the performer as the
//! plugin plays them at the defaults: each instrument over two octaves from its lowest
//! string (every fourth semitone), the hyperbolic and the static law, velocity 0.8; the
//! editor's regime classifier on the contact probe. A survey, printed, not asserted:
//! which limit cycle a stroke falls into is chaotic, so it is read as counts.
//!
//! - **Tremolo** (12 strokes a second): each stroke from 0.25 s to 2 s, classified over
//!   40-95 % of its length (after the bow's turn, which takes its first 30 %).
//! - **Spiccato**: separate notes of 0.25 s; each contact of the bouncing bow that lasts
//!   at least five periods, classified over its second half.
//! - **Sautillé** (12 strokes a second): separate notes a stroke long, each contact as in
//!   spiccato.
//!
//! `cargo test --release -p colophony-lab --test articulation_regime -- --ignored --nocapture`;
//! the counts are in docs/articulations.md.
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony::measure::contact::ContactSample;
use colophony::measure::regime::{classify_regime, Regime};
use colophony::performer::{Articulation, Performer, Setup};

const FS: f64 = 48_000.0;

/// The probe of `note` played as `setup` asks for `seconds`, the note released and played
/// again every `every_s` seconds when given (separate notes), else held.
fn probe(setup: &Setup, note: u8, seconds: f64, every_s: Option<f64>) -> Vec<ContactSample> {
    let mut p = Performer::new(setup.instrument);
    p.activate(setup, FS).unwrap();
    let bow = BowControl::default();
    let n = (seconds * FS) as usize;
    let every = every_s.map(|s| (s * FS) as usize);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        if i % 256 == 0 {
            p.configure(setup);
        }
        match every {
            Some(e) if i % e == 0 => {
                if i > 0 {
                    p.note_off(note);
                }
                p.note_on(note, 0.8);
            }
            None if i == 0 => p.note_on(note, 0.8),
            _ => {}
        }
        let frame = p.tick(bow);
        out.push(ContactSample::new(&frame, &p.bow()));
    }
    out
}

/// The regime of each contact in `samples` (the bow touching the string) that lasts at
/// least five periods of `f0` (`period` samples), classified over its second half.
fn contacts(samples: &[ContactSample], period: f64, f0: f64) -> Vec<Option<Regime>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, s) in samples.iter().enumerate() {
        let touching = s.mu.abs() > 1e-3;
        match (touching, start) {
            (true, None) => start = Some(i),
            (false, Some(a)) => {
                if (i - a) as f64 >= 5.0 * period {
                    let half = a + (i - a) / 2;
                    out.push(classify_regime(&samples[half..i], FS as f32, f0 as f32));
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Counts of Helmholtz motion among `regimes`, and the others by name.
fn tally(regimes: &[Option<Regime>]) -> (usize, usize, String) {
    let helm = regimes
        .iter()
        .filter(|r| **r == Some(Regime::Helmholtz))
        .count();
    let mut others = std::collections::BTreeMap::new();
    for r in regimes.iter().filter(|r| **r != Some(Regime::Helmholtz)) {
        *others.entry(format!("{r:?}")).or_insert(0) += 1;
    }
    (helm, regimes.len(), format!("{others:?}"))
}

#[test]
#[ignore]
fn tremolo_spiccato_and_sautille_regime_survey() {
    for kind in InstrumentKind::ALL {
        for law in [FrictionModel::Hyperbolic, FrictionModel::Stribeck] {
            let (low, _) = kind.note_range();
            let (mut trem, mut spicc, mut saut) = (Vec::new(), Vec::new(), Vec::new());
            for note in (low..=low + 24).step_by(4) {
                let f0 = midi_to_hz(note as f64);
                let period = FS / f0;
                let tremolo = Setup {
                    instrument: kind,
                    point_law: Some(law),
                    articulation: Articulation::Tremolo,
                    ..Setup::default()
                };
                let stroke = FS / tremolo.tremolo_rate_hz;
                let samples = probe(&tremolo, note, 2.0, None);
                let mut k = (0.25 * FS / stroke).ceil();
                while (k + 1.0) * stroke <= samples.len() as f64 {
                    let from = ((k + 0.4) * stroke) as usize;
                    let to = ((k + 0.95) * stroke) as usize;
                    trem.push(classify_regime(&samples[from..to], FS as f32, f0 as f32));
                    k += 1.0;
                }
                let spiccato = Setup {
                    articulation: Articulation::Spiccato,
                    ..tremolo
                };
                let samples = probe(&spiccato, note, 2.0, Some(0.25));
                spicc.extend(contacts(&samples, period, f0));
                let sautille = Setup {
                    articulation: Articulation::Sautille,
                    ..tremolo
                };
                let samples = probe(&sautille, note, 2.0, Some(stroke / FS));
                saut.extend(contacts(&samples, period, f0));
            }
            let (h, n, others) = tally(&trem);
            println!(
                "{kind:?} {law:?} tremolo: {h} of {n} strokes in Helmholtz motion; others {others}"
            );
            let (h, n, others) = tally(&spicc);
            println!("{kind:?} {law:?} spiccato: {h} of {n} contacts in Helmholtz motion; others {others}");
            let (h, n, others) = tally(&saut);
            println!("{kind:?} {law:?} sautille: {h} of {n} contacts in Helmholtz motion; others {others}");
        }
    }
}
