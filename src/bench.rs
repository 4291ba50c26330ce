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
