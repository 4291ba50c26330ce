//! The plugin through its VST3 wrapper, in the headless VST3 host of `tests/vst3_host/`:
//! the library is the tests' build with `assert_process_allocs` (the same code as
//! `Colophony.vst3`), so any allocation on the audio thread aborts these tests, in VST3
//! as in CLAP.
//!
//! nice-plug's logger is sent to a file (`NICE_LOG`, read once per process when the
//! library is first loaded) so that the wrapper's "event buffer filled up! This will
//! cause an allocation." warnings, which it allocates for under `permit_alloc` where the
//! allocation check cannot see it, fail the tests too.

#[allow(dead_code)]
mod host;
#[allow(dead_code)]
mod vst3_host;

use std::path::PathBuf;
use std::sync::OnceLock;

use colophony::analysis::{cents, peak_frequency_hz, rms};
use host::{channel_f64, first_unsafe_sample, test_plugin_path, Event, HostedPlugin, Score};
use vst3_host::Vst3Plugin;

/// Every test loads through here, so the log goes to the file before the first load.
fn load() -> Vst3Plugin {
    let _ = log_path();
    Vst3Plugin::load(test_plugin_path())
}

fn log_path() -> &'static PathBuf {
    static LOG: OnceLock<PathBuf> = OnceLock::new();
    LOG.get_or_init(|| {
        let log = std::env::temp_dir().join(format!("colophony-vst3-{}.log", std::process::id()));
        let _ = std::fs::remove_file(&log);
        std::env::set_var("NICE_LOG", &log);
        log
    })
}

fn assert_no_event_overflow() {
    let logged = std::fs::read_to_string(log_path()).unwrap_or_default();
    assert!(
        !logged.contains("filled up"),
        "the VST3 wrapper overflowed an event buffer (and allocated):\n{logged}"
    );
}

fn d3_hz() -> f64 {
    440.0 * 2f64.powf((50.0 - 69.0) / 12.0)
}

/// A bowed D3 with the bow velocity and force automated at sample positions that do not
/// fall on block boundaries, released at 1 s.
fn automated_score(clap: &mut HostedPlugin, sample_rate: f64) -> Score {
    let at = |s: f64| (s * sample_rate) as u64;
    let mut score = Score::new().at(0, Event::note_on(50));
    for (i, t) in [0.2, 0.35, 0.5, 0.65].into_iter().enumerate() {
        score.push(
            at(t) + 7,
            clap.plain("Bow Velocity", 0.08 + 0.02 * i as f64),
        );
        score.push(at(t) + 131, clap.plain("Bow Force", 0.9 + 0.1 * i as f64));
    }
    // A note expression through each format's own event: the brightness moves the bow
    // position of the note's string (VST3's kBrightnessTypeID, CLAP's brightness).
    score.push(
        at(0.3) + 19,
        Event::Brightness {
            key: 50,
            value: 0.8,
        },
    );
    score.push(at(1.0), Event::note_off(50));
    score
}

#[test]
fn the_vst3_wrapper_plays_the_same_samples_as_the_clap_wrapper() {
    // Both wrappers hand the plugin the same notes and parameter changes at the same
    // samples (sample-accurate automation splits the block at each change in both), and
    // the plugin is deterministic: the two formats must give the same bits. Checked at
    // the internal rate, at a resampled rate, and with 1-frame blocks.
    let mut vst3 = load();
    let mut clap = HostedPlugin::load(test_plugin_path());
    for (sample_rate, block) in [(48_000.0, 512), (44_100.0, 333), (96_000.0, 1)] {
        let frames = (1.3 * sample_rate) as usize;
        let seconds = if block == 1 { 0.4 } else { 1.3 };
        let frames = frames.min((seconds * sample_rate) as usize);
        clap.activate(sample_rate, block.max(64));
        vst3.activate(sample_rate, block.max(64));
        let mut score = automated_score(&mut clap, sample_rate);
        if block == 1 {
            // A short render: only the events inside it.
            let kept: Vec<_> = score
                .events()
                .iter()
                .copied()
                .filter(|(t, _)| (*t as usize) < frames)
                .collect();
            score = Score::new();
            for (t, e) in kept {
                score.push(t, e);
            }
        }
        let a = clap.render(frames, block, &score);
        let b = vst3.render(frames, block, &score);
        assert!(
            b.iter().flatten().all(|x| x.is_finite()),
            "{sample_rate} Hz: not finite"
        );
        let first_difference = a[0]
            .iter()
            .zip(&b[0])
            .position(|(x, y)| x.to_bits() != y.to_bits());
        assert_eq!(
            first_difference,
            None,
            "{sample_rate} Hz, blocks of {block}: the formats differ (CLAP, VST3 at the first \
             difference: {:?})",
            first_difference.map(|i| (a[0][i], b[0][i]))
        );
        assert_eq!(a[1], b[1], "{sample_rate} Hz: right channel");
        let left = channel_f64(&b, 0);
        // -80 dBFS: a sounding note is far louder (the golden renders' RMS is 0.13-0.24 on
        // the strings).
        assert!(rms(&left) > 1e-4, "{sample_rate} Hz: the note is silent");
        if block > 1 {
            // The note plays at its pitch (a quarter tone: the test is of the format,
            // the intonation has its own tests), between the automation points.
            let from = (0.7 * sample_rate) as usize;
            let to = (0.98 * sample_rate) as usize;
            let f = peak_frequency_hz(&left[from..to], sample_rate, d3_hz(), 100.0);
            let c = cents(f, d3_hz());
            assert!(c.abs() < 50.0, "{sample_rate} Hz: D3 at {c:+.1} cents");
        }
    }
    assert_no_event_overflow();
}

#[test]
fn a_vst3_host_lists_only_the_instruments_own_parameters_as_automatable() {
    // The wrapper's 16 x 130 MIDI parameters are there for the host to send controllers
    // through, hidden and read-only; a DAW's automation list shows the rest, which must
    // be the parameters the CLAP host sees, by name.
    let vst3 = load();
    let clap = HostedPlugin::load(test_plugin_path());
    let mut visible: Vec<&str> = vst3
        .params()
        .iter()
        .filter(|p| !p.hidden())
        .map(|p| p.title.as_str())
        .collect();
    let mut own: Vec<&str> = clap.params().iter().map(|p| p.name.as_str()).collect();
    visible.sort_unstable();
    own.sort_unstable();
    assert_eq!(visible, own);
    let hidden: Vec<_> = vst3.params().iter().filter(|p| p.hidden()).collect();
    assert_eq!(hidden.len(), 16 * 130, "the MIDI parameters");
    assert!(hidden.iter().all(|p| !p.automatable()));
    assert!(vst3
        .params()
        .iter()
        .filter(|p| !p.hidden())
        .all(|p| p.automatable()));
}

#[test]
fn a_daws_flush_of_every_midi_controller_through_vst3_neither_overflows_nor_allocates() {
    // A DAW that restores or chases controllers sends a point on every one of the
    // wrapper's 2080 MIDI parameters at once: in a stopped transport's parameter flush
    // (a zero-sample process call), and in a playing block with a note and our own
    // automation. The wrapper turns each point into an event in buffers reserved at load
    // (`Plugin::INPUT_EVENT_CAPACITY`); overflowing them allocates on the audio thread
    // (with the wrapper's default capacity, Ardour logs it four times in 6 s).
    const BLOCK: usize = 512;
    let mut vst3 = load();
    let mut clap = HostedPlugin::load(test_plugin_path());
    for sample_rate in [44_100.0, 48_000.0] {
        vst3.activate(sample_rate, BLOCK);
        clap.activate(sample_rate, BLOCK);
        let every_controller = |at: u64, score: &mut Score| {
            for channel in 0..16u8 {
                for cc in 0..130u32 {
                    // Neutral values: controllers at rest, pressure 0, bend centred.
                    let value = match cc {
                        7 | 11 => 127,
                        129 => 64,
                        _ => 0,
                    };
                    let midi = match cc {
                        0..=127 => [0xb0 | channel, cc as u8, value],
                        128 => [0xd0 | channel, 0, 0],
                        _ => [0xe0 | channel, 0, value],
                    };
                    score.push(at, Event::Midi(midi));
                }
            }
        };
        let mut flush = Score::new();
        every_controller(0, &mut flush);
        vst3.flush(&flush);
        let mut score = Score::new().at(0, Event::note_on(50));
        for block in [1u64, 3] {
            every_controller(block * BLOCK as u64 + 17, &mut score);
            for i in 0..64u64 {
                score.push(
                    block * BLOCK as u64 + i * 8,
                    clap.plain("Bow Velocity", 0.1 + 0.0005 * i as f64),
                );
            }
        }
        let out = vst3.render(8 * BLOCK, BLOCK, &score);
        assert!(out.iter().flatten().all(|x| x.is_finite()));
        // -80 dBFS: a sounding note is far louder (the golden renders' RMS is 0.13-0.24 on
        // the strings).
        assert!(
            rms(&channel_f64(&out, 0)[4 * BLOCK..]) > 1e-4,
            "{sample_rate} Hz: the note sounded through the flushes"
        );
    }
    assert_no_event_overflow();
}

#[test]
fn the_vst3_host_reads_the_resamplers_latency_at_every_rate() {
    let mut vst3 = load();
    let mut clap = HostedPlugin::load(test_plugin_path());
    for sample_rate in [44_100.0, 48_000.0, 96_000.0, 192_000.0] {
        vst3.activate(sample_rate, 256);
        clap.activate(sample_rate, 256);
        assert_eq!(vst3.latency(), clap.latency(), "{sample_rate} Hz");
    }
    assert_no_event_overflow();
}

#[test]
fn a_vst3_project_keeps_its_state_and_reopens_the_clap_fixtures() {
    // A host saves the project through VST3 after automation and reopens it in a new
    // instance: every parameter reads the same and the same notes give the same bits.
    // The state fixture saved through CLAP (the same JSON, without CLAP's length prefix)
    // opens through VST3 with every value CLAP shows.
    let mut clap = HostedPlugin::load(test_plugin_path());
    clap.activate(48_000.0, 256);
    let mut first = load();
    first.activate(48_000.0, 256);
    let setup = Score::new()
        .at(0, clap.text("Instrument", "Violin"))
        .at(0, clap.plain("Bow Force", 0.7))
        .at(0, clap.plain("Bow Velocity", -0.15))
        .at(0, clap.text("Friction Model", "Static (Stribeck)"))
        .at(0, clap.plain("Reference Pitch", 442.0));
    first.render(256, 256, &setup);
    let saved = first.save_state();
    assert!(!saved.is_empty());
    let visible: Vec<String> = first
        .params()
        .iter()
        .filter(|p| !p.hidden())
        .map(|p| p.title.clone())
        .collect();
    let mut second = load();
    second
        .load_state(&saved)
        .expect("the plugin refused its own state");
    second.activate(48_000.0, 256);
    for title in &visible {
        assert_eq!(second.value_text(title), first.value_text(title), "{title}");
    }
    assert_eq!(second.value_text("Instrument"), "Violin");
    first.activate(48_000.0, 256);
    let notes = Score::new()
        .at(0, Event::note_on(69))
        .at(14_400, Event::note_off(69));
    let a = first.render(24_000, 256, &notes);
    let b = second.render(24_000, 256, &notes);
    // -60 dBFS: a default note peaks near -12 dBFS.
    assert!(
        rms(&channel_f64(&a, 0)) > 1e-3,
        "the restored patch is silent"
    );
    assert_eq!(a, b, "the reopened project renders differently");
    // A broken state is refused and nothing is lost.
    assert!(second.load_state(b"{ not a state").is_err());
    assert_eq!(second.value_text("Instrument"), "Violin");

    let fixture =
        std::fs::read(host::workspace_root().join("tests/fixtures/state/v1-full.state")).unwrap();
    let reopened = load();
    reopened
        .load_state(&fixture[8..])
        .expect("the fixture refused through VST3");
    clap.load_state(&fixture).unwrap();
    for title in &visible {
        let value = clap.clap_value(title);
        let clap_text = clap.clap_to_text(title, value);
        // VST3 hosts show the unit apart (ParameterInfo::units); CLAP's text carries it.
        let vst3_text = reopened.value_text(title);
        assert!(
            clap_text == vst3_text || clap_text.starts_with(&format!("{vst3_text} ")),
            "{title}: VST3 {vst3_text:?}, CLAP {clap_text:?}"
        );
    }
    assert_no_event_overflow();
}

#[test]
fn vst3_activates_and_plays_finite_at_extreme_rates_and_block_sizes() {
    // A host may run at 8 or 384 kHz and hand blocks of one frame: activation succeeds,
    // every sample is finite and not subnormal (clap-validator's rule), below full scale.
    let mut vst3 = load();
    for (sample_rate, block) in [
        (8_000.0, 1),
        (8_000.0, 4096),
        (384_000.0, 4096),
        (384_000.0, 7),
    ] {
        vst3.activate(sample_rate, block);
        let at = |t: f64| (t * sample_rate) as u64;
        let score = Score::new()
            .at(0, Event::note_on(50))
            .at(at(0.05), Event::note_on(81))
            .at(at(0.2), Event::note_off(50))
            .at(at(0.2), Event::note_off(81));
        let out = vst3.render(at(0.3) as usize, block, &score);
        let bad = first_unsafe_sample(&out);
        assert_eq!(bad, None, "{sample_rate} Hz, blocks of {block}");
        assert!(
            out.iter().flatten().all(|x| x.abs() < 1.0),
            "{sample_rate} Hz: full scale"
        );
    }
    assert_no_event_overflow();
}
