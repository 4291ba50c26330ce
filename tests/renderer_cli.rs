//! The `colophony` binary as a user runs it: `render --probe` shows Raman's Helmholtz
//! motion, and bad arguments fail with a one-line error, a non-zero exit and no file.

use colophony::analysis::slip_stats;
use colophony::dsp::instrument::midi_to_hz;
use std::path::PathBuf;
use std::process::{Command, Output};

fn colophony(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_colophony"))
        .args(args)
        .output()
        .expect("running colophony")
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("renderer_cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn probe_at_default_settings_shows_one_slip_per_period_of_length_beta_at_bow_velocity() {
    let out = scratch("probe.wav");
    let run = colophony(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--probe",
        "--seconds",
        "2.5",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut reader = hound::WavReader::open(&out).unwrap();
    let spec = reader.spec();
    assert_eq!(spec.channels, 3);
    assert_eq!(spec.sample_format, hound::SampleFormat::Float);
    let samples: Vec<f32> = reader.samples::<f32>().map(Result::unwrap).collect();
    let fs = spec.sample_rate as f64;
    // Channel 1: string velocity at the bow, over 1.5..2.5 s (steady Helmholtz motion).
    let v: Vec<f64> = samples
        .chunks(3)
        .map(|frame| frame[1] as f64)
        .skip((1.5 * fs) as usize)
        .collect();
    let friction: Vec<f64> = samples.chunks(3).map(|frame| frame[2] as f64).collect();
    // Defaults of the renderer (and of the plugin): cello D3, v_b 0.1 m/s, beta 0.1.
    let (vb, beta) = (0.1, 0.1);
    // 1e-6 m/s: the probe is f32, which rounds the sticking velocity 0.1 to ~1e-8.
    let stats = slip_stats(&v, vb, fs, midi_to_hz(50.0), 1e-6);
    println!("probe of the default note: {stats:?}");
    assert!(
        (stats.slips_per_period - 1.0).abs() < 0.02,
        "{} slips per period",
        stats.slips_per_period
    );
    assert!(
        (stats.slip_fraction - beta).abs() < 0.1 * beta,
        "slip fraction {} (beta {beta})",
        stats.slip_fraction
    );
    assert!(
        (stats.stick_velocity_m_per_s - vb).abs() < 0.1 * vb,
        "sticking at {} m/s",
        stats.stick_velocity_m_per_s
    );
    // Channel 2 is the friction force, bounded by mu_s F_N = 0.4 N at the default 1 N.
    let peak = friction.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(peak > 0.1 && peak <= 0.4 + 1e-6, "friction peak {peak} N");
}

#[test]
fn bad_arguments_fail_with_one_line_and_write_nothing() {
    let cases: [(&str, &[&str]); 7] = [
        ("quality", &["--quality", "best"]),
        ("instrument", &["--instrument", "banjo"]),
        ("note-range", &["--note", "C1"]),
        ("note-name", &["--note", "H2"]),
        ("seconds", &["--seconds", "-1"]),
        ("sample-rate", &["--sample-rate", "0"]),
        ("force", &["--bow-force", "NaN"]),
    ];
    for (name, extra) in cases {
        let out = scratch(&format!("bad-{name}.wav"));
        let mut args = vec!["render", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let run = colophony(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        println!("{extra:?}: {}", stderr.trim());
        assert!(!run.status.success(), "{extra:?} succeeded");
        assert!(stderr.contains("error"), "{extra:?}: no error message");
        assert!(!out.exists(), "{extra:?} left {}", out.display());
        let partial = out.with_extension("wav.partial");
        assert!(!partial.exists(), "{extra:?} left a partial file");
    }
}

#[test]
fn an_unwritable_output_path_fails_cleanly() {
    let run = colophony(&[
        "render",
        "--out",
        "/nonexistent-dir/x.wav",
        "--seconds",
        "0.1",
    ]);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.starts_with("error"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}

#[test]
fn presets_and_friction_laws_render_and_unknown_names_fail_cleanly() {
    let out = scratch("glass.wav");
    let run = colophony(&[
        "render",
        "--preset",
        "wine-glass",
        "--seconds",
        "0.5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let reader = hound::WavReader::open(&out).unwrap();
    assert_eq!(reader.duration(), 24_000);
    for law in ["static", "lugre", "elasto-plastic", "hyperbolic"] {
        let out = scratch(&format!("law-{law}.wav"));
        let run = colophony(&[
            "render",
            "--friction",
            law,
            "--seconds",
            "0.3",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            run.status.success(),
            "{law}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    for bad in [["--preset", "kazoo"], ["--friction", "sticky"]] {
        let out = scratch("bad-name.wav");
        let mut args = vec!["render", "--out", out.to_str().unwrap()];
        args.extend_from_slice(&bad);
        let run = colophony(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && stderr.contains("error"),
            "{bad:?}: {stderr}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn paper_figures_are_written_as_png() {
    for name in [
        "serafin-fig7",
        "serafin-modal",
        "maestre-fig6",
        "maestre-fig7",
        "maestre-fig8",
    ] {
        let out = scratch(&format!("{name}.png"));
        let run = colophony(&["figure", name, "--out", out.to_str().unwrap()]);
        assert!(
            run.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let bytes = std::fs::read(&out).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name} is not a PNG");
        assert!(
            bytes.len() > 20_000,
            "{name}: suspiciously small ({} bytes)",
            bytes.len()
        );
    }
    let run = colophony(&[
        "figure",
        "nonsense",
        "--out",
        scratch("x.png").to_str().unwrap(),
    ]);
    assert!(!run.status.success());
}

/// The quality presets as the renderer's user picks them: each renders, and the draft's
/// thermal bowed pitch stays within a cent of the reference's (docs/precision.md measured
/// 0.07 cents at N_B 6 against N_B 120 on the same scenario).
#[test]
fn quality_presets_render_and_the_draft_bows_the_references_pitch() {
    let mut pitch = Vec::new();
    for quality in ["draft", "good", "reference", "auto"] {
        let out = scratch(&format!("quality-{quality}.wav"));
        let run = colophony(&[
            "render",
            "--out",
            out.to_str().unwrap(),
            "--friction",
            "thermal",
            "--note",
            "C2",
            "--bow-velocity",
            "0.15",
            "--bow-force",
            "3",
            "--seconds",
            "1.5",
            "--quality",
            quality,
            "--probe",
        ]);
        assert!(
            run.status.success(),
            "{quality}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let mut reader = hound::WavReader::open(&out).unwrap();
        let fs = reader.spec().sample_rate as f64;
        // Probe files: channel 0 is the audio.
        let x: Vec<f64> = reader
            .samples::<f32>()
            .step_by(3)
            .map(|s| s.unwrap() as f64)
            .collect();
        assert!(x.iter().all(|v| v.is_finite()));
        let steady = &x[x.len() / 2..];
        let f0 = colophony::analysis::peak_frequency_hz(steady, fs, midi_to_hz(36.0), 100.0);
        println!("{quality}: {f0:.3} Hz");
        pitch.push(f0);
    }
    let cents = |a: f64, b: f64| 1200.0 * (a / b).log2();
    let draft_error = cents(pitch[0], pitch[2]);
    println!("draft against reference: {draft_error:+.3} cents");
    assert!(draft_error.abs() < 1.0, "{draft_error:+.3} cents");
}
