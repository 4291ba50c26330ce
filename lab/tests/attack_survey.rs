//! Attacks through the performer, as the plugin plays a note from MIDI at the defaults:
//! each instrument's range (three octaves from the lowest open string, every third
//! semitone) at note velocities 0.3, 0.55, 0.8 and 1.0 (the velocity sets the bow's
//! acceleration, `src/performer/stroke.rs`), every point law, 2.5 s each; the editor's
//! regime classifier on the contact probe over 1.5-2.5 s. A survey, printed, not
//! asserted: which limit cycle an attack falls into is chaotic, so it is read as counts.
//!
//! As last run, attacks in Helmholtz motion, of 52 (hyperbolic / static / LuGre /
//! elasto-plastic; the violin's and viola's strings and the cello's A string at 96 kHz
//! inside, the plugin's bristle at `sigma0` 3e5 N/m): violin 49 / 51 / 51 / 52, viola
//! 48 / 52 / 51 / 52, cello 50 / 50 / 52 / 50. Among the misses (double slips or
//! raucous): the cello's D#3 and F#4 at velocity 1.0 with the hyperbolic law, its F#2 with
//! the static law and at velocities 0.3 and 1.0 with elasto-plastic; the violin's E6 at
//! 0.8 and the viola's D#5 at 1.0 with LuGre. `cargo test --release --test attack_survey
//! -- --ignored --nocapture`.
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony::measure::contact::ContactSample;
use colophony::measure::regime::{classify_regime, Regime};
use colophony::performer::{Performer, Setup};

const FS: f64 = 48_000.0;

#[test]
#[ignore]
fn attacks_through_the_performer_survey() {
    for kind in InstrumentKind::ALL {
        for law in FrictionModel::ALL {
            let (low, high) = kind.note_range();
            let mut helm = 0;
            let mut total = 0;
            let mut line = String::new();
            for note in (low..=high.min(low + 36)).step_by(3) {
                for vel in [0.3f32, 0.55, 0.8, 1.0] {
                    let setup = Setup {
                        instrument: kind,
                        point_law: Some(law),
                        ..Setup::default()
                    };
                    let mut p = Performer::new(kind);
                    p.activate(&setup, FS).unwrap();
                    p.note_on(note, vel);
                    let bow = BowControl::default();
                    let n = (2.5 * FS) as usize;
                    let mut probe = Vec::with_capacity(n);
                    for i in 0..n {
                        if i % 256 == 0 {
                            p.configure(&setup);
                        }
                        let frame = p.tick(bow);
                        probe.push(ContactSample::new(&frame, &p.bow()));
                    }
                    let f0 = midi_to_hz(note as f64);
                    let r = classify_regime(&probe[(1.5 * FS) as usize..], FS as f32, f0 as f32);
                    total += 1;
                    if r == Some(Regime::Helmholtz) {
                        helm += 1;
                    } else {
                        line += &format!(" {note}@{vel}:{r:?}");
                    }
                }
            }
            println!(
                "{:?} {}: {helm} of {total} attacks in Helmholtz motion at 1.5-2.5 s;{line}",
                kind,
                law.name()
            );
        }
    }
}

/// Guettler's diagram on the bare instrument (no performer): cello D3 (or `NOTE`), the
/// hyperbolic law, beta 0.1 (or `BETA`), the bow from rest at constant acceleration to
/// 0.1 m/s (0: landing at speed) at constant force, 0.6 s; printed: the time from the
/// landing to established Helmholtz motion ([`helmholtz_since`]), ms. `cargo test --release
/// -p colophony-lab --test attack_survey guettler -- --ignored --nocapture`.
#[test]
#[ignore]
fn guettler_diagram_survey() {
    use colophony::dsp::instrument::Instrument;
    use colophony::measure::regime::helmholtz_since;
    let note: u8 = std::env::var("NOTE").map_or(50, |s| s.parse().expect("NOTE: a MIDI note"));
    let beta: f64 = std::env::var("BETA").map_or(0.1, |s| s.parse().expect("BETA: 0.02-0.25"));
    let f0 = midi_to_hz(note as f64);
    let accels = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
    println!("cello note {note}, beta {beta}: rows bow force (N), columns acceleration (m/s^2; 0: landing at speed); ms to Helmholtz motion");
    println!(
        "      {}",
        accels.iter().map(|a| format!("{a:>7}")).collect::<String>()
    );
    for force_n in [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0] {
        let mut row = format!("{force_n:>5} ");
        for &a in &accels {
            let mut cello = Instrument::new(InstrumentKind::Cello, FS);
            cello.set_friction_model(FrictionModel::Hyperbolic);
            cello.note_on(note);
            let n = (0.6 * FS) as usize;
            let mut probe = Vec::with_capacity(n);
            for i in 0..n {
                if i % 256 == 0 {
                    cello.update_sleep();
                }
                let t = i as f64 / FS;
                let bow = BowControl {
                    velocity_m_per_s: if a == 0.0 { 0.1 } else { (a * t).min(0.1) },
                    force_n,
                    position_beta: beta,
                };
                probe.push(ContactSample::new(&cello.tick(bow), &bow));
            }
            row += &match helmholtz_since(&probe, FS as f32, f0 as f32) {
                Some(k) => format!("{:>7.0}", k as f64 / FS * 1e3),
                None => "  never".into(),
            };
        }
        println!("{row}");
    }
}
