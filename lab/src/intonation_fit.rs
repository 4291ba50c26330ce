//! Measures the intonation table (`colophony bench intonation --out FILE`): for every
//! friction model, instrument, string and semitone above the open string, the cents by
//! which the bowed note misses equal temperament at nominal bowing, folded into the
//! table the engines tune by ([`colophony::dsp::intonation`]).
//!
//! A player tunes by the note as they usually bow it. Each pass bows every entry through
//! the engines the plugin plays ([`crate::playing_space::render_cell`]) at the plugin's
//! defaults (0.1 m/s, 1 N on the knob times the string's weight, beta 0.1: `F_max / 2` of
//! the point laws' window on every string), [`FIT_SECONDS`] long, and measures it after
//! the 0.3 s settling time as the playing-space map measures. An entry's residual is, in
//! this order of trust (`residual`):
//! 1. the bowed pitch where the note is in Helmholtz motion by the map's full criterion
//!    (one slip a period, slip fraction within 15 % of beta, sticking at the bow
//!    velocity) and within [`TRUSTED_CENTS`];
//! 2. else, where the note sounds in another regime near its pitch (within
//!    [`TRUSTED_CENTS`]: double slips and irregular slipping keep the period), that pitch:
//!    it is what the player hears at the defaults, if less steady;
//! 3. else (an octave or a wolf-like jump, silence) the residual of its neighbours on the
//!    same string (linear between the nearest two).
//!
//! Entries are not smoothed: the bowed pitch of neighbouring semitones differs by
//! several cents (the Helmholtz period locks to the discretisation: docs/playing-space.md,
//! "The sample-grid lock"), and a smoothed table leaves each note that difference out of
//! tune. The first pass starts from free-decay tuning (a zero table); each later pass bows
//! with the table so far and adds its residuals, so a pass corrects what the previous
//! one's correction changed.
//!
//! The window's geometric middle (`F_max / 11`), the other nominal bowing, is not what the
//! table centres: for the point laws it is rarely Helmholtz motion, and its pitch (its
//! regime's) lies some cents from the defaults' (hyperbolic -4.8, static +6.6 cents,
//! median). The earlier procedure averaged it in (and smoothed over five semitones),
//! leaving the notes played at the defaults half that difference out of tune
//! (docs/playing-space.md, "Tuned at the defaults").
//!
//! With `--free` it fits the table's free-ring row for paper B's thermal strings instead
//! ([`fit_free`]): each note plucked, the pitch of its ring folded in the same way
//! (docs/articulations.md#pizzicato).

use crate::playing_space::{measure, Bowing, Cell, Model};
use colophony::dsp::intonation::{IntonationTable, SOFT_EXPRESSIONS, THERMAL_FREE_ROW};
use colophony::dsp::vocabulary::{InstrumentKind, MAX_STOP_SEMITONES, STRINGS};
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

fn entries(models: &[Model], kinds: &[InstrumentKind]) -> Vec<Entry> {
    let mut v = Vec::new();
    for &model in models {
        for &kind in kinds {
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

/// The residual one bowed cell says, if it can be trusted: a note in Helmholtz motion
/// near its pitch.
fn trusted(cents: f64, helmholtz: bool) -> Option<f64> {
    (helmholtz && cents.is_finite() && cents.abs() < TRUSTED_CENTS).then_some(cents)
}

/// One entry's residual by the module doc's order of trust: `(cents, helmholtz)` from a
/// note in Helmholtz motion, else from a note in another regime near its pitch, else NaN
/// (its neighbours fill it).
fn residual(cents: f64, helmholtz: bool) -> (f64, bool) {
    match trusted(cents, helmholtz) {
        Some(c) => (c, true),
        None => (trusted(cents, true).unwrap_or(f64::NAN), false),
    }
}

/// Length of each fitting render, s: [`crate::playing_space::SETTLE_S`] to settle, then
/// 0.9 s measured (above a hundred periods of the lowest note).
pub const FIT_SECONDS: f64 = 1.2;

/// One pass: bows every entry with `table` at the defaults, at the dynamics'
/// `expression` (1: full; below, the bow the Dynamics Guard plays there,
/// [`Cell::at_expression`]), and returns each entry's [`residual`].
fn residuals(
    entries: &[Entry],
    table: &'static IntonationTable,
    rate_hz: f64,
    expression: f64,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<(f64, bool)>, String> {
    entries
        .par_iter()
        .map(|e| {
            let mut cell = Cell::on_string(
                e.model,
                e.kind,
                e.note(),
                Some(e.string),
                rate_hz,
                Bowing::Defaults,
                FIT_SECONDS,
            )
            .at_expression(expression);
            cell.intonation = Some(table);
            let m = measure(&cell)?;
            bar.inc(1);
            Ok(residual(m.cents, m.helmholtz))
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

/// Runs `passes` passes at `rate_hz` for `models` and returns the table and a report;
/// with `dynamics`, instead, as many for each of [`SOFT_EXPRESSIONS`] (those within 0.001
/// of one of `expressions`, or all where it is empty), lowest first, each starting from
/// the correction the shipped table interpolates there without it; the full expression's
/// corrections stay (the point laws only: paper B's thermal bow slides at the soft
/// dynamics, docs/testing.md, "Dynamics").
pub fn fit(
    models: &[Model],
    kinds: &[InstrumentKind],
    rate_hz: f64,
    passes: usize,
    dynamics: bool,
    expressions: &[f64],
) -> Result<(IntonationTable, String), String> {
    if !dynamics {
        return fit_full(models, kinds, rate_hz, passes);
    }
    let mut table = colophony::dsp::intonation::shipped().clone();
    let mut report = String::new();
    {
        let points: Vec<Model> = models
            .iter()
            .copied()
            .filter(|m| matches!(m, Model::Point(_)))
            .collect();
        for level in 0..SOFT_EXPRESSIONS.len() {
            let asked = expressions.is_empty()
                || expressions
                    .iter()
                    .any(|e| (e - SOFT_EXPRESSIONS[level]).abs() < 1e-3);
            if !asked {
                continue;
            }
            let more = fit_soft(&mut table, &points, kinds, rate_hz, passes, level)?;
            report += &more;
        }
    }
    Ok((table, report))
}

/// A progress bar over `n` cells.
fn progress(n: usize) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(n as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{elapsed_precise} [{bar:40}] {pos}/{len} cells, eta {eta}",
    ) {
        bar.set_style(style);
    }
    bar
}

/// The passes at soft expression `level` ([`SOFT_EXPRESSIONS`]) for `models`, starting
/// from what the table interpolates there without the level (between its neighbours):
/// each pass bows with the table so far and adds its residuals to the entries at that
/// level.
fn fit_soft(
    table: &mut IntonationTable,
    models: &[Model],
    kinds: &[InstrumentKind],
    rate_hz: f64,
    passes: usize,
    level: usize,
) -> Result<String, String> {
    let entries = entries(models, kinds);
    let expression = SOFT_EXPRESSIONS[level];
    let mut report = String::new();
    for e in &entries {
        let row = e.model.row();
        table.set_soft(row, e.kind, e.string, e.semitone, level, f64::NAN);
        let between = table.correction_at(row, e.kind, e.string, e.semitone as f64, expression);
        table.set_soft(row, e.kind, e.string, e.semitone, level, between);
    }
    for pass in 0..passes.max(1) {
        let current: &'static IntonationTable = Box::leak(Box::new(table.clone()));
        let bar = progress(entries.len());
        let measured = residuals(&entries, current, rate_hz, expression, &bar)?;
        bar.finish_and_clear();
        let helm: Vec<f64> = measured.iter().filter(|m| m.1).map(|m| m.0).collect();
        let within = helm.iter().filter(|c| c.abs() <= 5.0).count();
        let _ = writeln!(
            report,
            "expression {expression:.2}, pass {}: {} of {} notes in Helmholtz motion near their pitch, {within} of them within 5 cents",
            pass + 1,
            helm.len(),
            entries.len(),
        );
        fold(table, &entries, &measured, Some(level));
    }
    Ok(report)
}

/// Adds one pass's residuals `measured` (one per entry, [`residual`]) to `table`'s
/// entries, string by string, gaps filled from their neighbours ([`fill_gaps`]): at
/// full expression (`level` `None`) or at soft expression `level`.
fn fold(
    table: &mut IntonationTable,
    entries: &[Entry],
    measured: &[(f64, bool)],
    level: Option<usize>,
) {
    let per_string = MAX_STOP_SEMITONES as usize + 1;
    for (es, ms) in entries.chunks(per_string).zip(measured.chunks(per_string)) {
        let mut r: Vec<f64> = ms.iter().map(|m| m.0).collect();
        fill_gaps(&mut r);
        for (e, r) in es.iter().zip(r) {
            let (row, k, string, s) = (e.model.row(), e.kind, e.string, e.semitone);
            match level {
                None => table.set(row, k, string, s, table.get(row, k, string, s) + r),
                Some(l) => {
                    let old = table.get_soft(row, k, string, s, l);
                    table.set_soft(row, k, string, s, l, old + r);
                }
            }
        }
    }
}

/// The full expression's passes of [`fit`].
fn fit_full(
    models: &[Model],
    kinds: &[InstrumentKind],
    rate_hz: f64,
    passes: usize,
) -> Result<(IntonationTable, String), String> {
    let entries = entries(models, kinds);
    let mut table = IntonationTable::zero();
    let mut report = String::new();
    for pass in 0..passes.max(1) {
        // The engines hold the table by a static reference; one leak per pass, in a tool.
        let current: &'static IntonationTable = Box::leak(Box::new(table.clone()));
        let bar = progress(entries.len());
        let measured = residuals(&entries, current, rate_hz, 1.0, &bar)?;
        bar.finish_and_clear();
        let _ = writeln!(
            report,
            "pass {} (bowed with the table of pass {}):",
            pass + 1,
            pass
        );
        for &model in models {
            let of_model = || {
                entries
                    .iter()
                    .zip(&measured)
                    .filter(move |(e, _)| e.model == model)
                    .map(|(_, m)| *m)
            };
            let total = of_model().count();
            let cells: Vec<f64> = of_model().filter(|m| m.1).map(|m| m.0).collect();
            let other = of_model().filter(|m| !m.1 && m.0.is_finite()).count();
            let within = cells.iter().filter(|c| c.abs() <= 3.0).count();
            let mut abs: Vec<f64> = cells.iter().map(|c| c.abs()).collect();
            abs.sort_by(f64::total_cmp);
            let median = abs.get(abs.len() / 2).copied().unwrap_or(f64::NAN);
            let _ = writeln!(
                report,
                "  {:15} {} of {} notes in Helmholtz motion near their pitch at the defaults; {} ({:.0} %) of them within 3 cents; median |error| {:.1} cents; {} more near their pitch in another regime",
                model.name(),
                cells.len(),
                total,
                within,
                100.0 * within as f64 / cells.len().max(1) as f64,
                median,
                other
            );
        }
        fold(&mut table, &entries, &measured, None);
    }
    Ok((table, report))
}

/// How long each plucked note rings for the free-pitch fit, and where its pitch is read
/// from, s: after the pluck's first passes, over tens of periods of the lowest note.
const FREE_SECONDS: f64 = 0.5;
const FREE_FROM_S: f64 = 0.05;

/// One thermal note plucked on its string at velocity 0.8 (the player's pluck,
/// [`colophony::performer::articulation::pluck_for`]) at the plugin's default bow
/// discretisation, tuned by `table`: how far its ring sounds from equal temperament,
/// cents (the strongest peak within [`TRUSTED_CENTS`] over 0.05-0.5 s of the output); NaN
/// if the note is refused, goes to another string, or its peak sits at the search's edge
/// (another resonance: its neighbours fill it).
fn free_residual(e: &Entry, table: &'static IntonationTable, rate_hz: f64) -> Result<f64, String> {
    use colophony::analysis::{cents, peak_frequency_hz};
    use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
    use colophony::dsp::vocabulary::{midi_to_hz, BowControl};
    let bridge = colophony::dsp::bridge_data::shipped_bridge(e.kind);
    let settings = ThermalSettings {
        nodes: colophony::quality::GOOD_NODES,
        width_m: 0.01,
    };
    let mut engine = ThermalInstrument::new(e.kind, &bridge.modes, rate_hz, settings)?;
    engine.set_intonation(Some(table));
    engine.set_preferred_string(Some(e.string));
    let pluck = colophony::performer::articulation::pluck_for(e.kind, 0.8);
    if engine.pluck(e.note(), pluck) != Some(e.string) {
        return Ok(f64::NAN);
    }
    let audio: Vec<f64> = (0..(FREE_SECONDS * rate_hz) as usize)
        .map(|_| engine.tick(BowControl::default()).audio)
        .collect();
    let f = midi_to_hz(e.note() as f64);
    let heard = peak_frequency_hz(
        &audio[(FREE_FROM_S * rate_hz) as usize..],
        rate_hz,
        f,
        TRUSTED_CENTS,
    );
    let c = cents(heard, f);
    Ok(if c.is_finite() && c.abs() < TRUSTED_CENTS - 5.0 {
        c
    } else {
        f64::NAN
    })
}

/// The thermal strings' free-ring row ([`THERMAL_FREE_ROW`]): `passes` passes over every
/// note of `kinds` plucked (`free_residual`), starting from the shipped table with that
/// row at zero (free-decay tuning); each pass plucks with the table so far and adds its
/// residuals, string by string, gaps filled from their neighbours. A last pass plucks
/// with the result: where a note then rings further from its pitch than with no
/// correction (a wolf-like note, two resonances whose strongest changes side, which the
/// passes do not settle), its correction is dropped.
pub fn fit_free(
    kinds: &[InstrumentKind],
    rate_hz: f64,
    passes: usize,
) -> Result<(IntonationTable, String), String> {
    let entries = entries(&[Model::Thermal], kinds);
    let mut table = colophony::dsp::intonation::shipped().clone();
    for e in &entries {
        table.set(THERMAL_FREE_ROW, e.kind, e.string, e.semitone, 0.0);
    }
    let mut report = String::new();
    let per_string = MAX_STOP_SEMITONES as usize + 1;
    let pluck_all = |table: &IntonationTable| {
        let current: &'static IntonationTable = Box::leak(Box::new(table.clone()));
        let bar = progress(entries.len());
        let measured = entries
            .par_iter()
            .map(|e| {
                let r = free_residual(e, current, rate_hz);
                bar.inc(1);
                r
            })
            .collect::<Result<Vec<f64>, String>>();
        bar.finish_and_clear();
        measured
    };
    // Notes within 5 cents per instrument, of those `values` reads.
    let within = |kind: InstrumentKind, values: &[f64]| {
        let of_kind = || {
            entries
                .iter()
                .zip(values)
                .filter(move |(e, _)| e.kind == kind)
        };
        (
            of_kind().filter(|(_, c)| c.abs() <= 5.0).count(),
            of_kind().count(),
        )
    };
    let untuned = pluck_all(&table)?;
    let mut measured = untuned.clone();
    for pass in 0..passes.max(1) {
        for &kind in kinds {
            let (n, of) = within(kind, &measured);
            let _ = writeln!(
                report,
                "pass {} (plucked with the table of pass {pass}): {kind:?}: {n} of {of} notes ring within 5 cents",
                pass + 1,
            );
        }
        for (es, ms) in entries.chunks(per_string).zip(measured.chunks(per_string)) {
            let mut r = ms.to_vec();
            fill_gaps(&mut r);
            for (e, r) in es.iter().zip(r) {
                let old = table.get(THERMAL_FREE_ROW, e.kind, e.string, e.semitone);
                table.set(THERMAL_FREE_ROW, e.kind, e.string, e.semitone, old + r);
            }
        }
        measured = pluck_all(&table)?;
    }
    // Drop the corrections that leave a note further from its pitch than none does.
    let mut dropped = 0;
    for ((e, now), before) in entries.iter().zip(measured.iter_mut()).zip(&untuned) {
        if !(now.abs() <= before.abs()) {
            table.set(THERMAL_FREE_ROW, e.kind, e.string, e.semitone, 0.0);
            *now = *before;
            dropped += 1;
        }
    }
    let _ = writeln!(
        report,
        "{dropped} of {} corrections dropped (the note rang further from its pitch with it)",
        entries.len()
    );
    for &kind in kinds {
        let ((n, of), (before, _)) = (within(kind, &measured), within(kind, &untuned));
        let _ = writeln!(
            report,
            "the table: {kind:?}: {n} of {of} notes ring within 5 cents ({before} with no correction)"
        );
    }
    Ok((table, report))
}

/// `colophony bench intonation --out FILE [--rates HZ] [--models ..] [--instruments ..]`:
/// fits the table at the first rate given (48 kHz by default) and writes it, with a
/// header, to `out`.
pub fn run(
    out: &Path,
    models: &[Model],
    kinds: &[InstrumentKind],
    rate_hz: f64,
    passes: usize,
    dynamics: bool,
    expressions: &[f64],
    free: bool,
) -> Result<String, String> {
    if free {
        // The shipped table with the fitted instruments' free-ring rows.
        let (table, report) = fit_free(kinds, rate_hz, passes)?;
        return write_table(out, &table, rate_hz).map(|done| format!("{report}{done}"));
    }
    let (table, report) = fit(models, kinds, rate_hz, passes, dynamics, expressions)?;
    // Models and instruments not fitted keep the shipped entries (and, without
    // `dynamics`, their soft ones).
    let mut merged = colophony::dsp::intonation::shipped().clone();
    for &model in models {
        let row = model.row();
        for &kind in kinds {
            for string in 0..STRINGS {
                for s in 0..=MAX_STOP_SEMITONES as usize {
                    if !dynamics {
                        merged.set(row, kind, string, s, table.get(row, kind, string, s));
                        continue;
                    }
                    for level in 0..SOFT_EXPRESSIONS.len() {
                        let c = table.get_soft(row, kind, string, s, level);
                        merged.set_soft(row, kind, string, s, level, c);
                    }
                }
            }
        }
    }
    write_table(out, &merged, rate_hz).map(|done| format!("{report}{done}"))
}

/// Writes `table` to `out` with the file's header.
fn write_table(out: &Path, table: &IntonationTable, rate_hz: f64) -> Result<String, String> {
    let text = format!(
        "# Intonation by the bowed sound (src/dsp/intonation.rs): cents each stopped note is moved\n\
         # from its equal-tempered free-decay pitch so that it sounds in tune bowed at the defaults.\n\
         # Measured by `colophony bench intonation` at a host rate of {rate_hz} Hz (the point\n\
         # strings run at {internal} Hz inside, the violin's and viola's strings and the cello's A\n\
         # string at twice that; the passes: docs/playing-space.md, docs/articulations.md). Rows\n\
         # with an expression below 1 hold the correction at that dynamics level (the Dynamics\n\
         # Guard's bow there), for the point laws (`--dynamics`). The rows named thermal-free\n\
         # move paper B's thermal strings' plucked and struck notes so that they ring at equal\n\
         # temperament (`--free`).\n{}",
        table.to_csv(),
        internal = colophony::dsp::vocabulary::INTERNAL_RATE_HZ,
    );
    std::fs::write(out, text).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    Ok(format!("wrote {}", out.display()))
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
    fn a_note_in_helmholtz_motion_is_trusted_first_another_regime_near_its_pitch_next() {
        assert_eq!(residual(5.0, true), (5.0, true));
        assert_eq!(residual(-7.0, false), (-7.0, false));
        let (c, h) = residual(1200.0, false);
        assert!(c.is_nan() && !h);
        let (c, h) = residual(80.0, true);
        assert!(c.is_nan() && !h);
    }

    #[test]
    fn trusted_first_means_helmholtz_motion_near_the_pitch() {
        assert_eq!(trusted(5.0, true), Some(5.0));
        assert_eq!(trusted(80.0, true), None);
        assert_eq!(trusted(1.0, false), None);
        assert_eq!(trusted(f64::NAN, true), None);
    }
}
