//! The `colophony` binary as a user runs it: `render --probe` shows Raman's Helmholtz
//! motion, and bad arguments fail with a one-line error, a non-zero exit and no file.

use colophony::analysis::slip_stats;
use colophony::dsp::vocabulary::midi_to_hz;
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
    // One slip per period over ~147 periods: only the window edges add a fraction.
    assert!(
        (stats.slips_per_period - 1.0).abs() < 0.02,
        "{} slips per period",
        stats.slips_per_period
    );
    // The rounded corners and the grid's rounding of the bow position move the slip
    // fraction off beta: 0.104 measured on the same note (docs/papers-reproduced.md).
    assert!(
        (stats.slip_fraction - beta).abs() < 0.1 * beta,
        "slip fraction {} (beta {beta})",
        stats.slip_fraction
    );
    // 10 %: the playing-space map's Helmholtz criterion; sticking is exact in the model.
    assert!(
        (stats.stick_velocity_m_per_s - vb).abs() < 0.1 * vb,
        "sticking at {} m/s",
        stats.stick_velocity_m_per_s
    );
    // Channel 2 is the friction force, bounded by mu_s F_N = 0.4 N at the default 1 N.
    let peak = friction.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    // While slipping the friction is at least mu_d F_N = 0.2 N (paper A's 0.4 / 0.2);
    // 1e-6 N: the probe is f32.
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
        // Not blank: more than twice a blank white canvas of its size, drawn by the same
        // library (measured 124-766 KB against blanks of 13-40 KB; a cut-off file or an
        // empty chart comes near the blank's size).
        let (w, h) = (
            u32::from_be_bytes(bytes[16..20].try_into().unwrap()),
            u32::from_be_bytes(bytes[20..24].try_into().unwrap()),
        );
        let blank = blank_png_bytes(w, h);
        assert!(
            bytes.len() > 2 * blank,
            "{name}: {} bytes, a blank {w} x {h} canvas {blank}",
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

/// A two-note MIDI file (format 1, tempo in track 0, notes in track 1) as bytes.
fn two_note_midi() -> Vec<u8> {
    use midly::num::{u15, u24, u28, u4, u7};
    use midly::{
        Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind,
    };
    let ev = |delta: u32, kind| TrackEvent {
        delta: u28::new(delta),
        kind,
    };
    let note = |on: bool, key: u8| TrackEventKind::Midi {
        channel: u4::new(0),
        message: if on {
            MidiMessage::NoteOn {
                key: u7::new(key),
                vel: u7::new(80),
            }
        } else {
            MidiMessage::NoteOff {
                key: u7::new(key),
                vel: u7::new(0),
            }
        },
    };
    let mut smf = Smf::new(Header::new(
        Format::Parallel,
        Timing::Metrical(u15::new(480)),
    ));
    smf.tracks = vec![
        // 60 bpm: a beat is a second.
        vec![ev(
            0,
            TrackEventKind::Meta(MetaMessage::Tempo(u24::new(1_000_000))),
        )],
        vec![
            ev(0, note(true, 50)),
            ev(480, note(false, 50)),
            ev(0, note(true, 57)),
            ev(480, note(false, 57)),
        ],
    ];
    let mut bytes = Vec::new();
    smf.write_std(&mut bytes).unwrap();
    bytes
}

/// `colophony render --midi MIDI --out OUT` with `extra` arguments.
fn render_midi(midi: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        "--midi",
        midi.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    colophony(&args)
}

#[test]
fn a_midi_file_renders_its_notes_at_their_times() {
    let midi = scratch("two-notes.mid");
    std::fs::write(&midi, two_note_midi()).unwrap();
    let out = scratch("two-notes.wav");
    let run = render_midi(&midi, &out, &[]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut reader = hound::WavReader::open(&out).unwrap();
    let fs = reader.spec().sample_rate as f64;
    let x: Vec<f64> = match reader.spec().sample_format {
        hound::SampleFormat::Float => reader.samples::<f32>().map(|s| s.unwrap() as f64).collect(),
        hound::SampleFormat::Int => reader.samples::<i32>().map(|s| s.unwrap() as f64).collect(),
    };
    // Two seconds of notes, then the ring-out.
    assert!(x.len() as f64 >= 2.0 * fs, "{} frames", x.len());
    let peak = |a: f64, b: f64| {
        x[(a * fs) as usize..(b * fs) as usize]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    // Each second bows its note: D3 then A3 (the pitch within 50 cents of each).
    use colophony::analysis::{cents, peak_frequency_hz};
    for (from, note) in [(0.4, 50.0), (1.4, 57.0)] {
        assert!(peak(from, from + 0.5) > 0.0, "silent at {from} s");
        let w = &x[(from * fs) as usize..((from + 0.5) * fs) as usize];
        let f = peak_frequency_hz(w, fs, midi_to_hz(note), 50.0);
        let c = cents(f, midi_to_hz(note));
        println!("note {note} at {from} s: {c:+.1} cents");
        // 15 cents: the bowed pitch within a quarter second of a new note, before the
        // attack has settled (the tuning itself is tested in lab/tests/playing_space.rs).
        assert!(c.abs() < 15.0, "note {note}: {c:+.1} cents");
    }
}

#[test]
fn broken_or_missing_midi_files_fail_in_one_line_with_no_file() {
    let bad = scratch("bad.mid");
    std::fs::write(&bad, b"MThd\x00\x00\x00\x06\x00").unwrap();
    let missing = scratch("missing.mid");
    for midi in [bad, missing] {
        let out = scratch("never.wav");
        let run = render_midi(&midi, &out, &[]);
        let err = String::from_utf8_lossy(&run.stderr);
        println!("{}", err.trim());
        assert!(!run.status.success());
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!out.exists() && !out.with_extension("wav.partial").exists());
    }
    // A track without notes.
    let midi = scratch("tempo-only.mid");
    std::fs::write(&midi, two_note_midi()).unwrap();
    let out = scratch("never2.wav");
    let run = render_midi(&midi, &out, &["--track", "0"]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("track 0 has no notes"));
    assert!(!out.exists());
}

/// The samples of the renderer's 16-bit WAV, full scale 1.
fn wav_samples(path: &std::path::Path) -> Vec<f32> {
    let mut reader = hound::WavReader::open(path).unwrap();
    reader
        .samples::<i16>()
        .map(|s| s.unwrap() as f32 / 32767.0)
        .collect()
}

#[test]
fn a_chosen_bridge_plays_through_the_plugins_instruments() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let bridge = |name: &str| root.join("assets/bridges").join(name);
    // One note on a bridge file, with the model `friction` ("hyperbolic": a point law).
    let on_bridge = |friction: &str, file: &std::path::Path, out: &std::path::Path| {
        colophony(&[
            "render",
            "--friction",
            friction,
            "--instrument",
            "cello",
            "--note",
            "D3",
            "--seconds",
            "0.5",
            "--bridge",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let render = |file: &std::path::Path, out: &std::path::Path| on_bridge("thermal", file, out);
    // The shipped cello bridge's own file gives the bits the plugin's performer gives on
    // its shipped bridge (the same chain, the same data).
    let shipped = scratch("bridge-shipped.wav");
    let run = render(&bridge("cello-generic.json"), &shipped);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    use colophony_lab::midi_file::{perform, MidiEvent, Performance, Timed};
    // The renderer's defaults (in f64: the plugin's parameters are f32).
    let bow = colophony::dsp::vocabulary::BowControl {
        velocity_m_per_s: 0.1,
        force_n: 1.0,
        position_beta: 0.1,
    };
    let mut setup = colophony::params::ColophonyParams::default().setup();
    setup.point_law = None;
    setup.bow_position_beta = bow.position_beta;
    setup.bow_width_m = 0.01;
    let how = Performance {
        setup,
        bow,
        gain: 1.0,
        sample_rate_hz: 48_000.0,
        block: 512,
        bridge: None,
    };
    let events = [
        Timed {
            sample: 0,
            channel: 0,
            event: MidiEvent::NoteOn(50, 100),
        },
        Timed {
            sample: 24_000,
            channel: 0,
            event: MidiEvent::NoteOff(50),
        },
    ];
    let mut direct = perform(&events, &how, |_, _| {}).unwrap();
    direct.truncate(24_000);
    let from_file = wav_samples(&shipped);
    assert_eq!(from_file.len(), direct.len());
    // The file is 16-bit: every sample within half a step of the performer's (rounding).
    let step = 1.0 / 32767.0;
    let worst = from_file
        .iter()
        .zip(&direct)
        .fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst <= 0.5 * step + 1e-7, "{worst}");
    // -60 dBFS: a bowed note is far louder.
    assert!(from_file.iter().any(|x| x.abs() > 1e-3), "silent");
    // Another bridge (the violin's, on the cello) changes the sound.
    let other = scratch("bridge-violin.wav");
    let run = render(&bridge("violin-generic.json"), &other);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let x = wav_samples(&other);
    // -60 dBFS: a bowed note is far louder.
    assert!(x.iter().all(|v| v.is_finite()) && x.iter().any(|v| v.abs() > 1e-3));
    let differing = x
        .iter()
        .zip(&from_file)
        .filter(|(a, b)| (*a - *b).abs() > step)
        .count();
    // Measured 23888 of the 24000 samples; 1000 asks that the bridge changes the sound,
    // not by how much.
    assert!(differing > 1000, "only {differing} samples differ");
    // A point law plays the bridge's passive reduction as its body: the cello with the
    // violin's bridge sounds unlike the cello with its own, and both sound.
    let point = |file: &std::path::Path, out: &std::path::Path| on_bridge("hyperbolic", file, out);
    let (own, violin) = (
        scratch("point-bridge-own.wav"),
        scratch("point-bridge-violin.wav"),
    );
    for (file, out) in [
        ("cello-generic.json", &own),
        ("violin-generic.json", &violin),
    ] {
        let run = point(&bridge(file), out);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(
            String::from_utf8_lossy(&run.stdout).contains("point-bow cello on the given bridge"),
            "{}",
            String::from_utf8_lossy(&run.stdout)
        );
    }
    let (a, b) = (wav_samples(&own), wav_samples(&violin));
    // -60 dBFS: a bowed note is far louder.
    assert!(a.iter().any(|v| v.abs() > 1e-3) && b.iter().any(|v| v.abs() > 1e-3));
    let differing = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| (*x - *y).abs() > step)
        .count();
    // Measured 23684 of 24000; 1000, as above.
    assert!(differing > 1000, "only {differing} samples differ");
    // A broken bridge file or a missing one: one line, no file.
    let broken = scratch("broken-bridge.json");
    std::fs::write(
        &broken,
        r#"{"modes": [{"freq_hz": 100, "bandwidth_hz": -1, "gain": [[1]]}]}"#,
    )
    .unwrap();
    for args in [
        vec![
            "--friction",
            "thermal",
            "--bridge",
            broken.to_str().unwrap(),
        ],
        vec![
            "--friction",
            "thermal",
            "--bridge",
            "/nonexistent/bridge.json",
        ],
        vec!["--bridge", broken.to_str().unwrap()],
    ] {
        let out = scratch("bridge-error.wav");
        let mut all = vec!["render", "--out", out.to_str().unwrap()];
        all.extend(args.iter().copied());
        let run = colophony(&all);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} succeeded");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!out.exists(), "{args:?} left a file");
    }
}

#[test]
fn bench_peers_compares_with_stk_or_says_how_to_install_it() {
    let dir = scratch("peers-dir");
    let run = colophony(&[
        "bench",
        "peers",
        "--seconds",
        "0.2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    if run.status.success() {
        // Every row of the speed table, the strings with their ratio to STK (STK's own
        // is 1), paper B's scenes in % of a core, each with its goal and whether it is met:
        // the cello's goals at the plugin's quality, the reference quality's exact N_B beside
        // them.
        let (good, exact) = (
            colophony::quality::GOOD_NODES,
            colophony::quality::REFERENCE_NODES,
        );
        for row in [
            "| STK Bowed |".to_string(),
            "| hyperbolic string (default) |".into(),
            "| elasto-plastic, plugin tolerance |".into(),
            "| elasto-plastic, reference tolerance |".into(),
            format!("| thermal cello, plugin quality (N_B {good}), C bowed |"),
            format!("| thermal cello, plugin quality (N_B {good}), C+G |"),
            format!("| thermal cello N_B {exact} (reference quality), C bowed |"),
            format!("| thermal cello N_B {exact} (reference quality), C+G |"),
            "| thermal quartet, plugin quality |".into(),
            "| silence through the performer".into(),
        ] {
            assert!(stdout.contains(&row), "{row} missing from\n{stdout}");
        }
        assert!(stdout.contains("1.00x STK"), "{stdout}");
        assert!(stdout.contains("% of a core"), "{stdout}");
        assert_eq!(stdout.matches("| <= ").count(), 6, "six goals: {stdout}");
    } else {
        // No STK or g++ on this machine: one line that says how to get them.
        assert!(stderr.contains("install-peers.sh"), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}

/// The size of a blank white `w` x `h` PNG as the figures' plotting library writes it.
fn blank_png_bytes(w: u32, h: u32) -> usize {
    use plotters::prelude::*;
    let path = scratch(&format!("blank-{w}x{h}.png"));
    {
        let root = BitMapBackend::new(&path, (w, h)).into_drawing_area();
        root.fill(&WHITE).unwrap();
        root.present().unwrap();
    }
    std::fs::read(&path).unwrap().len()
}

#[test]
fn timing_prints_a_floor_whose_stretch_fits_inside_the_whole_render() {
    // `--timing` prints the fastest stretch's time a sample on standard error. A stretch
    // is [`FLOOR_STRETCH`] samples or more of the render itself, so its time cannot exceed
    // the whole render's (the `wrote` line's time, setup included). Comparing the floor with
    // the render's mean a sample instead would compare two timings of different work (the
    // mean takes in the release tail and the last partial stretch), which other load on a
    // shared machine can order either way.
    use colophony_lab::timing::FLOOR_STRETCH;
    let out = scratch("timing.wav");
    let run = colophony(&[
        "render",
        "--out",
        out.to_str().unwrap(),
        "--seconds",
        "1",
        "--timing",
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
    );
    assert!(run.status.success(), "{stderr}");
    let floor_ns = colophony_lab::timing::parse_floor(&stderr).expect("a floor line");
    let took_s: f64 = stdout
        .split(" s in ")
        .nth(1)
        .and_then(|rest| rest.split(" s,").next())
        .and_then(|t| t.parse().ok())
        .expect("the render's time");
    // The `wrote` line rounds the time to 1 ms: half of that is the reading's slack.
    let stretch_s = floor_ns * 1e-9 * FLOOR_STRETCH as f64;
    assert!(
        floor_ns.is_finite() && floor_ns > 0.0 && stretch_s <= took_s + 0.5e-3,
        "floor {floor_ns} ns a sample ({stretch_s} s a stretch) against {took_s} s for the render"
    );
}
