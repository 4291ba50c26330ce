//! `cargo xtask bundle colophony --release` and the other nice-plug-xtask commands, plus
//! `cargo xtask demo`: bundle, then render a short demo through the bundled CLAP plugin.

#[path = "../../tests/host/mod.rs"]
mod host;

use host::{Event, HostedPlugin, Score};
use std::path::PathBuf;

fn main() -> nice_plug_xtask::Result<()> {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().map(String::as_str) == Some("demo") {
        return demo();
    }
    nice_plug_xtask::main_with_args("cargo xtask", args)
}

const SAMPLE_RATE: f64 = 48_000.0;
const BLOCK: usize = 256;

/// Bundles the plugin (release) and renders about 6 s of bowed cello through the CLAP
/// build to `target/demo/colophony-demo.wav`.
fn demo() -> nice_plug_xtask::Result<()> {
    nice_plug_xtask::main_with_args(
        "cargo xtask",
        ["bundle", "colophony", "--release"].map(String::from),
    )?;
    // `main_with_args` left us in the workspace root.
    let target = host::target_dir();
    let clap = target.join("bundled").join("Colophony.clap");
    anyhow_ensure(clap.exists(), format!("{} was not bundled", clap.display()))?;

    // Loading: open the bundle, create the instance, list its parameters (the host reads
    // every parameter's info), activate.
    let load_start = std::time::Instant::now();
    let mut plugin = HostedPlugin::load(&clap);
    plugin.activate(SAMPLE_RATE, BLOCK);
    let load_s = load_start.elapsed().as_secs_f64();
    let listed = plugin.params().len();
    let s = |t: f64| (t * SAMPLE_RATE).round() as u64;
    let cello = plugin.text("Instrument", "Cello");
    let score = Score::new()
        .at(0, cello)
        .at(0, plugin.plain("Bow Velocity", 0.1))
        .at(0, plugin.plain("Bow Force", 0.8))
        // D3, then a crescendo with more bow force and speed.
        .at(s(0.05), Event::note_on(50))
        .at(s(0.6), plugin.plain("Bow Force", 1.6))
        .at(s(0.6), plugin.plain("Bow Velocity", 0.18))
        .at(s(1.2), Event::note_off(50))
        // Up bow on A3 and then E4 on the A string, lighter and nearer the bridge.
        .at(s(1.25), plugin.plain("Bow Velocity", -0.12))
        .at(s(1.25), plugin.plain("Bow Force", 0.9))
        .at(s(1.3), Event::note_on(57))
        .at(s(1.9), plugin.plain("Bow Position", 0.07))
        .at(s(2.2), Event::note_off(57))
        .at(s(2.25), Event::note_on(64))
        .at(s(2.8), plugin.plain("Bow Velocity", -0.06))
        .at(s(3.1), Event::note_off(64))
        // A low G, down bow, lifted at 4.3 s and left to ring.
        .at(s(3.15), plugin.plain("Bow Position", 0.12))
        .at(s(3.15), plugin.plain("Bow Velocity", 0.15))
        .at(s(3.15), plugin.plain("Bow Force", 2.0))
        .at(s(3.2), Event::note_on(43))
        .at(s(4.3), Event::note_off(43));
    let frames = s(6.0) as usize;
    let out = plugin.render(frames, BLOCK, &score);
    let stats = plugin.last_render.expect("render stats");
    let path: PathBuf = host::write_wav_to(
        &target.join("demo").join("colophony-demo.wav"),
        SAMPLE_RATE,
        &out,
    );
    let peak = out.iter().flatten().fold(0.0f32, |m, x| m.max(x.abs()));
    println!("plugin: {} ({})", plugin.plugin_name, clap.display());
    println!("loaded, {listed} parameters listed and activated in {load_s:.3} s");
    println!(
        "wrote {} ({:.1} s, {} Hz, peak {:.1} dBFS)",
        path.display(),
        frames as f64 / SAMPLE_RATE,
        SAMPLE_RATE,
        20.0 * peak.max(1e-12).log10()
    );
    println!(
        "rendered in {:.3} s: {:.0}x real time",
        stats.wall.as_secs_f64(),
        stats.realtime_ratio()
    );
    Ok(())
}

fn anyhow_ensure(ok: bool, message: String) -> nice_plug_xtask::Result<()> {
    if ok {
        Ok(())
    } else {
        Err(std::io::Error::other(message).into())
    }
}
