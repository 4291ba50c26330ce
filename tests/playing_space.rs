//! The playing-space map's coarse subset (issue 16, item 6): every model, every instrument,
//! every fifth semitone from the lowest open string to two octaves above the highest, at
//! 44.1 and 96 kHz, through the engines the plugin plays (`colophony::playing_space`).

use colophony::dsp::instrument::InstrumentKind;
use colophony::editor::regime::Regime;
use colophony::playing_space::{
    measure, notes, regime_name, run_plan, Bowing, Cell, Measured, Model, Plan,
};
use rayon::prelude::*;

const RATES: [f64; 2] = [44_100.0, 96_000.0];

fn coarse_cells(bowing: Bowing, seconds: f64, force: impl Fn(&Cell) -> f64) -> Vec<Cell> {
    let mut cells = Vec::new();
    for model in Model::ALL {
        for rate in RATES {
            for kind in InstrumentKind::ALL {
                for note in notes(kind, 5) {
                    let mut cell = Cell::new(model, kind, note, rate, bowing, seconds);
                    cell.bow.force_n = force(&cell);
                    cells.push(cell);
                }
            }
        }
    }
    cells
}

fn measure_all(cells: &[Cell]) -> Vec<(Cell, Measured)> {
    cells
        .par_iter()
        .map(|c| (*c, measure(c).expect("every cell renders")))
        .collect()
}

/// Renders `cells` and fails, listing them, on any that the classifier calls Helmholtz
/// motion.
fn assert_never_helmholtz(cells: &[Cell]) {
    let results = measure_all(cells);
    let wrong: Vec<String> = results
        .iter()
        .filter(|(_, m)| m.regime == Some(Regime::Helmholtz) || m.helmholtz)
        .map(|(c, m)| describe(c, m))
        .collect();
    assert!(
        wrong.is_empty(),
        "{} cells:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}

fn describe(c: &Cell, m: &Measured) -> String {
    format!(
        "{} {} note {} at {} Hz, {:.3} N at beta {}: {} (peak {:.2e})",
        c.model.name(),
        c.kind.name(),
        c.note,
        c.rate_hz,
        c.bow.force_n,
        c.bow.position_beta,
        regime_name(m.regime),
        m.peak
    )
}

/// Every note of every model speaks at the plugin's defaults and at the middle of its
/// window, at both rates, with finite output: no note is refused or silent (the thermal
/// model used to drop high notes whose string was shorter than the bow).
#[test]
fn every_note_of_every_model_speaks_at_nominal_bowing() {
    let plan = Plan {
        note_step: 5,
        bowings: vec![Bowing::Defaults, Bowing::Middle],
        rates_hz: RATES.to_vec(),
        seconds: 0.5,
        ..Plan::full()
    };
    let results = run_plan(&plan, false).expect("every cell renders");
    let mut quiet = Vec::new();
    for (c, m) in &results {
        assert!(m.peak.is_finite(), "{}", describe(c, m));
        // A bowed note peaks near 0.1 at the plugin's scale; 1e-3 is 40 dB below it, far
        // above the exact zeros of a refused note.
        if !(m.peak > 1e-3) || matches!(m.regime, None | Some(Regime::Silent)) {
            quiet.push(describe(c, m));
        }
    }
    assert!(
        quiet.is_empty(),
        "{} quiet notes:\n{}",
        quiet.len(),
        quiet.join("\n")
    );
}

/// Far below Schelleng's lower limit (a tenth of `F_min`) no model shows Helmholtz motion:
/// the bow cannot hold the string through a period, as physics says.
#[test]
fn far_below_the_window_no_model_is_in_helmholtz_motion() {
    let cells = coarse_cells(Bowing::Middle, 0.6, |c| 0.1 * c.f_min_n);
    assert_never_helmholtz(&cells);
}

/// Far above Schelleng's upper limit (eight times `F_max`) the static friction laws
/// (hyperbolic, Stribeck) never show Helmholtz motion: the bow drags the string beyond the
/// corner (raucous or multiple slips). Schelleng's `F_max` is derived for exactly such a
/// law: the string sticks while the force stays within `mu_s F_N`. The bristle laws
/// (LuGre, elasto-plastic) hold the string through a compliant bristle rather than up to a
/// hard limit, and the thermal bow's sticking coefficient depends on the contact
/// temperature, so for them `F_max` is an estimate; the map shows where they differ (LuGre
/// stays periodic at 8 `F_max` on the highest notes at 96 kHz: docs/playing-space.md).
#[test]
fn far_above_the_window_the_static_laws_are_never_in_helmholtz_motion() {
    use colophony::dsp::friction::FrictionModel;
    let cells: Vec<Cell> = coarse_cells(Bowing::Middle, 0.6, |c| 8.0 * c.f_max_n)
        .into_iter()
        .filter(|c| {
            matches!(
                c.model,
                Model::Point(FrictionModel::Hyperbolic | FrictionModel::Stribeck)
            )
        })
        .collect();
    assert_never_helmholtz(&cells);
}

/// Issue 16, item 2, on the coarse subset: inside the window every model is in Helmholtz
/// motion within 0.3 s. **Not met yet** (docs/playing-space.md: the point laws reach it in
/// about a fifth of the window's cells, mostly in its upper half; the thermal model almost
/// nowhere), so it is ignored in CI; run it with `cargo test --test playing_space --
/// --ignored` to see the cells that miss.
#[test]
#[ignore]
fn inside_the_window_every_model_is_in_helmholtz_motion() {
    let plan = Plan {
        rates_hz: RATES.to_vec(),
        ..Plan::quick()
    };
    let results = run_plan(&plan, false).expect("every cell renders");
    let wrong: Vec<String> = results
        .iter()
        .filter(|(c, m)| !c.bowing.is_nominal() && !m.helmholtz)
        .map(|(c, m)| describe(c, m))
        .collect();
    assert!(
        wrong.is_empty(),
        "{} of {} cells:\n{}",
        wrong.len(),
        results.len(),
        wrong.join("\n")
    );
}
