//! The shipped measured window (`assets/measured-window.csv`) is what the model plays: a
//! few of its rows measured again must give the same verdict at every force, and every
//! row's window lies where Schelleng's theory puts its bounds.

use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::{InstrumentKind, STRINGS};
use colophony::measure::window::{measured, MEASURED_BETAS};
use colophony_lab::measured_window::{
    guard_cells, holds, note_cells, run_keys, speed_cells, Key, GUARD_WINDOW_HEADER, SHARES,
};
use colophony_lab::playing_space::Model;
use colophony_lab::playing_space::{measure_cells, Cell, Measured};

/// The shipped file's line for a row: its `held` field.
fn shipped_held(model: Model, kind: InstrumentKind, string: usize, beta: f64) -> String {
    let text = include_str!("../../assets/measured-window.csv");
    let key = format!("{},{},{string},{beta},", model.name(), kind.name());
    let line = text
        .lines()
        .find(|l| l.starts_with(&key))
        .unwrap_or_else(|| panic!("no row {key}"));
    line.split(',').nth(6).expect("a held field").to_string()
}

/// The verdicts of `cells[span]` as the file writes them: `1` held, `0` not.
fn verdicts(cells: &[Cell], measured: &[Measured], span: std::ops::Range<usize>) -> String {
    span.map(|i| {
        if holds(&cells[i], &measured[i]) {
            '1'
        } else {
            '0'
        }
    })
    .collect()
}

/// Whether this is the kind of machine the files were measured on: x86-64 with FMA and
/// AVX2. glibc picks its `sin`, `exp` and `pow` variants by those features, and a
/// last-bit difference can flip a chaotic cell (tests/golden.rs): elsewhere one share of
/// each row may differ.
fn same_machine() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::is_x86_feature_detected!("fma") && std::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

/// Whether verdicts measured now agree with a file's, share by share: a verdict for every
/// share, all the same on the machine the file was measured on, one allowed to differ
/// elsewhere ([`same_machine`]).
fn agrees(held: &str, shipped: &str, same_machine: bool) -> bool {
    let differ = held
        .chars()
        .zip(shipped.chars())
        .filter(|(a, b)| a != b)
        .count();
    held.len() == shipped.len() && (differ == 0 || (!same_machine && differ <= 1))
}

#[test]
fn rows_of_the_shipped_window_measured_again_give_the_same_verdicts() {
    // One row of each point law, on four instruments and four strings, at all four
    // positions: the render is deterministic, so a row measured again must match its
    // shipped line share by share; a change to the model that moves the window fails
    // here until `colophony bench window` is run again.
    let rows = [
        (FrictionModel::Hyperbolic, InstrumentKind::Cello, 2, 0.12),
        (FrictionModel::Hyperbolic, InstrumentKind::Violin, 3, 0.05),
        (FrictionModel::Stribeck, InstrumentKind::Viola, 0, 0.18),
        (
            FrictionModel::ElastoPlastic,
            InstrumentKind::DoubleBass,
            1,
            0.08,
        ),
    ];
    let keys: Vec<Key> = rows
        .iter()
        .map(|&(law, kind, string, beta)| (Model::Point(law), kind, string, beta))
        .collect();
    let measured_now = run_keys(&keys, false).expect("the rows measure");
    let same_machine = same_machine();
    if !same_machine {
        eprintln!("not the machine the window was measured on: one share a row may differ");
    }
    for ((law, kind, string, beta), measured_now) in rows.into_iter().zip(measured_now) {
        let model = Model::Point(law);
        let held: String = measured_now
            .held
            .iter()
            .map(|&h| if h { '1' } else { '0' })
            .collect();
        let shipped = shipped_held(model, kind, string, beta);
        assert!(
            agrees(&held, &shipped, same_machine),
            "{} {} string {string} beta {beta}: measured {held} ({:?}), shipped {shipped}",
            law.name(),
            kind.name(),
            measured_now.regimes
        );
    }
}

#[test]
fn rows_of_the_window_at_the_guards_bows_measured_again_give_the_same_verdicts() {
    // docs/playing-space/guard-window.csv (`colophony bench guard-window`) is what the
    // model holds at the Dynamics Guard's own speed and position: two of its rows (the
    // hyperbolic cello's A string at CC11 0, the static law's violin E string at 42)
    // measured again must match share by share, as the shipped window's rows do above.
    let text = include_str!("../../docs/playing-space/guard-window.csv");
    assert_eq!(text.lines().next(), Some(GUARD_WINDOW_HEADER));
    let same_machine = same_machine();
    for (law, kind, string, level) in [
        (FrictionModel::Hyperbolic, InstrumentKind::Cello, 3, 0u8),
        (FrictionModel::Stribeck, InstrumentKind::Violin, 3, 42),
    ] {
        let model = Model::Point(law);
        let cells = guard_cells(model, kind, string, level);
        let measured_now = measure_cells(&cells, false).expect("the row measures");
        let held = verdicts(&cells, &measured_now, 0..cells.len());
        let key = format!("{},{},{string},{level},", model.name(), kind.name());
        let line = text
            .lines()
            .find(|l| l.starts_with(&key))
            .unwrap_or_else(|| panic!("no row {key}"));
        let shipped = line.split(',').nth(8).expect("a held field");
        assert!(
            agrees(&held, shipped, same_machine),
            "{key}: measured {held}, shipped {shipped}"
        );
    }
}

#[test]
fn every_measured_window_lies_between_schellengs_bounds() {
    // Schelleng's F_min (a dashpot bridge's, from the string's own Q1) is at least
    // F_max / 229 on the grid (beta 0.18, Q1 500), so a window reaching below 1/256 of
    // F_max would be the classifier's error; its top may pass F_max by the grid's last
    // share (1.4), where the compliant laws keep their motion (docs/playing-space.md).
    let m = measured();
    let mut found = 0;
    for model in Model::ALL {
        for kind in InstrumentKind::ALL {
            for string in 0..STRINGS {
                for beta in MEASURED_BETAS {
                    if let Some((lo, hi)) = m.shares(model, kind, string, beta) {
                        found += 1;
                        assert!(
                            lo >= 1.0 / 256.0 && lo <= hi && hi <= SHARES[SHARES.len() - 1],
                            "{} {} {string} {beta}: {lo} .. {hi}",
                            model.name(),
                            kind.name()
                        );
                    }
                }
            }
        }
    }
    assert!(found > 0, "no window measured at all");
}

#[test]
#[ignore = "survey: cargo test --release -p colophony-lab --test measured_window stopped -- --ignored --nocapture"]
fn stopped_notes_against_their_open_strings_window() {
    // The shipped window is measured on the open strings and read for every note of a
    // string. Stopped a fifth and an octave up (hyperbolic law, beta 0.08 and 0.12, every
    // string of every instrument), how often does each share's verdict agree with the
    // open string's shipped one?
    let law = Model::Point(FrictionModel::Hyperbolic);
    let mut cells = Vec::new();
    let mut keys = Vec::new();
    for kind in InstrumentKind::ALL {
        for string in 0..STRINGS {
            for up in [7, 12] {
                for beta in [0.08, 0.12] {
                    let note = kind.open_notes()[string] + up;
                    cells.extend(note_cells(law, kind, string, note, beta));
                    keys.push((kind, string, up, beta));
                }
            }
        }
    }
    let measured = measure_cells(&cells, false).expect("the cells measure");
    let (mut agree, mut total) = (0, 0);
    for (k, &(kind, string, up, beta)) in keys.iter().enumerate() {
        let span = k * SHARES.len()..(k + 1) * SHARES.len();
        let held = verdicts(&cells, &measured, span);
        let shipped = shipped_held(law, kind, string, beta);
        let same = held
            .chars()
            .zip(shipped.chars())
            .filter(|(a, b)| a == b)
            .count();
        agree += same;
        total += SHARES.len();
        println!(
            "{} string {string} +{up} beta {beta}: stopped {held}, open {shipped} ({same} of {})",
            kind.name(),
            SHARES.len()
        );
    }
    println!("shares agreeing: {agree} of {total}");
    assert!(total > 0);
}

#[test]
#[ignore = "survey: cargo test --release -p colophony-lab --test measured_window dynamics -- --ignored --nocapture"]
fn the_dynamics_guards_bow_against_the_measured_window() {
    // Where the Dynamics Guard puts each open string's bow (the plugin's defaults at
    // CC11 0 .. 127: speed, force and the drift from the bridge) against the window
    // measured there: the force as a share of F_max at the drifted beta, and whether it
    // lies inside the measured shares. No rendering: the guard's arithmetic and the file.
    use colophony_lab::measured_window::{guard_cell, guard_share};
    let m = measured();
    for model in Model::ALL {
        let (mut inside, mut above, mut below, mut none) = (0, 0, 0, 0);
        for kind in InstrumentKind::ALL {
            for string in 0..STRINGS {
                for cc in [0u8, 21, 42, 64, 85, 106, 127] {
                    let bow = guard_cell(model, kind, string, cc).bow;
                    let share = guard_share(model, kind, string, cc);
                    match m.shares(model, kind, string, bow.position_beta) {
                        None => none += 1,
                        Some((_, hi)) if share > hi => above += 1,
                        Some((lo, _)) if share < lo => below += 1,
                        Some(_) => inside += 1,
                    }
                    if model == Model::Point(FrictionModel::Hyperbolic)
                        && kind == InstrumentKind::Cello
                    {
                        println!(
                            "hyperbolic cello string {string} CC11 {cc}: beta {:.3}, {:.3} F_max, measured {:?}",
                            bow.position_beta,
                            share,
                            m.shares(model, kind, string, bow.position_beta)
                        );
                    }
                }
            }
        }
        println!(
            "{}: of 112 (string, level) bows, {inside} inside the measured window, {above} above it, {below} below, {none} where none was measured",
            model.name()
        );
    }
}

#[test]
#[ignore = "survey: cargo test --release -p colophony-lab --test measured_window torsion -- --ignored --nocapture"]
fn the_held_window_without_torsion_or_the_hair() {
    // Torsion and the bow's hair are admittances beside the string's at the contact: how
    // far does each move the measured window's top? The hyperbolic law on the violin's
    // and cello's strings and the elasto-plastic law on the cello's, beta 0.08, 0.1 and
    // 0.12, with torsion off, the hair off and both off, against the shipped rows.
    let variants = [(false, true), (true, false), (false, false)];
    let mut keys = Vec::new();
    for (law, kinds) in [
        (
            FrictionModel::Hyperbolic,
            &[InstrumentKind::Violin, InstrumentKind::Cello][..],
        ),
        (FrictionModel::ElastoPlastic, &[InstrumentKind::Cello][..]),
    ] {
        for &kind in kinds {
            for string in 0..STRINGS {
                for beta in [0.08, 0.1, 0.12] {
                    keys.push((Model::Point(law), kind, string, beta));
                }
            }
        }
    }
    let mut cells = Vec::new();
    for &(torsion, hair) in &variants {
        for &(model, kind, string, beta) in &keys {
            for mut cell in note_cells(model, kind, string, kind.open_notes()[string], beta) {
                cell.torsion = torsion;
                cell.hair = hair;
                cells.push(cell);
            }
        }
    }
    let measured = measure_cells(&cells, false).expect("the cells measure");
    let top = |held: &str| -> Option<f64> {
        let bits: Vec<bool> = held.chars().map(|c| c == '1').collect();
        colophony_lab::measured_window::window_of(&bits).map(|w| SHARES[w.1])
    };
    for (v, &(torsion, hair)) in variants.iter().enumerate() {
        let (mut higher, mut same, mut lower) = (0, 0, 0);
        for (k, &(model, kind, string, beta)) in keys.iter().enumerate() {
            let base = (v * keys.len() + k) * SHARES.len();
            let held = verdicts(&cells, &measured, base..base + SHARES.len());
            let shipped = shipped_held(model, kind, string, beta);
            let (now, was) = (top(&held), top(&shipped));
            match now.partial_cmp(&was) {
                Some(std::cmp::Ordering::Greater) => higher += 1,
                Some(std::cmp::Ordering::Less) => lower += 1,
                _ => same += 1,
            }
            println!(
                "torsion {torsion} hair {hair}: {} {} string {string} beta {beta}: {held} (top {now:?}) against {shipped} (top {was:?})",
                model.name(),
                kind.name()
            );
        }
        println!(
            "torsion {torsion} hair {hair}: the top share higher in {higher}, the same in {same}, lower in {lower} of {} rows",
            keys.len()
        );
    }
    assert!(!keys.is_empty());
}

#[test]
#[ignore = "survey: cargo test --release -p colophony-lab --test measured_window speeds -- --ignored --nocapture"]
fn the_held_window_at_other_bow_speeds() {
    // Schelleng's limits both scale with the bow's speed, so in shares of F_max his
    // window is the same at every speed; the friction laws have speeds of their own (the
    // hyperbolic v0, the Stribeck v_s, the thermal bow's heating), so the model's need
    // not be. The shipped rows at beta 0.1 (0.1 m/s) against the same rows at 0.01, 0.03
    // and 0.3 m/s (SPEEDS=a,b,.. for others).
    let speeds: Vec<f64> = std::env::var("SPEEDS")
        .ok()
        .and_then(|l| l.split(',').map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![0.01, 0.03, 0.3]);
    let beta = 0.1;
    let mut keys = Vec::new();
    let mut cells = Vec::new();
    for model in Model::ALL {
        for kind in InstrumentKind::ALL {
            for string in 0..STRINGS {
                for &v in &speeds {
                    keys.push((model, kind, string, v));
                    cells.extend(speed_cells(model, kind, string, beta, v));
                }
            }
        }
    }
    let measured_now = measure_cells(&cells, true).expect("the cells measure");
    let m = measured();
    let n = SHARES.len();
    let median = |mut v: Vec<f64>| -> String {
        if v.is_empty() {
            return "-".into();
        }
        v.sort_by(f64::total_cmp);
        format!("{:.3}", v[v.len() / 2])
    };
    println!("| model | speed, m/s | rows as at 0.1 m/s | top higher / lower | no window | median top | median floor |");
    println!("|---|---|---|---|---|---|---|");
    for model in Model::ALL {
        let shipped: Vec<Option<(f64, f64)>> = keys
            .iter()
            .filter(|k| k.0 == model && k.3 == speeds[0])
            .map(|&(_, kind, string, _)| m.shares(model, kind, string, beta))
            .collect();
        println!(
            "| {} | 0.1 (shipped) | - | - | {} | {} | {} |",
            model.name(),
            shipped.iter().filter(|w| w.is_none()).count(),
            median(shipped.iter().flatten().map(|w| w.1).collect()),
            median(shipped.iter().flatten().map(|w| w.0).collect()),
        );
        for &v in &speeds {
            let (mut same, mut higher, mut lower, mut none) = (0, 0, 0, 0);
            let (mut tops, mut floors) = (Vec::new(), Vec::new());
            for (k, &(_, kind, string, _)) in keys
                .iter()
                .enumerate()
                .filter(|(_, k)| k.0 == model && k.3 == v)
            {
                let held: Vec<bool> = (k * n..(k + 1) * n)
                    .map(|i| holds(&cells[i], &measured_now[i]))
                    .collect();
                let window = colophony_lab::measured_window::window_of(&held)
                    .map(|(lo, hi)| (SHARES[lo], SHARES[hi]));
                let shipped = m.shares(model, kind, string, beta);
                match (window, shipped) {
                    (None, _) => none += 1,
                    (Some(w), Some(s)) if w.1 > s.1 => higher += 1,
                    (Some(w), Some(s)) if w.1 < s.1 => lower += 1,
                    _ => {}
                }
                if window == shipped {
                    same += 1;
                }
                if let Some((lo, hi)) = window {
                    tops.push(hi);
                    floors.push(lo);
                }
            }
            println!(
                "| {} | {v} | {same} of 16 | {higher} / {lower} | {none} | {} | {} |",
                model.name(),
                median(tops),
                median(floors)
            );
        }
    }
}

#[test]
#[ignore = "survey: cargo test --release -p colophony-lab --test measured_window guards_bows_against -- --ignored --nocapture"]
fn the_guards_bows_against_the_window_at_their_own_speed() {
    // docs/playing-space/guard-window.csv against where the guard puts its bow (no
    // rendering): inside the held window; above its top but under the next share of the
    // grid, which did not hold (the grid cannot say); or beyond that share (and the same
    // below the floor).
    use colophony_lab::measured_window::guard_share;
    let text = include_str!("../../docs/playing-space/guard-window.csv");
    for model in Model::ALL {
        let (mut inside, mut gap, mut beyond, mut none) = (0, 0, 0, 0);
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            if f[0] != model.name() {
                continue;
            }
            let kind = InstrumentKind::from_name(f[1]).expect("an instrument");
            let string: usize = f[2].parse().expect("a string");
            let level: u8 = f[3].parse().expect("a level");
            let share = guard_share(model, kind, string, level);
            let (Ok(lo), Ok(hi)) = (f[6].parse::<f64>(), f[7].parse::<f64>()) else {
                none += 1;
                continue;
            };
            let at = |x: f64| SHARES.iter().position(|&s| (s - x).abs() < 1e-9);
            let (l, h) = (at(lo).expect("a grid share"), at(hi).expect("a grid share"));
            let next_up = SHARES.get(h + 1).copied().unwrap_or(f64::INFINITY);
            let next_down = if l > 0 { SHARES[l - 1] } else { 0.0 };
            if share >= lo && share <= hi {
                inside += 1;
            } else if share < next_up && share > next_down {
                gap += 1;
            } else {
                beyond += 1;
                println!(
                    "{} {} string {string} CC11 {level}: guard {share:.3} F_max, held {lo}-{hi}",
                    model.name(),
                    kind.name()
                );
            }
        }
        println!(
            "{}: inside {inside}, outside by less than a grid step {gap}, beyond it {beyond}, no window {none}",
            model.name()
        );
    }
}
