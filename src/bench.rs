//! Real-time ratios printed by `colophony bench ...` (run it from a release build:
//! `cargo run --release -- bench friction`). Ratios are measured in one run, side by side,
//! because absolute times on a shared machine are noisy; each case takes the best of three.

use crate::dsp::friction::FrictionModel;
use crate::dsp::instrument::{BowControl, InstrumentKind};
use crate::dsp::rubbed::RubbedPreset;
use crate::render::{render, render_rubbed, RenderSettings};
use std::time::Instant;

const SECONDS: f64 = 10.0;
const FS: f64 = 48_000.0;

fn best_of_three(mut run: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            run();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::MAX, f64::min)
}

/// A markdown table: each friction law on paper A's cello D scenario (v_b 0.1 m/s,
/// F_N 1.1 N, beta 0.1) and on the wine-glass preset, 10 s at 48 kHz: real-time ratio and
/// cost relative to the static curve.
pub fn friction_table() -> Result<String, String> {
    let mut lines = vec![
        format!("{SECONDS} s at {FS} Hz, best of three; ratio = audio time / wall time (one core)."),
        String::new(),
        "| friction law | cello D: x real time | cost vs static | wine glass: x real time | cost vs static |".into(),
        "|---|---|---|---|---|".into(),
    ];
    let mut rows = Vec::new();
    for model in FrictionModel::ALL {
        let settings = RenderSettings {
            instrument: InstrumentKind::Cello,
            note: 50,
            seconds: SECONDS,
            bow: BowControl {
                velocity_m_per_s: 0.1,
                force_n: 1.1,
                position_beta: 0.1,
            },
            sample_rate_hz: FS,
            friction: model,
            ..RenderSettings::default()
        };
        let mut failure = None;
        let string_s = best_of_three(|| {
            if let Err(e) = render(&settings) {
                failure = Some(e.to_string());
            }
        });
        let glass_s = best_of_three(|| {
            if let Err(e) = render_rubbed(RubbedPreset::WineGlass, model, SECONDS, FS) {
                failure = Some(e.to_string());
            }
        });
        if let Some(e) = failure {
            return Err(e);
        }
        rows.push((model, string_s, glass_s));
    }
    let static_row = rows
        .iter()
        .find(|r| r.0 == FrictionModel::Stribeck)
        .copied()
        .expect("the static law is benchmarked");
    for (model, string_s, glass_s) in rows {
        lines.push(format!(
            "| {} | {:.0} | {:.2} | {:.0} | {:.2} |",
            model.name(),
            SECONDS / string_s,
            string_s / static_row.1,
            SECONDS / glass_s,
            glass_s / static_row.2
        ));
    }
    Ok(lines.join("\n"))
}

/// Paper B's Table 1 on this machine: real-time cost (% of one core) of the thermal bow
/// on the cello C string per node count, beside the paper's (whole cello, Intel P9400).
/// What is timed: the bowed string with both polarisations, hair and thermal grid at the
/// internal rate; the four-string bridge and the resampler are not in yet (issue 4 notes).
pub fn table1() -> Result<String, String> {
    use crate::dsp::thermal::{
        HairParams, ThermalBowControl, ThermalParams, ThermalString, ThermalStringSpec,
    };
    let paper = [
        (3, 4.3),
        (6, 9.2),
        (10, 18.4),
        (20, 49.6),
        (33, 119.0),
        (60, 334.0),
    ];
    let bow = ThermalBowControl {
        velocity_m_per_s: 0.15,
        force_per_m: 300.0,
        position_beta: 0.07,
    };
    let audio_s = 1.0;
    let mut lines = vec![
        "| N_B | dx (mm) | internal rate (kHz) | one string bowed (% of a core) | two strings bowed (%) | paper, whole cello on a P9400 (%) |".to_string(),
        "|---|---|---|---|---|---|".to_string(),
    ];
    for (nodes, paper_percent) in paper {
        let make = |spec: ThermalStringSpec| {
            ThermalString::new(
                spec,
                nodes,
                0.01,
                ThermalParams::default(),
                HairParams::default(),
            )
        };
        let c = ThermalStringSpec::cello_c();
        // The G string: 98 Hz, Z0 ~ 1.3 kg/s (PARAMETERS.md §1.4 scale), same length.
        let g = ThermalStringSpec {
            f0_hz: 98.0,
            z0_kg_per_s: 1.3,
            ..c
        };
        let mut one = make(c)?;
        let fs = one.internal_rate_hz();
        let samples = (audio_s * fs) as usize;
        let single = best_of_three(|| {
            for _ in 0..samples {
                std::hint::black_box(one.tick(bow));
            }
        });
        let mut a = make(c)?;
        let mut b = make(g)?;
        let samples_b = (audio_s * b.internal_rate_hz()) as usize;
        let double = best_of_three(|| {
            for _ in 0..samples {
                std::hint::black_box(a.tick(bow));
            }
            for _ in 0..samples_b {
                std::hint::black_box(b.tick(bow));
            }
        });
        lines.push(format!(
            "| {nodes} | {:.2} | {:.1} | {:.1} | {:.1} | {paper_percent} |",
            10.0 / nodes as f64,
            fs / 1e3,
            100.0 * single / audio_s,
            100.0 * double / audio_s,
        ));
    }
    Ok(lines.join("\n"))
}
