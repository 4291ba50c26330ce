//! The playing-space map as a PNG, one per model: a panel per host rate and instrument,
//! notes across, bowings down (the defaults, the window's middle, then each beta of the
//! grid at `2 F_min`, the middle and `F_max / 2`), each cell coloured by the regime the
//! probe showed, with the bowed pitch in cents printed where the motion is Helmholtz.

use super::{notes, Cell, Measured, Model, Plan};
use colophony::measure::regime::Regime;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

const CELL_W: i32 = 30;
const CELL_H: i32 = 16;
const LABEL_W: i32 = 120;
const HEADER_H: i32 = 34;
const LEGEND_H: i32 = 48;

/// Colour of a cell: green Helmholtz (pale where the classifier says one slip per period
/// but the slip fraction or the sticking velocity misses), blue multiple slips, red
/// raucous, grey sliding, dark silent, white refused.
fn colour(m: &Measured) -> RGBColor {
    match m.regime {
        Some(Regime::Helmholtz) if m.helmholtz => HELMHOLTZ,
        Some(Regime::Helmholtz) => ONE_SLIP,
        Some(Regime::MultipleSlips(_)) => MULTIPLE,
        Some(Regime::Raucous) => RAUCOUS,
        Some(Regime::Sliding) => SLIDING,
        Some(Regime::Silent) => SILENT,
        None => WHITE,
    }
}

/// The maps' palette (shared with the measured window's figure).
pub(crate) const HELMHOLTZ: RGBColor = RGBColor(90, 190, 90);
pub(crate) const ONE_SLIP: RGBColor = RGBColor(200, 230, 140);
pub(crate) const MULTIPLE: RGBColor = RGBColor(110, 150, 230);
pub(crate) const RAUCOUS: RGBColor = RGBColor(230, 100, 90);
pub(crate) const SLIDING: RGBColor = RGBColor(170, 170, 170);
pub(crate) const SILENT: RGBColor = RGBColor(60, 60, 60);

/// A MIDI note's name, C4 = 60.
pub(crate) fn note_name(note: u8) -> String {
    const NAMES: [&str; 12] = [
        "C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B",
    ];
    format!("{}{}", NAMES[note as usize % 12], note as i32 / 12 - 1)
}

/// Draws `model`'s map to `out`.
pub fn draw(
    plan: &Plan,
    results: &[(Cell, Measured)],
    model: Model,
    out: &Path,
) -> Result<(), String> {
    crate::figures::fonts();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let columns = plan
        .kinds
        .iter()
        .map(|k| notes(*k, plan.note_step).len())
        .max()
        .unwrap_or(1) as i32;
    let rows = plan.bowings.len() as i32;
    let panel_h = HEADER_H + rows * CELL_H + 8;
    let panels = (plan.kinds.len() * plan.rates_hz.len()) as i32;
    let width = (LABEL_W + columns * CELL_W + 10) as u32;
    let height = (LEGEND_H + panels * panel_h + 10) as u32;
    let root = BitMapBackend::new(out, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let text = |size: i32| ("sans-serif", size).into_font().color(&BLACK);
    let legend = [
        match plan.attack {
            super::Attack::Landing => {
                format!("Colophony playing space: {} (the bow lands at each force)", model.name())
            }
            super::Attack::Catch => format!(
                "Colophony playing space: {} (caught at F_max/2, then held at each force)",
                model.name()
            ),
            super::Attack::Hold => format!(
                "Colophony playing space: {} (held at F_max/2 until caught, then moved to each force)",
                model.name()
            ),
            super::Attack::Performer => format!(
                "Colophony playing space: {} (the performer's attack, velocity {})",
                model.name(),
                super::PERFORMER_VELOCITY
            ),
        },
        "green Helmholtz (bowed pitch in cents from equal temperament); pale green one slip but".into(),
        "slip fraction or sticking off; blue multiple slips; red raucous; grey sliding; dark silent".into(),
    ];
    for (i, line) in legend.iter().enumerate() {
        root.draw(&Text::new(line.clone(), (6, 4 + 14 * i as i32), text(12)))
            .map_err(|e| err(&e))?;
    }
    let mut y0 = LEGEND_H;
    for &rate in &plan.rates_hz {
        for &kind in &plan.kinds {
            let kind_notes = notes(kind, plan.note_step);
            root.draw(&Text::new(
                format!("{} at {} kHz", kind.name(), rate / 1000.0),
                (6, y0 + 2),
                text(13),
            ))
            .map_err(|e| err(&e))?;
            for (col, note) in kind_notes.iter().enumerate() {
                let x = LABEL_W + col as i32 * CELL_W;
                root.draw(&Text::new(
                    note_name(*note),
                    (x + CELL_W / 2, y0 + HEADER_H - 4),
                    text(10).pos(Pos::new(HPos::Center, VPos::Bottom)),
                ))
                .map_err(|e| err(&e))?;
            }
            for (row, bowing) in plan.bowings.iter().enumerate() {
                let y = y0 + HEADER_H + row as i32 * CELL_H;
                root.draw(&Text::new(
                    bowing.label(),
                    (6, y + CELL_H / 2),
                    text(11).pos(Pos::new(HPos::Left, VPos::Center)),
                ))
                .map_err(|e| err(&e))?;
                for (col, note) in kind_notes.iter().enumerate() {
                    let x = LABEL_W + col as i32 * CELL_W;
                    let Some((_, m)) = results.iter().find(|(c, _)| {
                        c.model == model
                            && c.rate_hz == rate
                            && c.kind == kind
                            && c.note == *note
                            && c.bowing == *bowing
                    }) else {
                        continue;
                    };
                    root.draw(&Rectangle::new(
                        [(x, y), (x + CELL_W - 1, y + CELL_H - 1)],
                        colour(m).filled(),
                    ))
                    .map_err(|e| err(&e))?;
                    if m.helmholtz {
                        root.draw(&Text::new(
                            format!("{:+.0}", m.cents),
                            (x + CELL_W / 2, y + CELL_H / 2),
                            text(10).pos(Pos::new(HPos::Center, VPos::Center)),
                        ))
                        .map_err(|e| err(&e))?;
                    }
                }
            }
            y0 += panel_h;
        }
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
