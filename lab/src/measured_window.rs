//! The window each model plays, measured (`colophony bench window --out FILE`; the
//! shipped one is `assets/measured-window.csv`, read by
//! [`colophony::measure::window::measured`]).
//!
//! **Method.** For every model, instrument, open string and beta of
//! [`MEASURED_BETAS`] (the map's grid, 0.1 and 0.15), the string is bowed at 0.1 m/s (slower where `F_max / 2` would pass
//! the plugin's 10 N, as the map bows) and held in Helmholtz motion at `F_max / 2`
//! ([`Attack::Hold`]: up to [`HOLD_MAX_S`] for the motion to form), then the force moves
//! geometrically over [`HOLD_MOVE_S`] to each share of Schelleng's `F_max` in [`SHARES`],
//! and the probe is read from [`HOLD_SETTLE_S`] to the cell's end. A force **holds** the
//! motion ([`holds`]) when the editor's classifier calls it one slip a period, the string
//! sticks at the bow (within [`STICK_TOLERANCE`]) and it slips for at least
//! `1 - SLIP_FRACTION_TOLERANCE` of beta: longer slips are Cremer's corner rounding,
//! which grows toward the lower edge; a shorter one is the point-bow string's short pulse
//! (docs/playing-space.md), not Helmholtz motion.
//!
//! **The window** of a (model, string, beta) is the run of consecutive shares that hold
//! the motion and contain `F_max / 2` (or, where `F_max / 2` itself does not, the longest
//! run): its lowest and highest share. The true edges lie between those and the next
//! shares out. Where no share holds, the window is not found. Schelleng's limits scale
//! with the bow speed, so the shares do too: the window at another speed is the same
//! shares of that speed's `F_max`.

use crate::playing_space::{
    measure_cells, regime_name, Attack, Bowing, Cell, Measured, Model, HOLD_SETTLE_S,
    SLIP_FRACTION_TOLERANCE, STICK_TOLERANCE,
};
#[cfg(doc)]
use crate::playing_space::{HOLD_MAX_S, HOLD_MOVE_S};
use colophony::dsp::vocabulary::{InstrumentKind, STRINGS};
use colophony::measure::regime::Regime;
use colophony::measure::window::{
    MeasuredWindows, SchellengWindow, MEASURED_BETAS, MEASURED_WINDOW_HEADER,
};
use std::fmt::Write as _;
use std::path::Path;

/// The forces tried, as shares of Schelleng's `F_max`: from about `F_min` (at beta 0.05
/// with `Q1` 500 `F_min` is `F_max / 64`; at 0.18, `F_max / 229`) to above `F_max`.
pub const SHARES: [f64; 10] = [
    1.0 / 128.0,
    1.0 / 64.0,
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    0.25,
    0.5,
    0.7,
    1.0,
    1.4,
];

/// The share the motion is caught at and from which the window is grown.
const CATCH_SHARE: usize = 6;

/// Seconds a cell lasts: half a second measured after [`HOLD_SETTLE_S`].
pub const SECONDS: f64 = HOLD_SETTLE_S + 0.5;

/// The host rate the window is measured at, Hz (every host rate plays the same internal
/// strings: docs/models.md).
pub const RATE_HZ: f64 = 48_000.0;

/// One (model, instrument, string, beta): the cells of [`SHARES`] in order, on the open
/// string.
fn cells_of(model: Model, kind: InstrumentKind, string: usize, beta: f64) -> Vec<Cell> {
    note_cells(model, kind, string, kind.open_notes()[string], beta)
}

/// The cells of [`SHARES`] in order for `note` played on `string` (a stopped note where
/// it lies above the open string).
pub fn note_cells(
    model: Model,
    kind: InstrumentKind,
    string: usize,
    note: u8,
    beta: f64,
) -> Vec<Cell> {
    SHARES
        .iter()
        .map(|&share| {
            let mut cell = Cell::on_string(
                model,
                kind,
                note,
                Some(string),
                RATE_HZ,
                Bowing::OfMax(beta, share),
                SECONDS,
            );
            cell.attack = Attack::Hold;
            cell
        })
        .collect()
}

/// Whether a cell's force held the motion (see the module doc).
pub fn holds(cell: &Cell, m: &Measured) -> bool {
    let beta = cell.bow.position_beta;
    let v_b = cell.bow.velocity_m_per_s;
    m.regime == Some(Regime::Helmholtz)
        && (m.stick_velocity_m_per_s - v_b).abs() <= STICK_TOLERANCE * v_b.abs()
        && m.slip_fraction >= (1.0 - SLIP_FRACTION_TOLERANCE) * beta
}

/// The window from which shares hold (see the module doc): indices into [`SHARES`] of its
/// lowest and highest, `None` where none holds.
pub fn window_of(held: &[bool]) -> Option<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (i, &h) in held.iter().enumerate() {
        match runs.last_mut() {
            Some(run) if h && run.1 + 1 == i => run.1 = i,
            _ if h => runs.push((i, i)),
            _ => {}
        }
    }
    let distance = |r: &(usize, usize)| r.0.abs_diff(CATCH_SHARE).min(r.1.abs_diff(CATCH_SHARE));
    runs.iter()
        .find(|r| (r.0..=r.1).contains(&CATCH_SHARE))
        .or_else(|| {
            runs.iter().max_by(|a, b| {
                (a.1 - a.0)
                    .cmp(&(b.1 - b.0))
                    // Equal lengths: the one nearer the catching share.
                    .then(distance(b).cmp(&distance(a)))
            })
        })
        .copied()
}

/// One measured row.
#[derive(Debug, Clone)]
pub struct Row {
    pub model: Model,
    pub kind: InstrumentKind,
    pub string: usize,
    pub beta: f64,
    /// Whether each share of [`SHARES`] held the motion, and what the classifier read.
    pub held: Vec<bool>,
    pub regimes: Vec<String>,
}

impl Row {
    /// The window's lowest and highest share of `F_max`.
    pub fn shares(&self) -> Option<(f64, f64)> {
        window_of(&self.held).map(|(lo, hi)| (SHARES[lo], SHARES[hi]))
    }
}

/// A row's key: model, instrument, string (0 = the lowest), beta.
pub type Key = (Model, InstrumentKind, usize, f64);

/// Measures every row of `models` x `kinds` (rayon; a progress bar on standard error when
/// `progress` is set).
pub fn run_rows(
    models: &[Model],
    kinds: &[InstrumentKind],
    progress: bool,
) -> Result<Vec<Row>, String> {
    let mut keys = Vec::new();
    for &model in models {
        for &kind in kinds {
            for string in 0..STRINGS {
                for beta in MEASURED_BETAS {
                    keys.push((model, kind, string, beta));
                }
            }
        }
    }
    run_keys(&keys, progress)
}

/// Measures the rows `keys` (rayon; a progress bar on standard error when `progress` is
/// set).
pub fn run_keys(keys: &[Key], progress: bool) -> Result<Vec<Row>, String> {
    let cells: Vec<Cell> = keys
        .iter()
        .flat_map(|&(m, k, s, b)| cells_of(m, k, s, b))
        .collect();
    Ok(keys
        .iter()
        .zip(measure_rows(&cells, progress)?)
        .map(|(&(model, kind, string, beta), (held, regimes))| Row {
            model,
            kind,
            string,
            beta,
            held,
            regimes,
        })
        .collect())
}

/// Measures `cells`, [`SHARES`] a row in order: each row's verdicts ([`holds`]) and what
/// the classifier read.
fn measure_rows(cells: &[Cell], progress: bool) -> Result<Vec<(Vec<bool>, Vec<String>)>, String> {
    let measured = measure_cells(cells, progress)?;
    Ok(cells
        .chunks(SHARES.len())
        .zip(measured.chunks(SHARES.len()))
        .map(|(cells, measured)| {
            (
                cells
                    .iter()
                    .zip(measured)
                    .map(|(c, m)| holds(c, m))
                    .collect(),
                measured.iter().map(|m| regime_name(m.regime)).collect(),
            )
        })
        .collect())
}

/// A row's window and verdicts as the files write them: the lowest and highest held
/// share (empty where none), and `1` held, `0` not, a share.
fn window_fields(shares: Option<(f64, f64)>, held: &[bool]) -> (String, String, String) {
    let (lo, hi) = shares.map_or((String::new(), String::new()), |(lo, hi)| {
        (format!("{lo}"), format!("{hi}"))
    });
    (
        lo,
        hi,
        held.iter().map(|&h| if h { '1' } else { '0' }).collect(),
    )
}

/// The shipped file's text: the header, then one line a row (the window's lowest and
/// highest share, empty where not found; then what each share did, `1` held and `0` not,
/// for the record).
pub fn csv(rows: &[Row]) -> String {
    let mut s = format!("{MEASURED_WINDOW_HEADER}\n");
    for r in rows {
        let (lo, hi, held) = window_fields(r.shares(), &r.held);
        let _ = writeln!(
            s,
            "{},{},{},{},{lo},{hi},{held},{}",
            r.model.name(),
            r.kind.name(),
            r.string,
            r.beta,
            r.regimes.join(" ")
        );
    }
    s
}

/// The summary: per model, how many rows found a window, and the median of their highest
/// and lowest shares, per beta.
pub fn summary(rows: &[Row]) -> String {
    let mut s = String::from(
        "| model | beta | windows found | highest share of F_max: median, range | lowest share: median, range |\n|---|---|---|---|---|\n",
    );
    let mut models: Vec<Model> = rows.iter().map(|r| r.model).collect();
    models.dedup();
    for model in models {
        for beta in MEASURED_BETAS {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.model == model && r.beta == beta)
                .collect();
            let found: Vec<(f64, f64)> = of.iter().filter_map(|r| r.shares()).collect();
            let stat = |mut v: Vec<f64>| -> String {
                if v.is_empty() {
                    return "-".into();
                }
                v.sort_by(f64::total_cmp);
                format!("{:.3}, {:.3}-{:.3}", v[v.len() / 2], v[0], v[v.len() - 1])
            };
            let _ = writeln!(
                s,
                "| {} | {beta} | {} of {} | {} | {} |",
                model.name(),
                found.len(),
                of.len(),
                stat(found.iter().map(|w| w.1).collect()),
                stat(found.iter().map(|w| w.0).collect()),
            );
        }
    }
    s
}

/// Writes `text` to `out`, making its folder where it is missing.
fn write_file(out: &Path, text: &str) -> Result<(), String> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    std::fs::write(out, text).map_err(|e| format!("cannot write {}: {e}", out.display()))
}

/// `colophony bench window --out FILE`: measures, writes the file and checks that it
/// reads back as the plugin reads it.
pub fn run(out: &Path, models: &[Model], kinds: &[InstrumentKind]) -> Result<String, String> {
    let t = std::time::Instant::now();
    let rows = run_rows(models, kinds, true)?;
    let text = csv(&rows);
    // A whole table must read back as the plugin reads it; a part of one is for study.
    if models.len() == Model::COUNT && kinds.len() == InstrumentKind::COUNT {
        MeasuredWindows::parse(&text)?;
    }
    write_file(out, &text)?;
    let png = out.with_extension("png");
    draw(&text, &png)?;
    Ok(format!(
        "{} rows ({} cells) in {:.0} s\n\n{}\nwrote {} and {}",
        rows.len(),
        rows.len() * SHARES.len(),
        t.elapsed().as_secs_f64(),
        summary(&rows),
        out.display(),
        png.display()
    ))
}

/// The measured window as a PNG (`out`) from the file's text: a panel per model, the
/// shares of `F_max` down (1.4 at the top), each string's six bow positions across,
/// grouped by instrument and string; a cell green where the share held the motion, pale
/// green where the classifier read one slip a period that did not count (the short
/// pulse, or the string not sticking at the bow), blue for multiple slips, red raucous,
/// grey sliding.
pub fn draw(text: &str, out: &Path) -> Result<(), String> {
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    const CELL_W: i32 = 9;
    const CELL_H: i32 = 11;
    const GAP: i32 = 5;
    const LABEL_W: i32 = 70;
    const HEADER_H: i32 = 34;
    const LEGEND_H: i32 = 36;
    crate::figures::fonts();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut lines = text.lines();
    if lines.next().map(str::trim) != Some(MEASURED_WINDOW_HEADER) {
        return Err(format!(
            "the measured window must begin with '{MEASURED_WINDOW_HEADER}'"
        ));
    }
    // (model, instrument, string, beta) -> (held, regimes)
    let rows: Vec<Vec<&str>> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').collect())
        .filter(|f: &Vec<&str>| f.len() == 8)
        .collect();
    let group_w = MEASURED_BETAS.len() as i32 * CELL_W + GAP;
    let groups = (InstrumentKind::COUNT * STRINGS) as i32;
    let panel_h = HEADER_H + SHARES.len() as i32 * CELL_H + 6;
    let width = (LABEL_W + groups * group_w + 10) as u32;
    let height = (LEGEND_H + Model::COUNT as i32 * panel_h + 10) as u32;
    let root = BitMapBackend::new(out, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let font = |size: i32| ("sans-serif", size).into_font().color(&BLACK);
    for (i, line) in [
        "Colophony, the measured window: held in Helmholtz motion at F_max/2, then moved to each share of F_max (down); each string's beta 0.05-0.18 across",
        "green held; pale green one slip a period not counted (short slip, or not sticking at the bow); blue multiple slips; red raucous; grey sliding",
    ]
    .iter()
    .enumerate()
    {
        root.draw(&Text::new(line.to_string(), (6, 4 + 14 * i as i32), font(12)))
            .map_err(|e| err(&e))?;
    }
    for (p, model) in Model::ALL.iter().enumerate() {
        let y0 = LEGEND_H + p as i32 * panel_h;
        root.draw(&Text::new(model.name().to_string(), (6, y0 + 2), font(13)))
            .map_err(|e| err(&e))?;
        for (row, share) in SHARES.iter().enumerate().rev() {
            let y = y0 + HEADER_H + (SHARES.len() - 1 - row) as i32 * CELL_H;
            let label = if *share >= 0.25 {
                format!("{share}")
            } else {
                format!("1/{}", (1.0 / share).round())
            };
            root.draw(&Text::new(
                label,
                (LABEL_W - 4, y + CELL_H / 2),
                font(9).pos(Pos::new(HPos::Right, VPos::Center)),
            ))
            .map_err(|e| err(&e))?;
        }
        for (k, kind) in InstrumentKind::ALL.iter().enumerate() {
            for string in 0..STRINGS {
                let g = (k * STRINGS + string) as i32;
                let x0 = LABEL_W + g * group_w;
                let abbrev = match kind {
                    InstrumentKind::Violin => "vn",
                    InstrumentKind::Viola => "va",
                    InstrumentKind::Cello => "vc",
                    InstrumentKind::DoubleBass => "db",
                };
                root.draw(&Text::new(
                    format!(
                        "{abbrev} {}",
                        crate::playing_space::figure::note_name(kind.open_notes()[string])
                    ),
                    (x0 + group_w / 2, y0 + HEADER_H - 3),
                    font(9).pos(Pos::new(HPos::Center, VPos::Bottom)),
                ))
                .map_err(|e| err(&e))?;
                for (b, beta) in MEASURED_BETAS.iter().enumerate() {
                    let key = [
                        model.name().to_string(),
                        kind.name().to_string(),
                        string.to_string(),
                        beta.to_string(),
                    ];
                    let Some(f) = rows.iter().find(|f| (0..4).all(|i| f[i] == key[i])) else {
                        continue;
                    };
                    let (held, regimes): (Vec<char>, Vec<&str>) =
                        (f[6].chars().collect(), f[7].split(' ').collect());
                    for row in 0..SHARES.len().min(held.len()).min(regimes.len()) {
                        use crate::playing_space::figure as palette;
                        let colour = match (held[row], regimes[row]) {
                            ('1', _) => palette::HELMHOLTZ,
                            (_, "helmholtz") => palette::ONE_SLIP,
                            (_, "raucous") => palette::RAUCOUS,
                            (_, "sliding") => palette::SLIDING,
                            (_, r) if r.starts_with("slips") => palette::MULTIPLE,
                            _ => palette::SILENT,
                        };
                        let x = x0 + b as i32 * CELL_W;
                        let y = y0 + HEADER_H + (SHARES.len() - 1 - row) as i32 * CELL_H;
                        root.draw(&Rectangle::new(
                            [(x, y), (x + CELL_W - 1, y + CELL_H - 1)],
                            colour.filled(),
                        ))
                        .map_err(|e| err(&e))?;
                    }
                }
            }
        }
    }
    root.present().map_err(|e| err(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_is_the_run_of_held_shares_through_the_catching_force() {
        let h = |s: &str| s.chars().map(|c| c == '1').collect::<Vec<bool>>();
        // The run through F_max / 2 (index 6), though a longer one lies below it.
        assert_eq!(window_of(&h("1111011100")), Some((5, 7)));
        assert_eq!(window_of(&h("0011111100")), Some((2, 7)));
        assert_eq!(window_of(&h("1110001100")), Some((6, 7)));
        // F_max / 2 does not hold: the longest run, and of equal ones the nearer.
        assert_eq!(window_of(&h("1111000111")), Some((0, 3)));
        assert_eq!(window_of(&h("1110000000")), Some((0, 2)));
        assert_eq!(window_of(&h("0110000110")), Some((7, 8)));
        assert_eq!(window_of(&h("0000000000")), None);
    }
}

/// The dynamics levels (CC11, 0-127) the window at the Dynamics Guard's bows is measured
/// at (127, full expression, is the parameters' own bow).
pub const GUARD_LEVELS: [u8; 6] = [0, 21, 42, 64, 85, 106];

/// The first line of the guard's window's file.
pub const GUARD_WINDOW_HEADER: &str =
    "model,instrument,string,level,velocity,beta,low,high,held,regimes";

/// The cells of [`SHARES`] at the Dynamics Guard's bow for CC11 `level` on `string`'s
/// open note: the speed and the drift from the bridge the guard plays there (the
/// parameters' defaults), the force a share of Schelleng's `F_max` at that speed and
/// position, held as [`note_cells`] hold theirs.
pub fn guard_cells(model: Model, kind: InstrumentKind, string: usize, level: u8) -> Vec<Cell> {
    let guard = guard_cell(model, kind, string, level);
    let (v, beta) = (guard.bow.velocity_m_per_s, guard.bow.position_beta);
    speed_cells(model, kind, string, beta, v)
        .into_iter()
        .map(|cell| Cell {
            expression: guard.expression,
            ..cell
        })
        .collect()
}

/// `string`'s open note bowed as the Dynamics Guard bows it at CC11 `level` (the
/// parameters' defaults, String Weight on: [`Cell::at_expression`]).
pub fn guard_cell(model: Model, kind: InstrumentKind, string: usize, level: u8) -> Cell {
    Cell::on_string(
        model,
        kind,
        kind.open_notes()[string],
        Some(string),
        RATE_HZ,
        Bowing::Defaults,
        SECONDS,
    )
    .at_expression(level as f64 / 127.0)
}

/// [`note_cells`] on `string`'s open note at `beta` with the bow at `speed_m_per_s`
/// instead of the window's 0.1 m/s: each force the same share of `F_max` at that speed.
pub fn speed_cells(
    model: Model,
    kind: InstrumentKind,
    string: usize,
    beta: f64,
    speed_m_per_s: f64,
) -> Vec<Cell> {
    note_cells(model, kind, string, kind.open_notes()[string], beta)
        .into_iter()
        .map(|mut cell| {
            let k = speed_m_per_s / cell.bow.velocity_m_per_s;
            cell.bow.velocity_m_per_s = speed_m_per_s;
            cell.bow.force_n *= k;
            cell.f_max_n *= k;
            cell.f_min_n *= k;
            cell
        })
        .collect()
}

/// The guard's bow's share of Schelleng's `F_max` (the model's coefficients) at CC11
/// `level` on `string` ([`guard_cell`]; its force is the string's own, weighted).
pub fn guard_share(model: Model, kind: InstrumentKind, string: usize, level: u8) -> f64 {
    let bow = guard_cell(model, kind, string, level).bow;
    let window = SchellengWindow::for_model(
        kind,
        string,
        bow.position_beta,
        model == Model::Thermal,
        false,
    );
    bow.force_n / window.max_force_n(bow.velocity_m_per_s)
}

/// One row of the guard's window: a (model, instrument, string, level) and what each
/// share of [`SHARES`] did at the guard's speed and position there.
#[derive(Debug, Clone)]
pub struct GuardRow {
    pub model: Model,
    pub kind: InstrumentKind,
    pub string: usize,
    pub level: u8,
    pub velocity_m_per_s: f64,
    pub beta: f64,
    pub held: Vec<bool>,
    pub regimes: Vec<String>,
}

impl GuardRow {
    /// The window's lowest and highest share of `F_max`.
    pub fn shares(&self) -> Option<(f64, f64)> {
        window_of(&self.held).map(|(lo, hi)| (SHARES[lo], SHARES[hi]))
    }
}

/// Measures the guard's window for every (model, instrument, string) of `models` x
/// `kinds` at every level of [`GUARD_LEVELS`] (rayon; a progress bar when `progress`).
pub fn run_guard_rows(
    models: &[Model],
    kinds: &[InstrumentKind],
    progress: bool,
) -> Result<Vec<GuardRow>, String> {
    let mut keys = Vec::new();
    for &model in models {
        for &kind in kinds {
            for string in 0..STRINGS {
                for level in GUARD_LEVELS {
                    keys.push((model, kind, string, level));
                }
            }
        }
    }
    let cells: Vec<Cell> = keys
        .iter()
        .flat_map(|&(m, k, s, l)| guard_cells(m, k, s, l))
        .collect();
    Ok(keys
        .iter()
        .zip(cells.chunks(SHARES.len()))
        .zip(measure_rows(&cells, progress)?)
        .map(
            |((&(model, kind, string, level), row), (held, regimes))| GuardRow {
                model,
                kind,
                string,
                level,
                velocity_m_per_s: row[0].bow.velocity_m_per_s,
                beta: row[0].bow.position_beta,
                held,
                regimes,
            },
        )
        .collect())
}

/// The guard's window file's text (as [`csv`], with the level, speed and position).
pub fn guard_csv(rows: &[GuardRow]) -> String {
    let mut s = format!("{GUARD_WINDOW_HEADER}\n");
    for r in rows {
        let (lo, hi, held) = window_fields(r.shares(), &r.held);
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{lo},{hi},{held},{}",
            r.model.name(),
            r.kind.name(),
            r.string,
            r.level,
            r.velocity_m_per_s,
            r.beta,
            r.regimes.join(" ")
        );
    }
    s
}

/// `colophony bench guard-window --out FILE` (docs/playing-space/guard-window.csv):
/// measures the window at the Dynamics Guard's own bows and writes the file, with a
/// count of where the guard puts its bow against it (docs/testing.md, "Dynamics").
pub fn run_guard(out: &Path, models: &[Model], kinds: &[InstrumentKind]) -> Result<String, String> {
    let t = std::time::Instant::now();
    let rows = run_guard_rows(models, kinds, true)?;
    write_file(out, &guard_csv(&rows))?;
    let mut report = format!(
        "{} rows ({} cells) in {:.0} s\n\n| model | guard bows inside | above | below | no window |\n|---|---|---|---|---|\n",
        rows.len(),
        rows.len() * SHARES.len(),
        t.elapsed().as_secs_f64()
    );
    for &model in models {
        let (mut inside, mut above, mut below, mut none) = (0, 0, 0, 0);
        for r in rows.iter().filter(|r| r.model == model) {
            let share = guard_share(model, r.kind, r.string, r.level);
            match r.shares() {
                None => none += 1,
                Some((_, hi)) if share > hi => above += 1,
                Some((lo, _)) if share < lo => below += 1,
                Some(_) => inside += 1,
            }
        }
        let _ = writeln!(
            report,
            "| {} | {inside} | {above} | {below} | {none} |",
            model.name()
        );
    }
    let _ = write!(report, "\nwrote {}", out.display());
    Ok(report)
}
