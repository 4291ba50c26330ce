use colophony::dsp::friction::FrictionModel;
use colophony::dsp::instrument::{midi_to_hz, BowControl, Instrument, InstrumentKind};
use colophony::dsp::intonation;
use colophony::editor::mapping::SchellengWindow;

const FS: f64 = 48_000.0;

/// Start (s) of the final run of onsets one period apart (3 %) reaching the end, or None.
fn settled(v_s: &[f64], v_b: f64, beta: f64, f0: f64) -> Option<f64> {
    let mut onsets = Vec::new();
    let mut slipping = false;
    for (i, v) in v_s.iter().enumerate() {
        let s = v_b - v > 0.5 * v_b / beta;
        if s && !slipping {
            onsets.push(i as f64 / FS);
        }
        slipping = s;
    }
    if onsets.len() < 10 {
        return None;
    }
    let t = 1.0 / f0;
    let mut k = onsets.len() - 1;
    while k > 0 && ((onsets[k] - onsets[k - 1]) / t - 1.0).abs() < 0.03 {
        k -= 1;
    }
    if onsets[onsets.len() - 1] - onsets[k] < 0.3 {
        return None;
    }
    Some(onsets[k])
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let law = FrictionModel::from_name(args.get(1).map_or("hyperbolic", |s| s)).unwrap();
    let kind = InstrumentKind::from_name(args.get(2).map_or("cello", |s| s)).unwrap();
    let note: u8 = args.get(3).map_or(50, |s| s.parse().unwrap());
    let beta: f64 = args.get(4).map_or(0.1, |s| s.parse().unwrap());
    let v = 0.1;
    let index = kind.string_for_note(note).unwrap();
    let w = SchellengWindow {
        mu_s: 0.4,
        mu_d: 0.2,
        ..SchellengWindow::for_string(kind, index, beta)
    };
    let (fmin, fmax) = (w.min_force_n(v), w.max_force_n(v));
    let f0 = midi_to_hz(note as f64);
    println!("{law:?} {kind:?} {note} beta {beta}: F_min {fmin:.3} F_max {fmax:.3}; settled at (ms), '-' never in 1.5 s");
    println!(
        "{:>10} {:>8} {:>8} {:>8} {:>8}",
        "force", "landing", "bite", "bite+hold", "held"
    );
    let mut ks: Vec<(String, f64)> = vec![
        ("Fmax/2".into(), fmax / 2.0),
        ("mid".into(), (fmin * fmax).sqrt()),
        ("2Fmin".into(), 2.0 * fmin),
    ];
    for k in [4.0, 8.0, 16.0, 32.0] {
        ks.push((format!("Fmax/{k}"), fmax / k));
    }
    for (name, target) in ks {
        print!("{name:>10}");
        for mode in 0..4 {
            let mut e = Instrument::new(kind, FS);
            e.set_friction_model(law);
            e.set_intonation(Some(intonation::shipped()));
            e.note_on(note);
            let n = (2.0 * FS) as usize;
            let bite = if mode == 3 { fmax / 2.0 } else { fmax / 2.5 };
            let mut vs = Vec::with_capacity(n);
            for i in 0..n {
                let t = i as f64 / FS;
                let (hold, fall) = match mode {
                    1 => (0.06, 0.04),
                    3 => (0.3, 0.1),
                    _ => (0.15, 0.1),
                };
                let force = if mode == 0 || target >= bite {
                    target
                } else if t < hold {
                    bite
                } else if t < hold + fall {
                    bite * (target / bite).powf((t - hold) / fall)
                } else {
                    target
                };
                if i % 256 == 0 {
                    e.update_sleep();
                }
                let fr = e.tick(BowControl {
                    velocity_m_per_s: v,
                    force_n: force,
                    position_beta: beta,
                });
                vs.push(fr.bow_point_velocity_m_per_s);
            }
            match settled(&vs, v, beta, f0) {
                Some(t) => print!(" {:>8.0}", t * 1e3),
                None => print!(" {:>8}", "-"),
            }
        }
        println!();
    }
}
