//! The work-precision benchmark's quick plan (`colophony bench precision --quick`) on
//! short renders: convergence under refinement where the model converges (thermal node
//! count, Newton tolerance; the waveguide's host rate does not converge, see
//! docs/precision.md, so nothing here claims it does), a deterministic reference, the
//! metric pipeline on signals whose answer is known, and the CSV's shape.

use colophony_lab::precision::{
    compute, csv, errors, measure, Plan, Report, Scenario, Series, ANALYSIS_RATE_HZ, CSV_HEADER,
};
use colophony_lab::render::Rendered;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// The quick plan is computed once and shared by the tests.
fn quick() -> &'static (Plan, Report) {
    static REPORT: OnceLock<(Plan, Report)> = OnceLock::new();
    REPORT.get_or_init(|| {
        let plan = Plan::quick();
        let report = compute(&plan, |_| {}).expect("the quick plan renders");
        (plan, report)
    })
}

#[test]
fn thermal_errors_fall_as_the_node_count_doubles() {
    let (_, report) = quick();
    let series: Vec<_> = report
        .convergence
        .iter()
        .filter(|r| r.series == Series::Nodes)
        .collect();
    // N_B 6, 12 and the N_B 24 reference.
    assert_eq!(series.len(), 3);
    let wave = |k: usize| series[k].errors.waveform_relative.unwrap();
    println!("thermal waveform error {:.2e} -> {:.2e}", wave(0), wave(1));
    assert!(wave(1) < wave(0));
}

#[test]
fn looser_newton_tolerance_never_beats_a_tighter_one() {
    let (_, report) = quick();
    let series: Vec<_> = report
        .convergence
        .iter()
        .filter(|r| r.series == Series::Tolerance && r.scenario.starts_with("cello D3"))
        .collect();
    // 1e-3, 1e-6 and the 1e-13 reference.
    assert_eq!(series.len(), 3);
    let wave = |k: usize| series[k].errors.waveform_relative.unwrap();
    println!("tolerance 1e-3: {:.2e}, 1e-6: {:.2e}", wave(0), wave(1));
    assert!(wave(1) <= wave(0));
}

#[test]
fn a_reference_rendered_twice_has_zero_error() {
    let (plan, _) = quick();
    let group = &plan.groups[0];
    let short = Plan {
        seconds: 0.5,
        timing_runs: 1,
        groups: vec![colophony_lab::precision::Group {
            configs: vec![group.reference.clone()],
            ..group.clone()
        }],
    };
    let report = compute(&short, |_| {}).unwrap();
    // Row 0: the reference rendered as a configuration; row 1: rendered as the reference.
    let e = report.rows[0].errors;
    assert_eq!(e.f0_cents, Some(0.0));
    assert_eq!(e.harmonics_db, Some(0.0));
    assert_eq!(e.slip_fraction, Some(0.0));
    assert_eq!(e.waveform_relative, Some(0.0));
}

fn tone(f_hz: f64, fs: f64, seconds: f64, amplitude: f64) -> Rendered {
    let audio: Vec<f64> = (0..(seconds * fs) as usize)
        .map(|i| {
            let t = i as f64 / fs;
            amplitude * ((2.0 * PI * f_hz * t).sin() + 0.5 * (4.0 * PI * f_hz * t).sin())
        })
        .collect();
    Rendered {
        sample_rate_hz: fs,
        bow_point_velocity_m_per_s: vec![0.0; audio.len()],
        friction_force_n: vec![0.0; audio.len()],
        audio,
        newton: Default::default(),
    }
}

#[test]
fn metrics_read_a_known_detuning_and_gain_from_different_rates() {
    let scenario = Scenario {
        name: "two harmonics",
        nominal_f0_hz: 220.0,
        bow_velocity_m_per_s: 0.1,
    };
    let reference = measure(&tone(220.0, 192_000.0, 1.0, 0.1), &scenario, 0.0).unwrap();
    // 3 cents sharp and 1 dB louder, at 44.1 kHz.
    let sharp = 220.0 * 2f64.powf(3.0 / 1200.0);
    let louder = 0.1 * 10f64.powf(1.0 / 20.0);
    let m = measure(&tone(sharp, 44_100.0, 1.0, louder), &scenario, 0.0).unwrap();
    let e = errors(&m, &reference);
    // Half a second of a clean tone: the peak estimate is far inside 0.01 cent.
    assert!((e.f0_cents.unwrap() - 3.0).abs() < 0.01, "{:?}", e.f0_cents);
    // Both harmonics 1 dB up, 18 more at the -60 dB floor in both: RMS over 20 is
    // 1 dB x sqrt(2 / 20); 0.01 dB allows for the window's leakage from the detuning.
    let expected = (2.0f64 / 20.0).sqrt();
    assert!(
        (e.harmonics_db.unwrap() - expected).abs() < 0.01,
        "{:?}",
        e.harmonics_db
    );
    assert_eq!(ANALYSIS_RATE_HZ, 48_000.0);
}

#[test]
fn csv_has_the_header_and_one_row_per_configuration() {
    let (plan, report) = quick();
    let text = csv(&report.rows);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], CSV_HEADER);
    let configurations: usize = plan.groups.iter().map(|g| g.configs.len() + 1).sum();
    assert_eq!(lines.len() - 1, configurations);
    let columns = CSV_HEADER.split(',').count();
    for line in &lines[1..] {
        assert_eq!(cells(line).len(), columns, "{line}");
    }
}

/// Splits a CSV line at the commas outside double quotes.
fn cells(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(String::new()),
            _ => out.last_mut().unwrap().push(c),
        }
    }
    out
}
