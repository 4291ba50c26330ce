//! Measures the intonation table (`colophony bench intonation --out FILE`): for every
//! friction model, instrument, string and semitone above the open string, the cents by
//! which the bowed note misses equal temperament at nominal bowing, folded into the
//! table the engines tune by ([`colophony::dsp::intonation`]).
//!
//! Each pass bows every entry twice through the engines the plugin plays
//! ([`crate::playing_space::render_cell`]): with the plugin's defaults (0.1 m/s, 1 N,
//! beta 0.1) and at the geometric middle of the note's Schelleng window (beta 0.1), one
//! second each, measured after the 0.3 s settling time as the playing-space map measures.
//! The residual of an entry is the mean of the two bowed pitches that sounded near the
//! note (within [`TRUSTED_CENTS`]); an entry with neither takes the residual of its
//! neighbours on the same string, and the residuals of a string are smoothed by a median
//! over five semitones (an irregular regime scatters the pitch; the correction changes
//! smoothly with the stopped length). The first pass starts from free-decay tuning (a zero
//! table); each later pass bows with the table so far and adds its residuals, so a pass
//! corrects what the previous one's correction changed (a string tuned lower slips a
//! little differently).

use crate::playing_space::{measure, Bowing, Cell, Model};
use colophony::dsp::instrument::{InstrumentKind, MAX_STOP_SEMITONES, STRINGS};
use colophony::dsp::intonation::{model_index, IntonationTable};
use colophony::editor::regime::Regime;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// A bowed pitch further than this from the note is another regime (an octave, a
/// wolf-like jump) or noise, not a mistuning: it does not steer the table, cents.
pub const TRUSTED_CENTS: f64 = 60.0;

/// One entry of the table.
#[derive(Debug, Clone, Copy)]
struct Entry {
    model: Model,
    kind: InstrumentKind,
    string: usize,
    semitone: usize,
}

impl Entry {
    fn note(&self) -> u8 {
        self.kind.open_notes()[self.string] + self.semitone as u8
    }
}

fn entries(models: &[Model]) -> Vec<Entry> {
    let mut v = Vec::new();
    for &model in models {
        for kind in InstrumentKind::ALL {
            for string in 0..STRINGS {
                for semitone in 0..=MAX_STOP_SEMITONES as usize {
                    v.push(Entry {
                        model,
                        kind,
                        string,
                        semitone,
                    });
                }
            }
        }
    }
    v
}

/// The residual one bowed cell says, if it can be trusted.
fn trusted(cents: f64, regime: Option<Regime>) -> Option<f64> {
    let sounding = matches!(
        regime,
        Some(Regime::Helmholtz | Regime::MultipleSlips(_) | Regime::Raucous)
    );
    (sounding && cents.is_finite() && cents.abs() < TRUSTED_CENTS).then_some(cents)
}

/// One pass: bows every entry with `table` and returns each entry's residual (NaN where
/// no bowing could be trusted) and the cells' pitches.
fn residuals(
    entries: &[Entry],
    table: &'static IntonationTable,
    rate_hz: f64,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<(f64, f64, f64)>, String> {
    entries
        .par_iter()
        .map(|e| {
            let mut pitches = [f64::NAN; 2];
            for (k, bowing) in [Bowing::Defaults, Bowing::Middle].into_iter().enumerate() {
                let mut cell = Cell::on_string(
                    e.model,
                    e.kind,
                    e.note(),
                    Some(e.string),
                    rate_hz,
                    bowing,
                    1.0,
                );
                cell.intonation = Some(table);
                let m = measure(&cell)?;
                pitches[k] = trusted(m.cents, m.regime).unwrap_or(f64::NAN);
                bar.inc(1);
            }
            let valid: Vec<f64> = pitches.iter().copied().filter(|c| c.is_finite()).collect();
            let r = if valid.is_empty() {
                f64::NAN
            } else {
                valid.iter().sum::<f64>() / valid.len() as f64
            };
            Ok((r, pitches[0], pitches[1]))
        })
        .collect()
}

/// Fills NaN residuals from the nearest trusted semitones of the same string (linear
/// between two, the nearest one at the ends, 0 if the string has none).
fn fill_gaps(values: &mut [f64]) {
    let known: Vec<usize> = (0..values.len())
        .filter(|&i| values[i].is_finite())
        .collect();
    if known.is_empty() {
        values.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    for i in 0..values.len() {
        if values[i].is_finite() {
            continue;
        }
        let below = known.iter().rev().find(|&&k| k < i).copied();
        let above = known.iter().find(|&&k| k > i).copied();
        values[i] = match (below, above) {
            (Some(a), Some(b)) => {
                let t = (i - a) as f64 / (b - a) as f64;
                values[a] + t * (values[b] - values[a])
            }
            (Some(a), None) => values[a],
            (None, Some(b)) => values[b],
            (None, None) => 0.0,
        };
    }
}

/// Replaces each value by the median of itself and its neighbours up to `half` semitones
/// away on the same string: the bowed pitch of an irregular regime is scattered, while
/// the correction a string needs changes smoothly with its stopped length.
fn median_filter(values: &mut [f64], half: usize) {
    let source = values.to_vec();
    for (i, v) in values.iter_mut().enumerate() {
        let lo = i.saturating_sub(half);
        let hi = (i + half + 1).min(source.len());
        let mut w = source[lo..hi].to_vec();
        w.sort_by(f64::total_cmp);
        let n = w.len();
        *v = if n % 2 == 1 {
            w[n / 2]
        } else {
            0.5 * (w[n / 2 - 1] + w[n / 2])
        };
    }
}

/// Neighbours on each side in the median filter of the residuals.
const MEDIAN_HALF_WIDTH: usize = 2;

/// Runs `passes` passes at `rate_hz` for `models` and returns the table and a report.
pub fn fit(
    models: &[Model],
    rate_hz: f64,
    passes: usize,
) -> Result<(IntonationTable, String), String> {
    let entries = entries(models);
    let mut table = IntonationTable::zero();
    let mut report = String::new();
    let per_string = MAX_STOP_SEMITONES as usize + 1;
    for pass in 0..passes.max(1) {
        // The engines hold the table by a static reference; one leak per pass, in a tool.
        let current: &'static IntonationTable = Box::leak(Box::new(table.clone()));
        let bar = indicatif::ProgressBar::new(2 * entries.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} cells, eta {eta}",
        ) {
            bar.set_style(style);
        }
        let measured = residuals(&entries, current, rate_hz, &bar)?;
        bar.finish_and_clear();
        let _ = writeln!(
            report,
            "pass {} (bowed with the table of pass {}):",
            pass + 1,
            pass
        );
        for &model in models {
            let rows: Vec<(usize, &(f64, f64, f64))> = entries
                .iter()
                .zip(&measured)
                .enumerate()
                .filter(|(_, (e, _))| e.model == model)
                .map(|(i, (_, m))| (i, m))
                .collect();
            let cells: Vec<f64> = rows
                .iter()
                .flat_map(|(_, m)| [m.1, m.2])
                .filter(|c| c.is_finite())
                .collect();
            let within = cells.iter().filter(|c| c.abs() <= 3.0).count();
            let mut abs: Vec<f64> = cells.iter().map(|c| c.abs()).collect();
            abs.sort_by(f64::total_cmp);
            let median = abs.get(abs.len() / 2).copied().unwrap_or(f64::NAN);
            let _ = writeln!(
                report,
                "  {:15} {} of {} nominal cells sounded near the note; {} ({:.0} %) within 3 cents; median |error| {:.1} cents",
                model.name(),
                cells.len(),
                2 * rows.len(),
                within,
                100.0 * within as f64 / cells.len().max(1) as f64,
                median
            );
        }
        // Fold the residuals in, string by string.
        for chunk in entries.chunks(per_string).zip(measured.chunks(per_string)) {
            let (es, ms) = chunk;
            let mut r: Vec<f64> = ms.iter().map(|m| m.0).collect();
            fill_gaps(&mut r);
            median_filter(&mut r, MEDIAN_HALF_WIDTH);
            for (e, r) in es.iter().zip(r) {
                let row = model_index(e.model.name());
                let old = table.get(row, e.kind, e.string, e.semitone);
                table.set(row, e.kind, e.string, e.semitone, old + r);
            }
        }
    }
    Ok((table, report))
}

/// `colophony bench intonation --out FILE [--rates HZ] [--models ..]`: fits the table at
/// the first rate given (48 kHz by default) and writes it, with a header, to `out`.
pub fn run(out: &Path, models: &[Model], rate_hz: f64, passes: usize) -> Result<String, String> {
    let (table, report) = fit(models, rate_hz, passes)?;
    // Models not fitted keep the shipped entries.
    let mut merged = colophony::dsp::intonation::shipped().clone();
    for &model in models {
        let row = model_index(model.name());
        for kind in InstrumentKind::ALL {
            for string in 0..STRINGS {
                for s in 0..=MAX_STOP_SEMITONES as usize {
                    merged.set(row, kind, string, s, table.get(row, kind, string, s));
                }
            }
        }
    }
    let text = format!(
        "# Intonation by the bowed sound (src/dsp/intonation.rs): cents each stopped note is moved\n\
         # from its equal-tempered free-decay pitch so that it sounds in tune bowed at nominal.\n\
         # Measured by `colophony bench intonation` at {rate_hz} Hz, {passes} passes.\n{}",
        merged.to_csv()
    );
    std::fs::write(out, text).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    Ok(format!("{report}wrote {}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_take_their_neighbours() {
        let mut v = [f64::NAN, 2.0, f64::NAN, f64::NAN, 8.0, f64::NAN];
        fill_gaps(&mut v);
        assert_eq!(v, [2.0, 2.0, 4.0, 6.0, 8.0, 8.0]);
        let mut none = [f64::NAN; 3];
        fill_gaps(&mut none);
        assert_eq!(none, [0.0; 3]);
    }

    #[test]
    fn the_median_filter_drops_a_lone_outlier_and_keeps_a_trend() {
        let mut v = [1.0, 2.0, 3.0, 40.0, 5.0, 6.0, 7.0];
        median_filter(&mut v, 2);
        assert_eq!(v, [2.0, 2.5, 3.0, 5.0, 6.0, 6.5, 6.0]);
    }

    #[test]
    fn far_or_silent_pitches_do_not_steer_the_table() {
        assert_eq!(trusted(5.0, Some(Regime::Helmholtz)), Some(5.0));
        assert_eq!(trusted(80.0, Some(Regime::Helmholtz)), None);
        assert_eq!(trusted(1.0, Some(Regime::Sliding)), None);
        assert_eq!(trusted(1.0, None), None);
    }
}
