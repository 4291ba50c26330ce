//! Real-time ratios printed by `colophony bench ...` (run it from a release build:
//! `cargo run --release -- bench friction`). Ratios are measured in one run, side by side,
//! because absolute times on a shared machine are noisy; each case takes the best of three.

use crate::render::{render, render_rubbed, RenderSettings};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::rubbed::RubbedPreset;
use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
use std::time::Instant;

const SECONDS: f64 = 10.0;
const FS: f64 = 48_000.0;

fn best_of_three(run: impl FnMut()) -> f64 {
    best_of_runs(3, run)
}

/// The shortest wall time of `runs` calls, s.
fn best_of_runs(runs: usize, mut run: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            run();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::MAX, f64::min)
}

/// Paper A's cello D scene (v_b 0.1 m/s, F_N 1.1 N, beta 0.1), `SECONDS` at `fs`.
fn paper_a_cello_d(fs: f64) -> RenderSettings {
    RenderSettings {
        instrument: InstrumentKind::Cello,
        note: 50,
        seconds: SECONDS,
        bow: BowControl {
            velocity_m_per_s: 0.1,
            force_n: 1.1,
            position_beta: 0.1,
        },
        sample_rate_hz: fs,
        ..RenderSettings::default()
    }
}

/// A markdown table: each friction law on paper A's cello D scenario (v_b 0.1 m/s,
/// F_N 1.1 N, beta 0.1) and on the wine-glass preset, 10 s at 48 kHz: real-time ratio and
/// cost relative to the static curve.
pub fn friction_table() -> Result<String, String> {
    let mut lines = vec![
        format!("{SECONDS} s at {FS} Hz, best of three; ratio = audio time / wall time (one core)."),
        String::new(),
        "| friction law | cello D: x real time | cost vs static | violin A4: x real time | wine glass: x real time | cost vs static |".into(),
        "|---|---|---|---|---|---|".into(),
    ];
    let mut rows = Vec::new();
    for model in FrictionModel::ALL {
        let settings = RenderSettings {
            friction: model,
            ..paper_a_cello_d(FS)
        };
        let mut failure = None;
        let string_s = best_of_three(|| {
            if let Err(e) = render(&settings) {
                failure = Some(e.to_string());
            }
        });
        // The violin's strings run at twice the internal rate
        // (`InstrumentKind::point_oversampling`): its A string, the same bowing.
        let violin = RenderSettings {
            instrument: colophony::dsp::vocabulary::InstrumentKind::Violin,
            note: 69,
            ..settings.clone()
        };
        let violin_s = best_of_three(|| {
            if let Err(e) = render(&violin) {
                failure = Some(e.to_string());
            }
        });
        let glass_s = best_of_three(|| {
            if let Err(e) = render_rubbed(RubbedPreset::WineGlass, model, SECONDS, FS) {
                failure = Some(e.to_string());
            }
        });
        if let Some(e) = failure {
            return Err(e);
        }
        rows.push((model, string_s, violin_s, glass_s));
    }
    let static_row = rows
        .iter()
        .find(|r| r.0 == FrictionModel::Stribeck)
        .copied()
        .expect("the static law is benchmarked");
    for (model, string_s, violin_s, glass_s) in rows {
        lines.push(format!(
            "| {} | {:.0} | {:.2} | {:.0} | {:.0} | {:.2} |",
            model.name(),
            SECONDS / string_s,
            string_s / static_row.1,
            SECONDS / violin_s,
            SECONDS / glass_s,
            glass_s / static_row.3
        ));
    }
    lines.push(String::new());
    lines.extend(host_rate_rows()?);
    Ok(lines.join("\n"))
}

/// The default string (hyperbolic cello D, as above) at other host rates: the plugin's
/// strings at their internal rate resampled to the host rate, against the same strings
/// run at the host rate itself ([`RenderSettings::native_rate`]); x real time.
fn host_rate_rows() -> Result<Vec<String>, String> {
    let mut lines = vec![
        format!(
            "| host rate (kHz) | plugin ({} kHz inside, resampled): x real time | strings at the host rate: x real time |",
            colophony::dsp::vocabulary::INTERNAL_RATE_HZ / 1e3
        ),
        "|---|---|---|".into(),
    ];
    for fs in [44_100.0, 48_000.0, 96_000.0, 192_000.0] {
        let settings = |native_rate| RenderSettings {
            native_rate,
            ..paper_a_cello_d(fs)
        };
        let mut failure = None;
        let mut time = |native| {
            best_of_three(|| {
                if let Err(e) = render(&settings(native)) {
                    failure = Some(e.to_string());
                }
            })
        };
        let (plugin_s, native_s) = (time(false), time(true));
        if let Some(e) = failure {
            return Err(e);
        }
        lines.push(format!(
            "| {:.1} | {:.0} | {:.0} |",
            fs / 1000.0,
            SECONDS / plugin_s,
            SECONDS / native_s
        ));
    }
    Ok(lines)
}

/// Paper B's Table 1 on this machine: real-time cost (% of one core) of the whole cello
/// with the thermal bow per node count, beside the paper's (Intel P9400, plain C): four
/// strings with both polarisations coupled at the shipped generic bridge, the C string
/// bowed (paper B's Figure 6 bow), resampled to 48 kHz; and a double stop (C and G bowed).
pub fn table1() -> Result<String, String> {
    use crate::admittance_fit::shipped_bridge;
    let paper = [
        (3, 4.3),
        (6, 9.2),
        (10, 18.4),
        (20, 49.6),
        (33, 119.0),
        (60, 334.0),
    ];
    let bow = FIG6_BOW;
    let bridge = shipped_bridge(InstrumentKind::Cello).modes;
    let audio_s = 1.0;
    let mut lines = vec![
        format!("The plugin's thermal cello (4 strings x 2 polarisations, {}-mode bridge, resampled to 48 kHz), 1 s of audio after a 0.2 s onset, best of three, % of one core:", bridge.len()),
        String::new(),
        "| N_B | nodes C/G/D/A | internal rate (kHz) | C string bowed (%) | double stop C+G (%) | paper, C bowed, P9400 (%) |".to_string(),
        "|---|---|---|---|---|---|".to_string(),
    ];
    for (nodes, paper_percent) in paper {
        let (cost, cello) = thermal_cello_cost(nodes, &bridge, bow, audio_s)?;
        let n = cello.nodes_per_string();
        lines.push(format!(
            "| {nodes} | {}/{}/{}/{} | {:.1} | {:.1} | {:.1} | {paper_percent} |",
            n[0],
            n[1],
            n[2],
            n[3],
            cello.internal_rate_hz() / 1e3,
            100.0 * cost[0] / audio_s,
            100.0 * cost[1] / audio_s,
        ));
    }
    Ok(lines.join("\n"))
}

/// Paper B's Figure 6 bow: 0.15 m/s, beta 0.07, 300 N/m over 1 cm (3 N).
const FIG6_BOW: BowControl = BowControl {
    velocity_m_per_s: 0.15,
    force_n: 3.0,
    position_beta: 0.07,
};

/// Seconds of CPU for `audio_s` of the plugin's thermal cello at 48 kHz with `nodes` bow
/// nodes over 1 cm, after a 0.2 s onset, best of three: the C string bowed, and the
/// double stop C+G. Returns the instrument of the last run too.
fn thermal_cello_cost(
    nodes: usize,
    bridge: &[colophony::dsp::bridge::BridgeMode],
    bow: BowControl,
    audio_s: f64,
) -> Result<
    (
        [f64; 2],
        colophony::dsp::thermal_instrument::ThermalInstrument,
    ),
    String,
> {
    use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
    let out_rate = 48_000.0;
    let mut cost = [0.0; 2];
    let mut instrument = None;
    for (k, notes) in [&[36u8][..], &[36, 43][..]].iter().enumerate() {
        let mut cello = ThermalInstrument::new(
            InstrumentKind::Cello,
            bridge,
            out_rate,
            ThermalSettings {
                nodes,
                width_m: 0.01,
            },
        )?;
        for &note in *notes {
            cello.note_on(note);
        }
        let mut out = vec![0.0; (audio_s * out_rate) as usize];
        cello.process(bow, &mut out[..(0.2 * out_rate) as usize]);
        cost[k] = best_of_three(|| {
            cello.process(bow, &mut out);
            std::hint::black_box(&out);
        });
        instrument = Some(cello);
    }
    Ok((cost, instrument.expect("two runs")))
}

/// Seconds of CPU for `seconds` of the performer in the plugin's 512-sample blocks,
/// silent (every engine asleep: a silent block is skipped whole, `Performer::skip`) or
/// with cello D3 bowed; best of five, interleaved.
fn performer_silence_cost(seconds: f64) -> (f64, f64) {
    let fs = 48_000.0;
    let performer_run = |bowed: bool| {
        let setup = colophony::performer::Setup::default();
        let mut p = colophony::performer::Performer::new(InstrumentKind::Cello);
        p.activate(&setup, fs).expect("the default setup activates");
        p.configure(&setup);
        if bowed {
            p.note_on(50, 0.8);
        }
        let bow = BowControl::default();
        let mut out = vec![0.0f32; 512];
        let mut sum = 0.0f64;
        // Timed from here: building the engines is the host's activation, not playing.
        let start = std::time::Instant::now();
        for _ in 0..(seconds * fs) as usize / 512 {
            p.configure(&setup);
            if p.is_asleep() {
                p.skip(512, bow);
                out.fill(0.0);
            } else {
                for y in out.iter_mut() {
                    *y = p.tick(bow).audio as f32;
                }
            }
            sum += out[0] as f64;
        }
        let elapsed = start.elapsed().as_secs_f64();
        std::hint::black_box(sum);
        elapsed
    };
    let (mut silent_s, mut bowed_s) = (f64::MAX, f64::MAX);
    for _ in 0..5 {
        silent_s = silent_s.min(performer_run(false));
        bowed_s = bowed_s.min(performer_run(true));
    }
    (silent_s, bowed_s)
}

/// `colophony bench scenes`: the cost of common scenes with and without skipping what does
/// not sound (sleeping strings), and the error skipping introduces against computing
/// everything, from one run. Cello, defaults, 4 s at 48 kHz, blocks of 256.
pub fn scenes() -> Result<String, String> {
    use colophony::dsp::instrument::Instrument;
    let fs = 48_000.0;
    let seconds = 4.0;
    let s = |t: f64| (t * fs) as usize;
    type Score = Vec<(usize, bool, u8)>;
    let on = |t: usize, n: u8| (t, true, n);
    let off = |t: usize, n: u8| (t, false, n);
    let scenes: Vec<(&str, f64, Score)> = vec![
        ("silence", seconds, vec![]),
        ("one string bowed", seconds, vec![on(0, 50)]),
        (
            "one string decaying",
            seconds,
            vec![on(0, 50), off(s(0.5), 50)],
        ),
        ("double stop", seconds, vec![on(0, 50), on(0, 57)]),
        (
            "four-string chord ringing",
            seconds,
            vec![
                on(0, 36),
                on(0, 43),
                on(0, 50),
                on(0, 57),
                off(s(0.3), 36),
                off(s(0.3), 43),
                off(s(0.3), 50),
                off(s(0.3), 57),
            ],
        ),
        (
            "short phrase",
            seconds,
            vec![
                on(0, 50),
                off(s(0.5), 50),
                on(s(0.5), 52),
                off(s(1.0), 52),
                on(s(1.0), 57),
                off(s(1.6), 57),
                on(s(1.6), 62),
                off(s(2.2), 62),
            ],
        ),
        // Longer: the A string bowed briefly and rung out (the point-bow cello falls
        // silent within the 12 s; the thermal cello's polarisations start falling asleep
        // one by one near the end, and it sounds to about 20 s).
        (
            "a note rung out to silence",
            12.0,
            vec![on(0, 57), off(s(0.3), 57)],
        ),
    ];
    // The point-bow cello (paper A's hyperbolic law) and paper B's thermal cello (default
    // bow: 10 nodes over 1 cm).
    let bridge = crate::admittance_fit::shipped_bridge(InstrumentKind::Cello).modes;
    // Returns the output, the asleep share and the seconds spent playing (building the
    // instrument is the host's activation, not playing: untimed).
    let render =
        |score: &Score, skipping: bool, thermal: bool, frames: usize| -> (Vec<f64>, f64, f64) {
            if thermal {
                let inst = colophony::dsp::thermal_instrument::ThermalInstrument::new(
                    InstrumentKind::Cello,
                    &bridge,
                    fs,
                    Default::default(),
                )
                .expect("the shipped bridge and default bow are valid");
                play_scene(inst, score, skipping, frames)
            } else {
                play_scene(
                    Instrument::new(InstrumentKind::Cello, fs),
                    score,
                    skipping,
                    frames,
                )
            }
        };
    let mut lines = vec![
        format!("Cello, {seconds} s at 48 kHz (the last scene 12 s), interleaved runs, best of five; cost in % of one core of the scene's length."),
        String::new(),
        "| model | scene | computing everything (%) | skipping (%) | saving | asleep (% of string or polarisation time) | largest difference (dB below peak) |".to_string(),
        "|---|---|---|---|---|---|---|".to_string(),
    ];
    let mut costs = Vec::new();
    for thermal in [false, true] {
        let model = if thermal {
            "thermal (paper B)"
        } else {
            "point bow"
        };
        for (name, seconds, score) in &scenes {
            let mut full = Vec::new();
            let mut skipped = Vec::new();
            let mut asleep = 0.0;
            let frames = (seconds * fs) as usize;
            // Interleaved (full, skipping, full, ...) so a noisy spell on a shared machine
            // hits both; best of five each.
            let (mut full_s, mut skip_s) = (f64::MAX, f64::MAX);
            for _ in 0..5 {
                let (out, _, took) = render(score, false, thermal, frames);
                (full, full_s) = (out, full_s.min(took));
                let (out, share, took) = render(score, true, thermal, frames);
                (skipped, asleep, skip_s) = (out, share, skip_s.min(took));
            }
            let peak = full.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let diff = full
                .iter()
                .zip(&skipped)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let db = if diff == 0.0 {
                "identical".to_string()
            } else {
                format!("{:.0}", 20.0 * (diff / peak.max(1e-30)).log10())
            };
            lines.push(format!(
                "| {model} | {name} | {:.3} | {:.3} | {:.1}x | {:.0} | {db} |",
                100.0 * full_s / seconds,
                100.0 * skip_s / seconds,
                full_s / skip_s,
                100.0 * asleep
            ));
            if !thermal {
                costs.push(skip_s);
            }
        }
    }
    lines.push(String::new());
    lines.push(format!(
        "Silence costs {:.1} % of one bowed string (point bow, the engine alone in blocks of {BLOCK}).",
        100.0 * costs[0] / costs[1]
    ));
    // Through the performer in the plugin's blocks: a silent block with nothing landing
    // is skipped whole (`Performer::skip`).
    let (silent_s, bowed_s) = performer_silence_cost(seconds);
    lines.push(format!(
        "Through the performer in 512-sample blocks (as the plugin): silence {:.4} % of a core, one bowed string {:.3} %; silence costs {:.2} % of one bowed string.",
        100.0 * silent_s / seconds,
        100.0 * bowed_s / seconds,
        100.0 * silent_s / bowed_s
    ));
    Ok(lines.join("\n"))
}

/// Plays a score of `(sample, note down, note)` with the default bow, a block at a time
/// (generic, so `process` inlines as in the plugin); returns the output, the asleep share
/// and the seconds it took.
fn play_scene<I: SceneInstrument>(
    mut inst: I,
    score: &[(usize, bool, u8)],
    skipping: bool,
    frames: usize,
) -> (Vec<f64>, f64, f64) {
    inst.set_skipping(skipping);
    let bow = BowControl::default();
    let mut out = vec![0.0; frames];
    let start = Instant::now();
    let mut next = 0;
    let (mut asleep, mut blocks) = (0.0, 0.0f64);
    let mut i = 0;
    while i < frames {
        if i % BLOCK == 0 {
            inst.update_sleep();
            asleep += inst.asleep_share();
            blocks += 1.0;
        }
        while next < score.len() && score[next].0 == i {
            let (_, down, note) = score[next];
            if down {
                inst.note_on(note);
            } else {
                inst.note_off(note);
            }
            next += 1;
        }
        // As a host plays it: a block at a time, split where a note lands (an asleep
        // block is zeros without a per-sample call).
        let block_end = (i / BLOCK + 1) * BLOCK;
        let event = score.get(next).map_or(frames, |e| e.0);
        let end = block_end.min(event).min(frames).max(i + 1);
        inst.process(bow, &mut out[i..end]);
        i = end;
    }
    let took = start.elapsed().as_secs_f64();
    (out, asleep / blocks.max(1.0), took)
}

/// The block size `bench scenes` plays in (a common host buffer).
const BLOCK: usize = 256;

/// What `bench scenes` plays: both cellos, with sleeping on or off.
trait SceneInstrument {
    fn set_skipping(&mut self, skipping: bool);
    fn update_sleep(&mut self);
    fn note_on(&mut self, note: u8);
    fn note_off(&mut self, note: u8);
    /// `out.len()` samples with the bow held, no event between.
    fn process(&mut self, bow: BowControl, out: &mut [f64]);
    /// The share of the strings (point bow) or polarisations (thermal) asleep now.
    fn asleep_share(&self) -> f64;
}

macro_rules! scene_instrument {
    ($t:ty, $share:expr) => {
        impl SceneInstrument for $t {
            fn set_skipping(&mut self, skipping: bool) {
                <$t>::set_skipping(self, skipping)
            }
            fn update_sleep(&mut self) {
                <$t>::update_sleep(self)
            }
            fn note_on(&mut self, note: u8) {
                <$t>::note_on(self, note);
            }
            fn note_off(&mut self, note: u8) {
                <$t>::note_off(self, note)
            }
            fn process(&mut self, bow: BowControl, out: &mut [f64]) {
                <$t>::process(self, bow, out)
            }
            fn asleep_share(&self) -> f64 {
                $share(self)
            }
        }
    };
}

scene_instrument!(
    colophony::dsp::instrument::Instrument,
    |i: &colophony::dsp::instrument::Instrument| {
        1.0 - i.awake_strings() as f64 / colophony::dsp::vocabulary::STRINGS as f64
    }
);
scene_instrument!(
    colophony::dsp::thermal_instrument::ThermalInstrument,
    |i: &colophony::dsp::thermal_instrument::ThermalInstrument| {
        i.asleep_polarisations() as f64 / (2 * colophony::dsp::vocabulary::STRINGS) as f64
    }
);

/// CPU time (user + system, seconds) of the children this process has waited for.
#[cfg(unix)]
fn children_cpu_s() -> f64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    let t = |tv: libc::timeval| tv.tv_sec as f64 + tv.tv_usec as f64 * 1e-6;
    t(usage.ru_utime) + t(usage.ru_stime)
}

#[cfg(not(unix))]
fn children_cpu_s() -> f64 {
    0.0
}

/// Runs `cmd` to completion; its CPU time (user + system, s).
fn child_cpu_s(cmd: &mut std::process::Command, what: &str) -> Result<f64, String> {
    let before = children_cpu_s();
    crate::precision::peers::run_checked(cmd, what)?;
    Ok(children_cpu_s() - before)
}

/// `colophony bench peers`: Colophony against its peers (STK's `Bowed`, Faust). Whole processes each render `seconds`
/// of cello D3 at 48 kHz to a file: this binary's `render` with the hyperbolic (default)
/// and the elasto-plastic string (paper A), and STK's `stk::Bowed` at 146.8 Hz
/// (`assets/peers/stk_bowed.cpp`, one render per process, raw f32 out, built with g++ -O2
/// against libstk-dev: `scripts/install-peers.sh` installs it). User + system CPU of each
/// process, best of three, the three interleaved in each round so load on a shared machine
/// hits them alike. Prints each one's CPU seconds and its ratio to STK's. Unix only (the
/// children's CPU time comes from getrusage).
pub fn peers(seconds: f64, dir: &std::path::Path) -> Result<String, String> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(format!("--seconds must be within 0..=3600, got {seconds}"));
    }
    if !cfg!(unix) {
        return Err("bench peers measures child CPU time with getrusage: Unix only".into());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let stk = crate::precision::peers::build_stk(dir).map_err(|e| {
        format!("{e} (STK is needed: scripts/install-peers.sh, or apt-get install libstk-dev g++)")
    })?;
    let me = std::env::current_exe().map_err(|e| e.to_string())?;
    let secs = format!("{seconds}");
    let d3_hz = format!("{}", colophony::dsp::vocabulary::midi_to_hz(50.0));
    // `quality`: a solver preset (its Newton tolerance); without one, `render` solves the
    // bristle laws to the reference's tolerance as well, the precision bench's setting.
    let ours = |friction: &str, quality: Option<&str>| {
        let mut c = std::process::Command::new(&me);
        c.args([
            "render",
            "--note",
            "D3",
            "--seconds",
            &secs,
            "--friction",
            friction,
        ]);
        if let Some(q) = quality {
            c.args(["--quality", q]);
        }
        c.arg("--out")
            .arg(dir.join(format!("{friction}-{}.wav", quality.unwrap_or("default"))));
        c
    };
    let mut rows: Vec<(&str, std::process::Command)> = vec![
        ("STK Bowed", {
            let mut c = std::process::Command::new(&stk);
            c.args([secs.as_str(), "48000", d3_hz.as_str()])
                .arg(dir.join("stk.f32"))
                .arg("1");
            c
        }),
        ("hyperbolic string (default)", ours("hyperbolic", None)),
        (
            "elasto-plastic string (paper A)",
            ours("elasto-plastic", None),
        ),
        // The plugin solves to the good preset's tolerance (1e-4 m/s, src/quality.rs; its
        // error is in docs/precision.md): what the plugin's elasto-plastic string costs.
        (
            "elasto-plastic, plugin tolerance",
            ours("elasto-plastic", Some("good")),
        ),
    ];
    let mut best = vec![f64::INFINITY; rows.len()];
    for _round in 0..3 {
        for (i, (name, cmd)) in rows.iter_mut().enumerate() {
            best[i] = best[i].min(child_cpu_s(cmd, name)?);
        }
    }
    let mut lines = vec![format!(
        "{seconds} s of cello D3 at 48 kHz to a file, whole process, user + system CPU, best of 3 (interleaved)"
    )];
    for ((name, _), cpu) in rows.iter().zip(&best) {
        lines.push(format!(
            "{name:<32} {cpu:8.3} s  {:6.1}x real time  {:5.2}x STK",
            seconds / cpu,
            cpu / best[0]
        ));
    }
    // The comparison table, from this run: the two strings against STK above, silence
    // through the performer, and paper B's whole cello at N_B = 60 (`bench scenes` and
    // `bench table1` measure the same).
    let (silent_s, bowed_s) = performer_silence_cost(4.0);
    let bridge = crate::admittance_fit::shipped_bridge(InstrumentKind::Cello).modes;
    let (table1, _) = thermal_cello_cost(60, &bridge, FIG6_BOW, 1.0)?;
    let goals = [
        (
            "hyperbolic string (default)",
            best[1] / best[0],
            "x STK",
            0.8,
        ),
        (
            "elasto-plastic string (paper A)",
            best[2] / best[0],
            "x STK",
            3.0,
        ),
        (
            "silence, % of one bowed string",
            100.0 * silent_s / bowed_s,
            "%",
            1.0,
        ),
        (
            "thermal cello N_B 60, C bowed",
            100.0 * table1[0],
            "% of a core",
            10.0,
        ),
        (
            "double stop C+G at N_B 60",
            100.0 * table1[1],
            "% of a core",
            15.0,
        ),
    ];
    lines.push(String::new());
    lines.push("| what | measured | goal | met |".into());
    lines.push("|---|---|---|---|".into());
    for (what, value, unit, goal) in goals {
        lines.push(format!(
            "| {what} | {value:.2} {unit} | <= {goal} | {} |",
            if value <= goal { "yes" } else { "no" }
        ));
    }
    Ok(lines.join("\n"))
}
