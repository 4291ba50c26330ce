//! The factory presets as a user plays them: each one, applied to the plugin's parameters
//! and played through the performer on its own note, sounds (finite, audible, and for the
//! bowed strings at the note's pitch); the renderer's `--preset` plays a named preset and
//! a broken or unknown one fails in one line with no file.

use colophony::analysis::{cents, rms};
use colophony::dsp::vocabulary::midi_to_hz;
use colophony::params::ColophonyParams;
use colophony::performer::Performer;
use colophony::presets;
use std::path::PathBuf;
use std::process::Command;

const FS: f64 = 48_000.0;

#[test]
fn every_factory_preset_sounds_on_its_note() {
    for (id, preset) in presets::factory() {
        let params = ColophonyParams::default();
        preset.apply_to(&params).unwrap();
        let setup = params.setup();
        let mut performer = Performer::new(setup.instrument);
        performer.activate(&setup, FS).unwrap();
        performer.configure(&setup);
        let note = preset.note.expect("every factory preset names its note");
        performer.note_on(note, 0.8);
        let bow = params.bow();
        let out: Vec<f64> = (0..(1.5 * FS) as usize)
            .map(|_| performer.tick(bow).audio)
            .collect();
        assert!(out.iter().all(|x| x.is_finite()), "{id}: not finite");
        let tail = &out[out.len() / 2..];
        // Over the whole note: the rubbed objects include a squeak that sticks after
        // 0.2 s (paper A's modal object, as the renderer's own rub of it) and a squeal
        // that builds up over a second (the brake). -60 dBFS: far below any of them, far
        // above a note that does not speak.
        let level = rms(&out);
        assert!(level > 1e-3, "{id}: rms {level:.2e}");
        if setup.rubbed.is_none() {
            let tail_rms = rms(tail);
            // -60 dBFS, as above: a bowed note that speaks is far louder.
            assert!(
                tail_rms > 1e-3,
                "{id}: the bowed note dies ({tail_rms:.2e} after 0.75 s)"
            );
            // The bowed strings sound their note: within a quarter tone (the intonation
            // has its own tests, lab/tests/playing_space.rs; this checks the preset plays
            // the note, not an octave or a fifth off).
            let hz = autocorrelation_pitch_hz(tail, FS, midi_to_hz(note as f64));
            let off = cents(hz, midi_to_hz(note as f64));
            assert!(
                off.abs() < 50.0,
                "{id}: {hz:.1} Hz, {off:+.0} cents from note {note}"
            );
        }
    }
}

/// The pitch whose period is the shortest lag (from a third to twice the expected period)
/// with a normalised autocorrelation within 10 % of the best: an octave up or a period
/// doubling shows as half or twice the period.
fn autocorrelation_pitch_hz(x: &[f64], fs: f64, expected_hz: f64) -> f64 {
    let period = fs / expected_hz;
    let (lo, hi) = ((period / 3.0) as usize, (period * 2.0) as usize);
    let n = x.len() - hi;
    let energy: f64 = x[..n].iter().map(|v| v * v).sum();
    let corr: Vec<f64> = (lo..=hi)
        .map(|lag| {
            x[..n]
                .iter()
                .zip(&x[lag..lag + n])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / energy
        })
        .collect();
    let best = corr.iter().cloned().fold(f64::MIN, f64::max);
    // The first local maximum within 10 % of the best.
    let i = (1..corr.len() - 1)
        .find(|&i| corr[i] >= 0.9 * best && corr[i] >= corr[i - 1] && corr[i] >= corr[i + 1])
        .unwrap_or(0);
    fs / (lo + i) as f64
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("presets");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn render_plays_a_preset_by_id_and_refuses_broken_ones_in_one_line() {
    let out = scratch("detache.wav");
    let run = Command::new(env!("CARGO_BIN_EXE_colophony"))
        .args([
            "render",
            "--preset",
            "violin-detache",
            "--seconds",
            "0.5",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(hound::WavReader::open(&out).unwrap().duration(), 24_000);

    let broken = scratch("broken.json");
    std::fs::write(
        &broken,
        r#"{"name": "b", "params": {"instrument": "lute"}}"#,
    )
    .unwrap();
    for what in [
        broken.to_str().unwrap(),
        "no-such-preset",
        "/no/such/file.json",
    ] {
        let out = scratch("refused.wav");
        let run = Command::new(env!("CARGO_BIN_EXE_colophony"))
            .args(["render", "--preset", what, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{what}");
        assert!(stderr.starts_with("error"), "{what}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{what}: {stderr}");
        assert!(!out.exists(), "{what} left a file");
    }
}
