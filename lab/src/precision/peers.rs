//! Peers measured beside Colophony by `colophony bench precision`: STK's `stk::Bowed`
//! (Debian's libstk-dev) and Faust's `pm.violinModel` from physmodels.lib (the faust
//! package), each playing A4 at 48 kHz.
//!
//! The setup step ([`ensure_installed`], also `scripts/install-peers.sh`) installs
//! `libstk-dev faust g++` with apt-get when any is missing. The bench then writes the
//! drivers kept in `assets/peers/` into `DIR/peers/`, builds them with `g++ -O2`, and runs
//! them: each renders three times and reports its fastest render (the sample loop only,
//! as Colophony's times are) and the audio as raw f32.
//!
//! Comparable: the cost, and the pitch against the note asked for. Not comparable: the
//! harmonic, slip, Helmholtz-time and waveform errors, which need a refined reference of
//! the same model and a bow-point velocity; neither peer takes physical bow velocity or
//! force (their controls are 0-1 or 0-128 values), and neither outputs the string velocity.

use super::{Errors, Measured, Row, ANALYSIS_RATE_HZ};
use colophony::analysis::{cents, peak_frequency_hz, rms};
use colophony::dsp::vocabulary::midi_to_hz;
use std::path::{Path, PathBuf};
use std::process::Command;

const STK_SOURCE: &str = include_str!("../../../assets/peers/stk_bowed.cpp");
const FAUST_DSP: &str = include_str!("../../../assets/peers/faust_violin.dsp");
const FAUST_DRIVER: &str = include_str!("../../../assets/peers/faust_driver.cpp");

/// The pitch both peers play: A4.
const NOTE: f64 = 69.0;

fn command_ok(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Installs `libstk-dev`, `faust` and `g++` with apt-get if any is missing (needs root
/// and the package registry). Returns what went wrong, for the unavailable rows.
pub fn ensure_installed() -> Result<(), String> {
    let mut missing = Vec::new();
    if !command_ok("dpkg", &["-s", "libstk-dev"]) {
        missing.push("libstk-dev");
    }
    if !command_ok("faust", &["--version"]) {
        missing.push("faust");
    }
    if !command_ok("g++", &["--version"]) {
        missing.push("g++");
    }
    if missing.is_empty() {
        return Ok(());
    }
    eprintln!("peers: installing {} with apt-get", missing.join(" "));
    let run = |args: &[&str]| -> Result<(), String> {
        let out = Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .output()
            .map_err(|e| format!("cannot run apt-get: {e}"))?;
        if out.status.success() {
            Ok(())
        } else {
            let err = String::from_utf8_lossy(&out.stderr);
            Err(format!(
                "apt-get {} failed: {}",
                args.join(" "),
                err.lines().last().unwrap_or("no message")
            ))
        }
    };
    run(&["update", "-q"])?;
    let mut install = vec!["install", "-y", "-q", "--no-install-recommends"];
    install.extend(&missing);
    run(&install)
}

/// Runs `cmd` to completion: its standard output, or the first line of its error.
pub(crate) fn run_checked(cmd: &mut Command, what: &str) -> Result<String, String> {
    run_checked_both(cmd, what).map(|(stdout, _)| stdout)
}

/// [`run_checked`], with the standard error of a run that succeeded too.
pub(crate) fn run_checked_both(cmd: &mut Command, what: &str) -> Result<(String, String), String> {
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {what}: {e}"))?;
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    if !out.status.success() {
        return Err(format!(
            "{what} failed: {}",
            err.lines().next().unwrap_or("no message")
        ));
    }
    Ok((String::from_utf8_lossy(&out.stdout).into_owned(), err))
}

/// Runs a built driver; returns the fastest render time (s) and the audio.
fn run_driver(program: &Path, args: &[&str], raw: &Path) -> Result<(f64, Vec<f64>), String> {
    let stdout = run_checked(
        Command::new(program).args(args).arg(raw),
        &program.display().to_string(),
    )?;
    let took: f64 = stdout
        .trim()
        .parse()
        .map_err(|_| format!("{} printed '{}'", program.display(), stdout.trim()))?;
    let bytes = std::fs::read(raw).map_err(|e| format!("cannot read {}: {e}", raw.display()))?;
    let audio = bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]) as f64)
        .collect();
    Ok((took, audio))
}

/// Writes the STK driver into `dir` and builds it with `g++ -O2 ... -lstk`.
pub fn build_stk(dir: &Path) -> Result<PathBuf, String> {
    let source = dir.join("stk_bowed.cpp");
    std::fs::write(&source, STK_SOURCE).map_err(|e| e.to_string())?;
    let exe = dir.join("stk_bowed");
    run_checked(
        Command::new("g++")
            .args(["-O2", "-o"])
            .arg(&exe)
            .arg(&source)
            .arg("-lstk"),
        "g++ (STK driver)",
    )?;
    Ok(exe)
}

fn build_faust(dir: &Path, freq_hz: f64) -> Result<PathBuf, String> {
    let dsp = dir.join("faust_violin.dsp");
    std::fs::write(&dsp, FAUST_DSP.replace("FREQ_HZ", &format!("{freq_hz:.6}")))
        .map_err(|e| e.to_string())?;
    std::fs::write(dir.join("faust_driver.cpp"), FAUST_DRIVER).map_err(|e| e.to_string())?;
    run_checked(
        Command::new("faust")
            .args(["-lang", "cpp", "-cn", "FaustViolin", "-o"])
            .arg(dir.join("faust_violin.hpp"))
            .arg(&dsp),
        "faust",
    )?;
    let exe = dir.join("faust_violin");
    run_checked(
        Command::new("g++")
            .args(["-O2", "-o"])
            .arg(&exe)
            .arg(dir.join("faust_driver.cpp")),
        "g++ (Faust driver)",
    )?;
    Ok(exe)
}

fn version(program: &str, args: &[&str]) -> String {
    Command::new(program)
        .args(args)
        .output()
        .ok()
        .and_then(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .next()
                .map(str::to_string)
        })
        .unwrap_or_default()
}

const NOT_COMPARABLE: &str = "pitch against the note asked for only: no refined reference of \
the same model, controls not in physical units, no bow-point velocity output";

fn row(model: &str, setting: &str, result: Result<(f64, Vec<f64>), String>, seconds: f64) -> Row {
    let target = midi_to_hz(NOTE);
    let base = Row {
        scenario: "violin A4".into(),
        model: model.into(),
        series: "peer".into(),
        setting: setting.into(),
        host_rate_hz: Some(ANALYSIS_RATE_HZ),
        realtime_ratio: None,
        measured: None,
        errors: Errors::default(),
        note: String::new(),
    };
    match result {
        Err(e) => {
            eprintln!("peers: {model} unavailable: {e}");
            Row {
                host_rate_hz: None,
                note: format!("unavailable: {e}"),
                ..base
            }
        }
        Ok((took, audio)) => {
            let steady = &audio[audio.len() / 2..];
            // Silence has no pitch (1e-6 is far below either peer's output level).
            let f0 = (rms(steady) > 1e-6)
                .then(|| peak_frequency_hz(steady, ANALYSIS_RATE_HZ, target, 300.0));
            Row {
                realtime_ratio: Some(seconds / took),
                measured: Some(Measured {
                    f0_hz: f0,
                    harmonics: Vec::new(),
                    slip_fraction: None,
                    slips_per_period: None,
                    helmholtz_s: None,
                    attack: Vec::new(),
                }),
                errors: Errors {
                    f0_cents: f0.map(|f| cents(f, target)),
                    ..Errors::default()
                },
                note: if f0.is_some() {
                    NOT_COMPARABLE.into()
                } else {
                    format!("silent output; {NOT_COMPARABLE}")
                },
                ..base
            }
        }
    }
}

/// Sets up, builds and runs both peers for `seconds` of A4 at 48 kHz in `out_dir/peers/`.
/// Never fails: a peer that cannot be installed, built or run gets a row that says so.
pub fn measure_peers(out_dir: &Path, seconds: f64) -> Vec<Row> {
    let dir = out_dir.join("peers");
    let setup = ensure_installed().and_then(|()| {
        std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))
    });
    let secs = format!("{seconds}");
    let rate = format!("{ANALYSIS_RATE_HZ}");
    let freq = format!("{:.6}", midi_to_hz(NOTE));
    let stk = setup.clone().and_then(|()| {
        let exe = build_stk(&dir)?;
        run_driver(&exe, &[&secs, &rate, &freq], &dir.join("stk_bowed.f32"))
    });
    let faust = setup.and_then(|()| {
        let exe = build_faust(&dir, midi_to_hz(NOTE))?;
        run_driver(&exe, &[&secs, &rate], &dir.join("faust_violin.f32"))
    });
    let stk_version = version("dpkg-query", &["-W", "-f", "${Version}", "libstk-dev"]);
    let faust_version = version("faust", &["--version"]);
    vec![
        row(
            &format!("peer: STK Bowed (libstk-dev {stk_version})"),
            "48 kHz, noteOn(440 Hz, 0.8), STK defaults",
            stk,
            seconds,
        ),
        row(
            &format!(
                "peer: Faust pm.violinModel ({})",
                faust_version.trim_start_matches("FAUST ")
            ),
            "48 kHz, pressure 0.5, velocity 0.6, position 0.7",
            faust,
            seconds,
        ),
    ]
}
