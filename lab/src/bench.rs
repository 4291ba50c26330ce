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
        format!(
            "The plugin's thermal cello (4 strings x 2 polarisations, {}-mode bridge, resampled to \
             48 kHz), {audio_s} s of audio a round after a 0.2 s onset, {TABLE1_ROUNDS} rounds with \
             every row and scene interleaved in each, % of one core: the best round, its spread \
             (worst / best - 1) and the floor (the fastest stretch of {} samples over the rounds, \
             which other load on the machine cannot raise; lab/src/timing.rs), and where valgrind \
             is installed the instructions a 48 kHz sample (callgrind, 0.5 s against 0.25 s):",
            bridge.len(),
            crate::timing::FLOOR_STRETCH
        ),
        String::new(),
        "| N_B | nodes C/G/D/A | internal rate (kHz) | C string bowed (%) | spread | floor (%) | instructions a sample | double stop C+G (%) | spread | floor (%) | instructions a sample | paper, C bowed, P9400 (%) |".to_string(),
        "|---|---|---|---|---|---|---|---|---|---|---|---|".to_string(),
    ];
    let mut scenes = Vec::new();
    for (nodes, _) in paper {
        scenes.push(thermal_cello_scenes(nodes, &bridge, bow)?);
    }
    // Each scene's time a round, s, and its floor, s a sample.
    let mut times = vec![[const { Vec::new() }; 2]; scenes.len()];
    let mut floors = vec![[f64::INFINITY; 2]; scenes.len()];
    let samples = (audio_s * TABLE1_RATE_HZ) as usize;
    let mut out = vec![0.0; TABLE1_BLOCK];
    for _round in 0..TABLE1_ROUNDS {
        for ((pair, t), f) in scenes.iter_mut().zip(&mut times).zip(&mut floors) {
            for (k, cello) in pair.iter_mut().enumerate() {
                let mut floor = crate::timing::Floor::new();
                let start = Instant::now();
                for _ in 0..samples / TABLE1_BLOCK {
                    cello.process(bow, &mut out);
                    std::hint::black_box(&out);
                    floor.advance(TABLE1_BLOCK);
                }
                t[k].push(start.elapsed().as_secs_f64());
                f[k] = f[k].min(floor.ns_per_sample().unwrap_or(f64::INFINITY) * 1e-9);
            }
        }
    }
    // Instructions a 48 kHz sample of each scene where valgrind is installed: callgrind on
    // `bench peer-scene:cello-c@N` (and `cello-cg@N`) for 0.25 s and 0.5 s, their
    // difference (the setup and the attack cancel).
    let me = std::env::current_exe().map_err(|e| e.to_string())?;
    let with_valgrind = valgrind_available();
    let instructions = |nodes: usize, k: usize| -> String {
        if !with_valgrind {
            return "-".into();
        }
        let scene = format!("peer-scene:{}@{nodes}", ["cello-c", "cello-cg"][k]);
        let command = |secs: f64| {
            let mut c = std::process::Command::new(&me);
            c.args(["bench", &scene, "--seconds", &format!("{secs}")]);
            c
        };
        instructions_per_sample(&command, 0.25, 0.5, &scene)
            .map_or("-".into(), |i| format!("{i:.0}"))
    };
    let percent = |s: f64| 100.0 * s / audio_s;
    for (((nodes, paper_percent), pair), (t, f)) in
        paper.iter().zip(&scenes).zip(times.iter().zip(&floors))
    {
        let n = pair[0].nodes_per_string();
        let cell = |k: usize| {
            let best = t[k].iter().copied().fold(f64::INFINITY, f64::min);
            let worst = t[k].iter().copied().fold(0.0, f64::max);
            format!(
                "{:.1} | {:.0} % | {:.1} | {}",
                percent(best),
                100.0 * (worst / best - 1.0),
                100.0 * f[k] * TABLE1_RATE_HZ,
                instructions(*nodes, k)
            )
        };
        lines.push(format!(
            "| {nodes} | {}/{}/{}/{} | {:.1} | {} | {} | {paper_percent} |",
            n[0],
            n[1],
            n[2],
            n[3],
            pair[0].internal_rate_hz() / 1e3,
            cell(0),
            cell(1),
        ));
    }
    Ok(lines.join("\n"))
}

/// Rounds of [`table1`]: every row and scene is timed this many times, interleaved.
const TABLE1_ROUNDS: usize = 5;
/// [`table1`]'s output rate, Hz, and the block it processes.
const TABLE1_RATE_HZ: f64 = 48_000.0;
const TABLE1_BLOCK: usize = 512;

/// The plugin's thermal cello at 48 kHz with `nodes` bow nodes over 1 cm bowed with
/// `bow` for a 0.2 s onset: the C string alone, and the double stop C+G.
fn thermal_cello_scenes(
    nodes: usize,
    bridge: &[colophony::dsp::bridge::BridgeMode],
    bow: BowControl,
) -> Result<[colophony::dsp::thermal_instrument::ThermalInstrument; 2], String> {
    use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
    let scene = |notes: &[u8]| -> Result<ThermalInstrument, String> {
        let mut cello = ThermalInstrument::new(
            InstrumentKind::Cello,
            bridge,
            TABLE1_RATE_HZ,
            ThermalSettings {
                nodes,
                width_m: 0.01,
            },
        )?;
        for &note in notes {
            cello.note_on(note);
        }
        let mut onset = vec![0.0; (0.2 * TABLE1_RATE_HZ) as usize];
        cello.process(bow, &mut onset);
        Ok(cello)
    };
    Ok([scene(&[36])?, scene(&[36, 43])?])
}

/// Paper B's Figure 6 bow: 0.15 m/s, beta 0.07, 300 N/m over 1 cm (3 N).
const FIG6_BOW: BowControl = BowControl {
    velocity_m_per_s: 0.15,
    force_n: 3.0,
    position_beta: 0.07,
};

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

/// Runs `cmd` to completion; its CPU time (user + system, s) and the timing floor it
/// printed on standard error ([`crate::timing`], ns a sample), if it printed one.
fn child_cpu_and_floor(
    cmd: &mut std::process::Command,
    what: &str,
) -> Result<(f64, Option<f64>), String> {
    let before = children_cpu_s();
    let (_, stderr) = crate::precision::peers::run_checked_both(cmd, what)?;
    Ok((
        children_cpu_s() - before,
        crate::timing::parse_floor(&stderr),
    ))
}

/// Rounds of [`peers`]: every process runs this many times, interleaved.
const PEER_ROUNDS: usize = 5;

/// What a [`peers`] row's CPU time is measured against.
#[derive(Clone, Copy, PartialEq)]
enum PeerMeasure {
    /// STK's CPU time in the same round (a point-bow string's whole process).
    TimesStk,
    /// The audio's length: % of one core (paper B's scenes).
    PercentOfCore,
}

/// One whole process [`peers`] times: a command for `seconds` of audio.
struct PeerRow {
    name: String,
    /// Seconds of audio the timed process renders.
    seconds: f64,
    measure: PeerMeasure,
    /// The most the measure may be, if the row has a goal.
    goal: Option<f64>,
    command: Box<dyn Fn(f64) -> std::process::Command>,
}

/// `colophony bench peers`: Colophony against its peers and its speed goals, whole
/// processes timed in one run. Each row is a separate process rendering cello D3 at
/// 48 kHz (or a scene of paper B's instrument, through `bench peer-scene:NAME`): STK's
/// `stk::Bowed` at 146.8 Hz (`assets/peers/stk_bowed.cpp`, built with g++ -O2 against
/// libstk-dev: `scripts/install-peers.sh` installs it), this binary's `render` with the
/// hyperbolic string (the default) and with the elasto-plastic string at the plugin's
/// tolerance (the good preset's) and at the reference's, paper B's cello (its Figure 6
/// bow) at the plugin's default quality (the good preset's node count) and at the exact
/// `N_B` of the reference quality, and a quartet of thermal instruments. User + system
/// CPU of each process, `PEER_ROUNDS` rounds with
/// the rows interleaved in each, so load on a shared machine hits them alike; the best,
/// the spread (worst over best) and, against STK, the ratio of the bests and its range
/// over the rounds. Where valgrind is installed, instructions per output sample beside
/// them (callgrind, the difference of two render lengths: setup cancels). Then silence
/// through the performer, timed in-process. Unix only (children's CPU from getrusage).
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
    let d3_hz = format!("{}", colophony::dsp::vocabulary::midi_to_hz(50.0));
    let render_row = |name: &str, friction: &'static str, quality: Option<&'static str>, goal| {
        let (me, dir) = (me.clone(), dir.to_path_buf());
        PeerRow {
            name: name.into(),
            seconds,
            measure: PeerMeasure::TimesStk,
            goal,
            command: Box::new(move |secs: f64| {
                let mut c = std::process::Command::new(&me);
                c.args(["render", "--note", "D3", "--friction", friction, "--timing"])
                    .args(["--seconds", &format!("{secs}")]);
                if let Some(q) = quality {
                    c.args(["--quality", q]);
                }
                c.arg("--out")
                    .arg(dir.join(format!("{friction}-{}.wav", quality.unwrap_or("reference"))));
                c
            }),
        }
    };
    // Paper B's scenes cost tens of times a point-bow string: a tenth of the audio.
    let scene_row = |name: String, scene: String, goal| {
        let me = me.clone();
        PeerRow {
            name,
            seconds: (seconds / 10.0).max(0.1),
            measure: PeerMeasure::PercentOfCore,
            goal,
            command: Box::new(move |secs: f64| {
                let mut c = std::process::Command::new(&me);
                c.args(["bench", &format!("peer-scene:{scene}")])
                    .args(["--seconds", &format!("{secs}")]);
                c
            }),
        }
    };
    let node_count = |q: colophony::quality::Quality| {
        q.fixed_thermal_nodes()
            .expect("the good and reference presets fix their node counts")
    };
    let good = node_count(colophony::quality::Quality::Good);
    let exact = node_count(colophony::quality::Quality::Reference);
    let rows = vec![
        PeerRow {
            name: "STK Bowed".into(),
            seconds,
            measure: PeerMeasure::TimesStk,
            goal: None,
            command: Box::new({
                let (stk, dir, d3_hz) = (stk.clone(), dir.to_path_buf(), d3_hz.clone());
                move |secs: f64| {
                    let mut c = std::process::Command::new(&stk);
                    c.args([format!("{secs}").as_str(), "48000", d3_hz.as_str()])
                        .arg(dir.join("stk.f32"))
                        .arg("1");
                    c
                }
            }),
        },
        render_row("hyperbolic string (default)", "hyperbolic", None, Some(0.5)),
        // The plugin solves to the good preset's tolerance (1e-4 m/s, src/quality.rs; its
        // error is in docs/precision.md): what the plugin's elasto-plastic string costs.
        render_row(
            "elasto-plastic, plugin tolerance",
            "elasto-plastic",
            Some("good"),
            Some(1.5),
        ),
        render_row(
            "elasto-plastic, reference tolerance",
            "elasto-plastic",
            None,
            None,
        ),
        // Paper B's cello (its Figure 6 bow, 1 cm) at the plugin's default quality: the
        // good preset's node count, whose error against the reference quality's exact
        // N_B the precision bench gives (docs/precision.md); the exact N_B beside it.
        scene_row(
            format!("thermal cello, plugin quality (N_B {good}), C bowed"),
            format!("cello-c@{good}"),
            Some(3.0),
        ),
        scene_row(
            format!("thermal cello, plugin quality (N_B {good}), C+G"),
            format!("cello-cg@{good}"),
            Some(5.0),
        ),
        scene_row(
            format!("thermal cello N_B {exact} (reference quality), C bowed"),
            format!("cello-c@{exact}"),
            None,
        ),
        scene_row(
            format!("thermal cello N_B {exact} (reference quality), C+G"),
            format!("cello-cg@{exact}"),
            None,
        ),
        scene_row(
            "thermal quartet, plugin quality".into(),
            "quartet".into(),
            Some(15.0),
        ),
    ];
    let mut cpu = vec![Vec::with_capacity(PEER_ROUNDS); rows.len()];
    // Each row's timing floor over the rounds, ns a 48 kHz sample.
    let mut floors = vec![f64::INFINITY; rows.len()];
    for _round in 0..PEER_ROUNDS {
        for ((row, times), floor) in rows.iter().zip(&mut cpu).zip(&mut floors) {
            let (t, f) = child_cpu_and_floor(&mut (row.command)(row.seconds), &row.name)?;
            times.push(t);
            *floor = floor.min(f.unwrap_or(f64::INFINITY));
        }
    }
    let instructions: Vec<Option<f64>> = if valgrind_available() {
        rows.iter()
            .map(|row| {
                // Long enough that the difference is the steady sound, short enough for
                // valgrind (about 50 times slower): 2 s and 4 s of a point-bow string,
                // 0.25 s and 0.5 s of paper B's scenes, less for a short run.
                let short = (0.5 * row.seconds).min(match row.measure {
                    PeerMeasure::TimesStk => 2.0,
                    PeerMeasure::PercentOfCore => 0.25,
                });
                instructions_per_sample(&*row.command, short, 2.0 * short, &row.name).ok()
            })
            .collect()
    } else {
        vec![None; rows.len()]
    };
    let best = |t: &[f64]| t.iter().copied().fold(f64::INFINITY, f64::min);
    let worst = |t: &[f64]| t.iter().copied().fold(0.0, f64::max);
    let stk_best = best(&cpu[0]);
    let mut lines = vec![
        format!(
            "Whole processes, user + system CPU, best of {PEER_ROUNDS} (interleaved); spread = worst / best - 1; \
             cello D3 at 48 kHz ({seconds} s; paper B's scenes {} s). Floor: each process's fastest \
             stretch of {} samples, the least over the rounds, ns a 48 kHz sample (the sample loop \
             with its output, no setup), which other load on the machine cannot raise; its \
             measure against STK's floor or as a share of one core",
            rows[4].seconds,
            crate::timing::FLOOR_STRETCH
        ),
        String::new(),
        "| what | CPU best (s) | spread | measured | range over the rounds | floor (ns a sample) | floor measured | instructions a sample | goal | met (best, floor) |".into(),
        "|---|---|---|---|---|---|---|---|---|---|".into(),
    ];
    let stk_floor = floors[0];
    for (((row, times), instr), &floor) in rows.iter().zip(&cpu).zip(&instructions).zip(&floors) {
        let (b, w) = (best(times), worst(times));
        // Each round's value, the best's, and its unit.
        let (per_round, value, unit): (Vec<f64>, f64, &str) = match row.measure {
            PeerMeasure::TimesStk => (
                times.iter().zip(&cpu[0]).map(|(t, s)| t / s).collect(),
                b / stk_best,
                "x STK",
            ),
            PeerMeasure::PercentOfCore => (
                times.iter().map(|t| 100.0 * t / row.seconds).collect(),
                100.0 * b / row.seconds,
                " % of a core",
            ),
        };
        let (measured, range) = (
            format!("{value:.2}{unit}"),
            format!("{:.2}-{:.2}", best(&per_round), worst(&per_round)),
        );
        // The floor's measure: against STK's floor, or the share of a core a 48 kHz
        // stream takes at that time a sample.
        let floor_value = floor.is_finite().then(|| match row.measure {
            PeerMeasure::TimesStk => floor / stk_floor,
            PeerMeasure::PercentOfCore => 100.0 * floor * 1e-9 * 48_000.0,
        });
        let goal = row.goal.map_or(String::new(), |g| format!("<= {g}{unit}"));
        let verdict = |v: f64, g: f64| if v <= g { "yes" } else { "no" };
        let met = row.goal.map_or(String::new(), |g| {
            format!(
                "{}, {}",
                verdict(value, g),
                floor_value.map_or("-", |f| verdict(f, g))
            )
        });
        lines.push(format!(
            "| {} | {b:.3} | {:.0} % | {measured} | {range} | {} | {} | {} | {goal} | {met} |",
            row.name,
            100.0 * (w / b - 1.0),
            if floor.is_finite() {
                format!("{floor:.1}")
            } else {
                "-".into()
            },
            floor_value.map_or("-".into(), |f| format!("{f:.2}{unit}")),
            instr.map_or("-".into(), |i| format!("{i:.0}")),
        ));
    }
    let (silent_s, bowed_s) = performer_silence_cost(4.0);
    let silence = 100.0 * silent_s / bowed_s;
    lines.push(format!(
        "| silence through the performer (in-process, best of five) | | | {silence:.2} % of one bowed string | | | | | <= 1 % | {} |",
        if silence <= 1.0 { "yes" } else { "no" }
    ));
    if instructions.iter().all(Option::is_none) {
        lines.push(String::new());
        lines.push("(instruction counts need valgrind: apt-get install valgrind)".into());
    }
    Ok(lines.join("\n"))
}

/// Whether `valgrind` runs here.
fn valgrind_available() -> bool {
    std::process::Command::new("valgrind")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Instructions per 48 kHz output sample of `command`: callgrind's totals for `short` and
/// `long` seconds of audio, their difference over the difference of the samples.
fn instructions_per_sample(
    command: &dyn Fn(f64) -> std::process::Command,
    short: f64,
    long: f64,
    what: &str,
) -> Result<f64, String> {
    let count = |secs: f64| -> Result<f64, String> {
        let inner = command(secs);
        let mut c = std::process::Command::new("valgrind");
        c.args(["--tool=callgrind", "--callgrind-out-file=/dev/null"])
            .arg(inner.get_program())
            .args(inner.get_args());
        let out = c.output().map_err(|e| format!("valgrind: {e}"))?;
        if !out.status.success() {
            return Err(format!("valgrind on {what} failed"));
        }
        // "==PID== Collected : N" on stderr.
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .find_map(|l| l.split("Collected :").nth(1))
            .and_then(|n| n.trim().parse::<f64>().ok())
            .ok_or_else(|| format!("no instruction count from callgrind on {what}"))
    };
    let (a, b) = (count(short)?, count(long)?);
    Ok((b - a) / ((long - short) * 48_000.0))
}

/// `colophony bench peer-scene:NAME --seconds S`: renders one of [`peers`]' scenes of
/// paper B's instrument for `seconds` of audio at 48 kHz (the attack included) and
/// prints nothing (the parent times the process): `cello-c` (the cello's open C, `N_B`
/// 60 over 1 cm, paper B's Figure 6 bow), `cello-cg` (the double stop C+G, the same) and
/// `quartet` (two violins, a viola and a cello, each bowing one note at the plugin's
/// default quality, the plugin's default bow). `cello-c@N` and `cello-cg@N` bow with
/// `N` nodes instead of 60 ([`table1`]'s rows).
pub fn peer_scene(name: &str, seconds: f64) -> Result<String, String> {
    use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(format!("--seconds must be within 0..=3600, got {seconds}"));
    }
    let fs = 48_000.0;
    let build =
        |kind: InstrumentKind, nodes: usize, notes: &[u8]| -> Result<ThermalInstrument, String> {
            let bridge = colophony::dsp::bridge_data::shipped_bridge(kind).modes;
            let mut i = ThermalInstrument::new(
                kind,
                &bridge,
                fs,
                ThermalSettings {
                    nodes,
                    width_m: 0.01,
                },
            )?;
            for &note in notes {
                i.note_on(note);
            }
            Ok(i)
        };
    let good = colophony::quality::Quality::Good
        .fixed_thermal_nodes()
        .expect("the good preset fixes its node count");
    let (scene, cello_nodes) = match name.split_once('@') {
        Some((scene, n)) if scene != "quartet" => (
            scene,
            n.parse::<usize>()
                .map_err(|_| format!("peer scene '{name}': '{n}' is not a node count"))?,
        ),
        Some(_) => {
            return Err(format!(
                "peer scene '{name}': the quartet takes no node count"
            ))
        }
        None => (name, colophony::quality::REFERENCE_NODES),
    };
    let (mut players, bow) = match scene {
        "cello-c" => (
            vec![build(InstrumentKind::Cello, cello_nodes, &[36])?],
            FIG6_BOW,
        ),
        "cello-cg" => (
            vec![build(InstrumentKind::Cello, cello_nodes, &[36, 43])?],
            FIG6_BOW,
        ),
        "quartet" => (
            vec![
                build(InstrumentKind::Violin, good, &[76])?,
                build(InstrumentKind::Violin, good, &[67])?,
                build(InstrumentKind::Viola, good, &[60])?,
                build(InstrumentKind::Cello, good, &[48])?,
            ],
            BowControl::default(),
        ),
        other => {
            return Err(format!(
            "unknown peer scene '{other}': cello-c, cello-cg (each with @N for N nodes) or quartet"
        ))
        }
    };
    let block = 512;
    let mut out = vec![0.0; block];
    let mut mix = vec![0.0; block];
    let blocks = (seconds * fs / block as f64).ceil() as usize;
    // Each player's sum of squares over the last second: every one must sound.
    let mut energy = vec![0.0; players.len()];
    let last_second = blocks.saturating_sub((fs / block as f64) as usize);
    let mut floor = crate::timing::Floor::new();
    for b in 0..blocks {
        mix.iter_mut().for_each(|x| *x = 0.0);
        for (p, e) in players.iter_mut().zip(&mut energy) {
            p.process(bow, &mut out);
            mix.iter_mut().zip(&out).for_each(|(m, x)| *m += x);
            if b >= last_second {
                *e += out.iter().map(|x| x * x).sum::<f64>();
            }
        }
        floor.advance(block);
    }
    let levels: Vec<String> = energy
        .iter()
        .map(|e| format!("{:.1}", 10.0 * (e / fs).log10()))
        .collect();
    if !energy.iter().all(|e| e.is_finite() && *e > 0.0) {
        return Err(format!(
            "peer scene {name}: a player is silent or not finite ({levels:?} dB)"
        ));
    }
    if floor.ns_per_sample().is_some() {
        eprintln!("{}", floor.line());
    }
    Ok(format!(
        "{name}: {seconds} s; each player's level over the last second {} dB",
        levels.join(", ")
    ))
}
