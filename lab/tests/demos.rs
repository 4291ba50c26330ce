//! The sound demos (`assets/demos/`, listed with their commands in `demos.txt`) are what
//! their commands render: each command runs again through the `colophony` binary and its
//! audio must have the file's length, level and pitch. A change that moves a demo's sound
//! fails here until the demos are rendered again (`scripts/render-demos.sh`).

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

struct Demo {
    file: String,
    args: Vec<String>,
}

fn demos() -> Vec<Demo> {
    let list = std::fs::read_to_string(root().join("assets/demos/demos.txt"))
        .expect("assets/demos/demos.txt");
    list.lines()
        .filter(|line| !line.starts_with('#') && !line.trim().is_empty())
        .map(|line| {
            let mut fields = line.split('|');
            let file = fields.next().expect("file").trim().to_string();
            let args = fields
                .next()
                .expect("arguments")
                .split_whitespace()
                .map(String::from)
                .collect();
            assert!(fields.next().is_some(), "{file}: no listening note");
            Demo { file, args }
        })
        .collect()
}

fn read_wav(path: &Path) -> (Vec<f64>, f64) {
    let mut reader =
        hound::WavReader::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let spec = reader.spec();
    assert_eq!(spec.channels, 1, "{}: the demos are mono", path.display());
    assert_eq!(
        spec.bits_per_sample,
        16,
        "{}: the demos are 16-bit",
        path.display()
    );
    let samples = reader
        .samples::<i16>()
        .map(|s| f64::from(s.expect("sample")) / 32768.0)
        .collect();
    (samples, f64::from(spec.sample_rate))
}

fn rms_db(x: &[f64]) -> f64 {
    20.0 * colophony::analysis::rms(x).max(1e-15).log10()
}

/// The fundamental of a window by YIN (de Cheveigne and Kawahara 2002): the first lag
/// whose cumulative-mean-normalised difference dips under 0.15, refined by a parabola;
/// `None` where no lag does (noise, silence) or the window is 60 dB under full scale.
fn yin_hz(x: &[f64], sample_rate_hz: f64) -> Option<f64> {
    if rms_db(x) < -60.0 {
        return None;
    }
    let min_lag = (sample_rate_hz / 2000.0) as usize;
    let max_lag = (sample_rate_hz / 40.0) as usize;
    let n = x.len() - max_lag;
    let mut d = vec![0.0; max_lag + 1];
    for (lag, slot) in d.iter_mut().enumerate().skip(1) {
        *slot = (0..n).map(|i| (x[i] - x[i + lag]).powi(2)).sum();
    }
    let mut running = 0.0;
    let mut cmnd = vec![1.0; max_lag + 1];
    for lag in 1..=max_lag {
        running += d[lag];
        cmnd[lag] = d[lag] * lag as f64 / running.max(1e-30);
    }
    let mut lag = min_lag;
    while lag < max_lag {
        if cmnd[lag] < 0.15 {
            while lag + 1 < max_lag && cmnd[lag + 1] < cmnd[lag] {
                lag += 1;
            }
            let (a, b, c) = (cmnd[lag - 1], cmnd[lag], cmnd[lag + 1]);
            let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
            return Some(sample_rate_hz / (lag as f64 + shift.clamp(-1.0, 1.0)));
        }
        lag += 1;
    }
    None
}

/// The pitch track: one YIN estimate a quarter second, over 4096-sample windows.
fn pitch_track(x: &[f64], sample_rate_hz: f64) -> Vec<Option<f64>> {
    let hop = (0.25 * sample_rate_hz) as usize;
    (0..x.len().saturating_sub(4096) / hop)
        .map(|k| yin_hz(&x[k * hop..k * hop + 4096], sample_rate_hz))
        .collect()
}

#[test]
fn every_demo_command_renders_its_file_with_the_same_length_level_and_pitch() {
    let out_dir = std::env::temp_dir().join(format!("colophony-demos-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).unwrap();
    let list = demos();
    // 15: the instruments', friction laws', papers' and rubbed objects' demos; the five
    // articulation demos make 20. Fewer means the file or its parsing lost lines.
    assert!(list.len() >= 15, "the demo list lost lines: {}", list.len());
    for demo in &list {
        let fresh = out_dir.join(&demo.file);
        let status = Command::new(env!("CARGO_BIN_EXE_colophony"))
            .current_dir(root())
            .arg("render")
            .args(&demo.args)
            .arg("--out")
            .arg(&fresh)
            .status()
            .expect("run colophony");
        assert!(
            status.success(),
            "{}: `colophony render {}` failed",
            demo.file,
            demo.args.join(" ")
        );
        let (kept, fs) = read_wav(&root().join("assets/demos").join(&demo.file));
        let (now, fs_now) = read_wav(&fresh);
        assert_eq!(fs, fs_now, "{}: sample rate", demo.file);
        // The renderer's length is decided by the score and the ring-out rule, not by
        // chance: it must match to the sample.
        assert_eq!(kept.len(), now.len(), "{}: length in samples", demo.file);
        // 0.5 dB: half the level difference a listener just notices.
        let (level_kept, level_now) = (rms_db(&kept), rms_db(&now));
        assert!(
            (level_kept - level_now).abs() < 0.5,
            "{}: level {level_now:.2} dB against the file's {level_kept:.2} dB",
            demo.file
        );
        // Pitch, a quarter second at a time: where both are pitched, within 5 cents (about
        // the smallest mistuning a trained ear hears); pitched and unpitched windows agree
        // in 90 % of the track (a decision at a note's edge may flip with a tiny change).
        let (track_kept, track_now) = (pitch_track(&kept, fs), pitch_track(&now, fs));
        let mut agree = 0;
        for (k, (a, b)) in track_kept.iter().zip(&track_now).enumerate() {
            match (a, b) {
                (Some(a), Some(b)) => {
                    let cents = 1200.0 * (b / a).log2();
                    assert!(
                        cents.abs() < 5.0,
                        "{}: at {:.2} s the pitch is {b:.2} Hz against the file's {a:.2} Hz ({cents:+.1} cents)",
                        demo.file,
                        k as f64 * 0.25
                    );
                    agree += 1;
                }
                (None, None) => agree += 1,
                _ => {}
            }
        }
        assert!(
            agree * 10 >= track_kept.len() * 9,
            "{}: pitched and unpitched windows agree in {agree} of {}",
            demo.file,
            track_kept.len()
        );
        std::fs::remove_file(&fresh).ok();
    }
    std::fs::remove_dir_all(&out_dir).ok();
}
