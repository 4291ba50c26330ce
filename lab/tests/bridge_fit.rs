//! The bridge admittance fit on synthetic data with known modes, its refusal of bad
//! input, the `colophony fit-bridge` command as a user runs it, and the shipped
//! generic bridges.

use colophony_lab::admittance_fit::synthetic::{
    add_relative_noise, log_grid_hz, random_modes, sample, GenericInstrument,
};
use colophony_lab::admittance_fit::{
    admittance_csv, bridge_json, draw_figure, fit_bridge, fit_errors, load_bridge,
    load_bridge_ports, parse_admittance_csv, read_admittance_csv, symmetric_eigenvalues,
    write_admittance_csv, write_bridge, Admittance, AdmittanceData, BridgeModes,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    scratch_in("bridge_fit", name)
}

/// A scratch path in a directory of its own (a test that checks for leftover temporary
/// files must not see another test's write in progress).
fn scratch_in(dir: &str, name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

fn colophony(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_colophony"))
        .args(args)
        .output()
        .expect("running colophony")
}

fn repo(path: &str) -> PathBuf {
    // The repository root, where the assets and docs are (this crate is lab/).
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

/// Synthetic measurement: `count` random modes over 50-5000 Hz, 600 log-spaced points
/// (about five points per bandwidth at Q 60), 1 % complex noise.
fn synthetic(seed: u64, count: usize, ports: usize) -> (BridgeModes, AdmittanceData) {
    let truth = random_modes(seed, count, ports, 50.0, 5000.0);
    let mut data = sample(&truth, ports, &log_grid_hz(50.0, 5000.0, 600));
    add_relative_noise(&mut data, 0.01, seed + 1000);
    (truth, data)
}

fn frobenius(g: &[[f64; 2]; 2]) -> f64 {
    g.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

/// Worst relative errors (frequency, bandwidth, gain) of `fit` against `truth`, modes
/// matched in frequency order.
fn recovery_errors(truth: &BridgeModes, fit: &BridgeModes) -> (f64, f64, f64) {
    assert_eq!(truth.modes.len(), fit.modes.len());
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for (t, f) in truth.modes.iter().zip(&fit.modes) {
        let dg = [0, 1].map(|i| [0, 1].map(|j| f.gain[i][j] - t.gain[i][j]));
        worst.0 = worst.0.max((f.freq_hz / t.freq_hz - 1.0).abs());
        worst.1 = worst.1.max((f.bandwidth_hz / t.bandwidth_hz - 1.0).abs());
        worst.2 = worst.2.max(frobenius(&dg) / frobenius(&t.gain));
    }
    worst
}

/// Passive: every gain PSD, and the smallest eigenvalue of Re Y(j w) non-negative on a
/// dense grid well past the data band. Both to rounding: 1e-12 of the gain's (or of
/// Re Y's) size.
fn assert_passive(bridge: &BridgeModes) {
    for (i, m) in bridge.modes.iter().enumerate() {
        assert!(m.freq_hz > 0.0 && m.bandwidth_hz > 0.0, "mode {i}: {m:?}");
        assert_eq!(m.gain[0][1], m.gain[1][0], "mode {i}: asymmetric");
        let [lo, hi] = symmetric_eigenvalues(m.gain[0][0], m.gain[0][1], m.gain[1][1]);
        assert!(lo >= -1e-12 * hi.abs(), "mode {i}: gain eigenvalue {lo}");
    }
    for f in log_grid_hz(1.0, 40_000.0, 20_000) {
        let y = bridge.admittance_s_per_kg(f);
        let [lo, hi] =
            symmetric_eigenvalues(y[0][0].re, 0.5 * (y[0][1].re + y[1][0].re), y[1][1].re);
        assert!(
            lo >= -1e-12 * hi.abs(),
            "Re Y has eigenvalue {lo} at {f} Hz"
        );
    }
}

// Tolerances of the recovery tests: frequency 1 %, bandwidth 20 %, gain 15 % (Frobenius,
// relative). With 1 % noise the fit does far better (about 0.01 %, 0.5 % and 0.2 %); the
// margins leave room for harder draws, not for a broken fit.
const FREQ_TOL: f64 = 0.01;
const BANDWIDTH_TOL: f64 = 0.2;
const GAIN_TOL: f64 = 0.15;

fn assert_recovers(label: &str, truth: &BridgeModes, fit: &BridgeModes) {
    let (df, db, dg) = recovery_errors(truth, fit);
    eprintln!(
        "{label}: worst frequency error {:.4} %, bandwidth {:.3} %, gain {:.3} %",
        100.0 * df,
        100.0 * db,
        100.0 * dg
    );
    assert!(df < FREQ_TOL, "{label}: frequency error {df}");
    assert!(db < BANDWIDTH_TOL, "{label}: bandwidth error {db}");
    assert!(dg < GAIN_TOL, "{label}: gain error {dg}");
}

/// 1 % complex noise is 0.061 dB and 0.41 degrees RMS in each of magnitude and phase; a
/// fit that reaches the noise floor stays within 1.5 times that.
fn assert_fits_to_noise(fit_errors: &[colophony_lab::admittance_fit::EntryError]) {
    for e in fit_errors {
        assert!(
            e.magnitude_db_rms < 0.09 && e.phase_deg_rms < 0.6,
            "fit error above the noise: {e:?}"
        );
    }
}

#[test]
fn fit_recovers_random_2x2_modes_from_noisy_data() {
    for seed in 1..=4 {
        let (truth, data) = synthetic(seed, 8, 2);
        let fit = fit_bridge(&data, 8).unwrap();
        assert_eq!(fit.ports, 2);
        assert_recovers(&format!("2x2, 8 modes, seed {seed}"), &truth, &fit.bridge);
        assert_fits_to_noise(&fit.errors);
        assert_passive(&fit.bridge);
    }
}

#[test]
fn fit_recovers_random_1x1_modes_from_noisy_data() {
    for seed in 11..=13 {
        let (truth, data) = synthetic(seed, 6, 1);
        let fit = fit_bridge(&data, 6).unwrap();
        assert_eq!(fit.ports, 1);
        assert_recovers(&format!("1x1, 6 modes, seed {seed}"), &truth, &fit.bridge);
        assert_fits_to_noise(&fit.errors);
        assert_passive(&fit.bridge);
    }
}

#[test]
fn fit_recovers_modes_from_a_linear_frequency_grid() {
    // Measurements usually come as FFT bins: 2 Hz steps from 40 Hz to 4 kHz.
    let truth = random_modes(21, 10, 2, 80.0, 4000.0);
    let grid: Vec<f64> = (0..1981).map(|k| 40.0 + 2.0 * k as f64).collect();
    let mut data = sample(&truth, 2, &grid);
    add_relative_noise(&mut data, 0.01, 99);
    let fit = fit_bridge(&data, 10).unwrap();
    assert_recovers("2x2, 10 modes, linear grid", &truth, &fit.bridge);
    assert_fits_to_noise(&fit.errors);
    assert_passive(&fit.bridge);
}

#[test]
fn fit_with_more_modes_than_peaks_stays_passive_in_band_and_fits_to_noise() {
    // Six true modes, nine asked for: the extra ones go where the residual is largest
    // and must neither break passivity nor leave the band nor worsen the fit.
    let (_, data) = synthetic(7, 6, 2);
    let fit = fit_bridge(&data, 9).unwrap();
    assert_eq!(fit.bridge.modes.len(), 9);
    assert_passive(&fit.bridge);
    assert_fits_to_noise(&fit.errors);
    let band = data.freq_hz[0]..=data.freq_hz[data.freq_hz.len() - 1];
    assert!(fit.bridge.modes.iter().all(|m| band.contains(&m.freq_hz)));
}

#[test]
fn fit_with_fewer_modes_than_the_data_has_is_still_passive() {
    // The generic cello has 14 modes; eight cannot fit it well, but what they give must
    // still be a passive bridge, and better than no bridge at all (error below 20 dB).
    let data = GenericInstrument::Cello.synthetic_data();
    let fit = fit_bridge(&data, 8).unwrap();
    assert_eq!(fit.bridge.modes.len(), 8);
    assert_passive(&fit.bridge);
    for e in &fit.errors {
        assert!(e.magnitude_db_rms < 20.0, "{e:?}");
    }
}

/// Every way a CSV can be malformed, with a word the error message must contain.
const BAD_CSV: &[(&str, &str, &str)] = &[
    ("empty", "", "empty"),
    ("blank", "\n \n", "empty"),
    ("header only", "freq_hz,y_re,y_im\n", "no data rows"),
    (
        "wrong header",
        "f,re,im\n100,1,0\n",
        "header must be `freq_hz,yhh_re",
    ),
    (
        "2x2 header with 1x1 rows",
        "freq_hz,yhh_re,yhh_im,yhv_re,yhv_im,yvv_re,yvv_im\n100,1,0\n",
        "expected 7 columns",
    ),
    (
        "extra column",
        "freq_hz,y_re,y_im\n100,1,0,5\n",
        "expected 3 columns",
    ),
    (
        "not a number",
        "freq_hz,y_re,y_im\n100,abc,0\n",
        "`abc` is not a number",
    ),
    (
        "NaN",
        "freq_hz,y_re,y_im\n100,NaN,0\n",
        "not a finite number",
    ),
    (
        "infinity",
        "freq_hz,y_re,y_im\n100,0,inf\n",
        "not a finite number",
    ),
    (
        "unsorted",
        "freq_hz,y_re,y_im\n100,1,0\n300,1,0\n200,1,0\n",
        "line 4: frequency 200 Hz follows 300 Hz",
    ),
    (
        "duplicate",
        "freq_hz,y_re,y_im\n100,1,0\n100,1,0\n",
        "line 3: duplicate frequency 100 Hz",
    ),
    (
        "zero frequency",
        "freq_hz,y_re,y_im\n0,1,0\n",
        "not positive",
    ),
];

#[test]
fn malformed_csv_is_refused_with_a_clear_message() {
    for (name, text, expected) in BAD_CSV {
        let e = parse_admittance_csv(text).expect_err(name);
        assert!(e.contains(expected), "{name}: got `{e}`");
    }
}

#[test]
fn fit_refuses_more_modes_than_the_data_supports() {
    let (_, data) = synthetic(3, 2, 1);
    let short = AdmittanceData {
        freq_hz: data.freq_hz[..11].to_vec(),
        entries: vec![data.entries[0][..11].to_vec()],
    };
    let e = fit_bridge(&short, 3).unwrap_err();
    assert!(
        e.contains("cannot support 3 modes") && e.contains("at most 2"),
        "{e}"
    );
    assert!(fit_bridge(&short, 2).is_ok());
    assert!(fit_bridge(&short, 0).unwrap_err().contains("at least 1"));
    let zero = AdmittanceData {
        entries: vec![vec![Default::default(); 11]],
        ..short
    };
    assert!(fit_bridge(&zero, 1).unwrap_err().contains("zero"));
}

fn no_leftovers(dir: &Path) {
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

#[test]
fn cli_fit_bridge_writes_a_loadable_passive_bridge_and_reports_errors() {
    for ports in [1, 2] {
        let (truth, data) = synthetic(30 + ports as u64, 5, ports);
        let input = scratch_in("bridge_fit_cli", &format!("cli-{ports}.csv"));
        std::fs::write(&input, admittance_csv(&data)).unwrap();
        let out = scratch_in("bridge_fit_cli", &format!("cli-{ports}.json"));
        let run = colophony(&[
            "fit-bridge",
            input.to_str().unwrap(),
            "--modes",
            "5",
            "--out",
            out.to_str().unwrap(),
        ]);
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let entries: &[&str] = if ports == 1 {
            &["y:"]
        } else {
            &["hh:", "hv:", "vv:"]
        };
        for entry in entries {
            let line = stdout.lines().find(|l| l.trim_start().starts_with(entry));
            let line = line.unwrap_or_else(|| panic!("no {entry} line in\n{stdout}"));
            assert!(line.contains(" dB") && line.contains(" deg"), "{line}");
        }
        let (bridge, loaded_ports) = load_bridge_ports(&out).unwrap();
        assert_eq!(loaded_ports, ports);
        assert_recovers(&format!("CLI {ports}x{ports}"), &truth, &bridge);
        assert_passive(&bridge);
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            text,
            bridge_json(&bridge, ports),
            "JSON is in the documented format"
        );
        if ports == 1 {
            // A 1x1 file's gains are 1x1 matrices and load as [[g, 0], [0, 0]].
            assert!(
                text.contains("\"gain\":[[") && !text.contains("],["),
                "{text}"
            );
            assert!(bridge.modes.iter().all(|m| m.gain[1] == [0.0, 0.0]));
        }
        no_leftovers(out.parent().unwrap());
    }
}

#[test]
fn cli_fit_bridge_refuses_bad_input_and_writes_nothing() {
    let (_, data) = synthetic(40, 2, 2);
    let mut cases: Vec<(String, String, &str)> = BAD_CSV
        .iter()
        .map(|(name, text, _)| (name.to_string(), text.to_string(), "3"))
        .collect();
    let few = AdmittanceData {
        freq_hz: data.freq_hz[..10].to_vec(),
        entries: data.entries.iter().map(|s| s[..10].to_vec()).collect(),
    };
    cases.push(("too many modes".into(), admittance_csv(&few), "3"));
    cases.push(("zero modes".into(), admittance_csv(&data), "0"));
    for (i, (name, text, modes)) in cases.iter().enumerate() {
        let input = scratch_in("bridge_fit_refused", &format!("bad-{i}.csv"));
        std::fs::write(&input, text).unwrap();
        let out = scratch_in("bridge_fit_refused", &format!("bad-{i}.json"));
        let run = colophony(&[
            "fit-bridge",
            input.to_str().unwrap(),
            "--modes",
            modes,
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{name}: succeeded");
        assert!(stderr.starts_with("error"), "{name}: stderr `{stderr}`");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{name}: `{stderr}`");
        assert!(!out.exists(), "{name}: wrote {}", out.display());
    }
    let missing = scratch_in("bridge_fit_refused", "missing.csv");
    let out = scratch_in("bridge_fit_refused", "missing.json");
    let run = colophony(&[
        "fit-bridge",
        missing.to_str().unwrap(),
        "--modes",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).starts_with("error"));
    assert!(!out.exists());
    no_leftovers(out.parent().unwrap());
}

#[test]
fn cli_figure_bridge_fit_draws_data_against_model() {
    let (truth, data) = synthetic(50, 4, 2);
    let input = scratch("figure.csv");
    std::fs::write(&input, admittance_csv(&data)).unwrap();
    let fit = scratch("figure.json");
    std::fs::write(&fit, bridge_json(&truth, 2)).unwrap();
    let out = scratch("figure.png");
    let run = colophony(&[
        "figure",
        "bridge-fit",
        "--in",
        input.to_str().unwrap(),
        "--fit",
        fit.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let png = std::fs::read(&out).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // Width from the IHDR chunk: three entry columns.
    let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
    assert!(width > 1500, "width {width}");

    // A 1x1 fit against 2x2 data is refused, and nothing is drawn.
    let one = scratch("figure-1x1.json");
    std::fs::write(&one, bridge_json(&truth, 1)).unwrap();
    let out = scratch("figure-mismatch.png");
    let run = colophony(&[
        "figure",
        "bridge-fit",
        "--in",
        input.to_str().unwrap(),
        "--fit",
        one.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).starts_with("error"));
    assert!(!out.exists());
}

/// The shipped generic bridges: `COLOPHONY_BLESS_BRIDGES=1 cargo test --test bridge_fit
/// shipped` regenerates `assets/bridges/{cello,violin,viola}-synthetic.csv`, the fitted
/// `{cello,violin,viola}-generic.json` and `docs/bridge-fit-cello.png`; without it, the test
/// checks that the shipped files are what that would produce.
#[test]
fn shipped_generic_bridges_are_passive_fits_of_their_synthetic_source() {
    let bless = std::env::var_os("COLOPHONY_BLESS_BRIDGES").is_some();
    for inst in [
        GenericInstrument::Cello,
        GenericInstrument::Violin,
        GenericInstrument::Viola,
    ] {
        let name = inst.name();
        let csv = repo(&format!("assets/bridges/{name}-synthetic.csv"));
        let json = repo(&format!("assets/bridges/{name}-generic.json"));
        let data = inst.synthetic_data();
        let fit = fit_bridge(&data, 14).unwrap();
        if bless {
            write_admittance_csv(&csv, &data).unwrap();
            write_bridge(&json, &fit.bridge, 2).unwrap();
            if inst == GenericInstrument::Cello {
                let png = repo("docs/bridge-fit-cello.png");
                draw_figure(&csv, &json, &png).unwrap();
            }
        }
        // The CSV is the generator's output exactly (it prints round-trip decimals).
        assert_eq!(
            read_admittance_csv(&csv).unwrap(),
            data,
            "{name}: CSV is stale"
        );
        let shipped = load_bridge(&json).unwrap();
        assert_passive(&shipped);
        // The same fit again gives the shipped modes; 1e-9 allows for floating-point
        // differences between machines, far below anything audible.
        assert_eq!(shipped.modes.len(), 14);
        for (s, f) in shipped.modes.iter().zip(&fit.bridge.modes) {
            assert!(
                (s.freq_hz / f.freq_hz - 1.0).abs() < 1e-9,
                "{name}: {s:?} vs {f:?}"
            );
            assert!(
                (s.bandwidth_hz / f.bandwidth_hz - 1.0).abs() < 1e-9,
                "{name}"
            );
            for (gs, gf) in s.gain.iter().flatten().zip(f.gain.iter().flatten()) {
                assert!((gs - gf).abs() <= 1e-9 * frobenius(&f.gain), "{name}: gain");
            }
        }
        for e in fit_errors(&data, &shipped) {
            eprintln!(
                "{name} {}: {:.3} dB, {:.2} deg RMS",
                e.entry, e.magnitude_db_rms, e.phase_deg_rms
            );
        }
        assert_fits_to_noise(&fit_errors(&data, &shipped));
        assert_recovers(&format!("generic {name}"), &inst.modes(), &shipped);
    }
}
