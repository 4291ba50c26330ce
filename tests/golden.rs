//! Golden renders: a few seconds of every source the plugin plays (the four point laws
//! on the waveguide strings, paper B's thermal cello, each rubbed object), rendered
//! through the CLAP build in the headless host with notes, a bend, a string choice and
//! bow automation, must keep the same bits across refactoring.
//!
//! Each render is kept as a 64-bit FNV-1a hash of its samples' bits, with its RMS and
//! peak for the failure message, in `tests/golden/renders.txt`. A change meant to be
//! audible re-records them: `COLOPHONY_RECORD_GOLDEN=1 cargo test --test golden --test
//! state_fixtures` (the second re-records the saved state's render too), and the commit
//! says why.
//!
//! Bits are comparable only where the math library takes the same code paths: glibc picks
//! its `sin`, `exp`, `pow` variants by the CPU's features (FMA or not), which can change
//! last bits that a bowed string's chaotic moments then amplify. The file records the
//! features it was made on; on a machine that differs the test compares each render's
//! RMS and peak within 2 % instead (last-bit rounding changes of this code move them by
//! 0.2 % at most) and says so.

mod host;

use host::{channel_f64, fnv1a, machine, Event, HostedPlugin, Score};
use std::fmt::Write as _;

const FS: f64 = 48_000.0;
const BLOCK: usize = 256;
const GOLDEN: &str = "tests/golden/renders.txt";

fn secs(t: f64) -> u64 {
    (t * FS).round() as u64
}

/// One scene: a name, the parameter texts to set, and the length in seconds.
struct Scene {
    name: &'static str,
    texts: &'static [(&'static str, &'static str)],
    instrument: &'static str,
    seconds: f64,
}

const SCENES: &[Scene] = &[
    Scene {
        name: "hyperbolic-cello",
        texts: &[("Friction Model", "Hyperbolic")],
        instrument: "Cello",
        seconds: 2.5,
    },
    Scene {
        name: "static-violin",
        texts: &[("Friction Model", "Static (Stribeck)")],
        instrument: "Violin",
        seconds: 2.5,
    },
    Scene {
        name: "lugre-viola",
        texts: &[("Friction Model", "LuGre")],
        instrument: "Viola",
        seconds: 2.5,
    },
    Scene {
        name: "elasto-plastic-cello",
        texts: &[("Friction Model", "Elasto-plastic")],
        instrument: "Cello",
        seconds: 2.5,
    },
    Scene {
        name: "thermal-cello",
        texts: &[("Friction Model", "Thermal (paper B)")],
        instrument: "Cello",
        seconds: 1.5,
    },
    Scene {
        name: "rubbed-door-hinge",
        texts: &[("Resonator", "Door hinge")],
        instrument: "Cello",
        seconds: 1.5,
    },
    Scene {
        name: "rubbed-wine-glass",
        texts: &[("Resonator", "Wine glass")],
        instrument: "Cello",
        seconds: 1.5,
    },
    Scene {
        name: "rubbed-paper-modal",
        texts: &[("Resonator", "Paper A modal")],
        instrument: "Cello",
        seconds: 1.5,
    },
];

/// Renders a scene: two notes (the second a fifth up, overlapping), a bend, a string
/// choice, force and velocity automation, a bow change, then the release.
fn render(scene: &Scene) -> Vec<f32> {
    let mut plugin = HostedPlugin::load_test_build();
    plugin.activate(FS, BLOCK);
    let t = scene.seconds;
    let mut score = Score::new().at(0, plugin.text("Instrument", scene.instrument));
    for (name, text) in scene.texts {
        score = score.at(0, plugin.text(name, text));
    }
    let low = match scene.instrument {
        "Violin" => 62,
        "Viola" => 55,
        _ => 50,
    };
    score = score
        .at(0, Event::note_on(low))
        .at(secs(0.25 * t), plugin.plain("Bow Force", 2.0))
        .at(secs(0.3 * t), Event::pitch_bend(0.6))
        .at(secs(0.4 * t), plugin.text("String", "IV (lowest)"))
        .at(secs(0.45 * t), Event::note_on(low + 7))
        .at(secs(0.5 * t), Event::note_off(low))
        .at(secs(0.55 * t), plugin.plain("Bow Velocity", -0.15))
        .at(secs(0.6 * t), plugin.plain("Bow Position", 0.15))
        .at(secs(0.75 * t), Event::note_off(low + 7));
    let out = plugin.render(secs(t) as usize, BLOCK, &score);
    out[0].clone()
}

/// RMS and peak of a golden line.
fn levels(line: &str) -> (f64, f64) {
    let f: Vec<&str> = line.split_whitespace().collect();
    (f[3].parse().unwrap(), f[5].parse().unwrap())
}

fn line(scene: &Scene, x: &[f32]) -> String {
    let y = channel_f64(&[x.to_vec()], 0);
    let rms = (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt();
    let peak = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    format!(
        "{} {:016x} rms {:.6e} peak {:.6e}",
        scene.name,
        fnv1a(x),
        rms,
        peak
    )
}

#[test]
fn every_source_renders_the_same_bits_as_recorded() {
    let mut got = String::new();
    for scene in SCENES {
        let x = render(scene);
        assert!(x.iter().any(|v| *v != 0.0), "{}: silent", scene.name);
        let _ = writeln!(got, "{}", line(scene, &x));
    }
    if std::env::var_os("COLOPHONY_RECORD_GOLDEN").is_some() {
        std::fs::create_dir_all("tests/golden").unwrap();
        std::fs::write(GOLDEN, format!("{}\n{got}", machine())).unwrap();
        println!("recorded {GOLDEN}:\n{got}");
        return;
    }
    let file = std::fs::read_to_string(GOLDEN).expect("tests/golden/renders.txt (record it first)");
    let recorded_on = file
        .lines()
        .find(|l| l.starts_with("# machine:"))
        .unwrap_or("");
    let want: Vec<&str> = file.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(
        got.lines().count(),
        want.len(),
        "scene count changed:\n{got}"
    );
    let same_machine = recorded_on == machine();
    if !same_machine {
        println!(
            "recorded on '{recorded_on}', running on '{}': comparing levels",
            machine()
        );
    }
    let mut diffs = Vec::new();
    for (g, w) in got.lines().zip(&want) {
        let differs = if same_machine {
            g != *w
        } else {
            let ((gr, gp), (wr, wp)) = (levels(g), levels(w));
            // Rounding changes move RMS and peak by 0.2 % at most (module doc).
            (gr / wr - 1.0).abs() > 0.02 || (gp / wp - 1.0).abs() > 0.02
        };
        if differs {
            diffs.push(format!("  now {g}\n  was {w}"));
        }
    }
    assert!(diffs.is_empty(), "renders changed:\n{}", diffs.join("\n"));
}
