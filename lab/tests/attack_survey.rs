//! Attacks through the performer, as the plugin plays a note from MIDI at the defaults:
//! each instrument's range (three octaves from the lowest open string, every third
//! semitone) at note velocities 0.3, 0.55, 0.8 and 1.0 (the velocity sets the bow's
//! acceleration, `src/performer/stroke.rs`), every point law, 2.5 s each; the editor's
//! regime classifier on the contact probe over 1.5-2.5 s. A survey, printed, not
//! asserted: which limit cycle an attack falls into is chaotic, so it is read as counts.
//!
//! As last run, attacks in Helmholtz motion, of 52 (hyperbolic / static / LuGre /
//! elasto-plastic; the violin's and viola's strings and the cello's A string at 96 kHz
//! inside, the plugin's bristle at `sigma0` 3e5 N/m): violin 49 / 51 / 51 / 52, viola
//! 48 / 52 / 51 / 52, cello 50 / 50 / 52 / 50. Among the misses (double slips or
//! raucous): the cello's D#3 and F#4 at velocity 1.0 with the hyperbolic law, its F#2 with
//! the static law and at velocities 0.3 and 1.0 with elasto-plastic; the violin's E6 at
//! 0.8 and the viola's D#5 at 1.0 with LuGre. `cargo test --release --test attack_survey
//! -- --ignored --nocapture`.
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony::measure::contact::ContactSample;
use colophony::measure::regime::{classify_regime, Regime};
use colophony::performer::{Performer, Setup};

const FS: f64 = 48_000.0;

/// The contact probe of the bare cello (no performer), `note` bowed with the hyperbolic
/// law for `n` samples at `force_n` and `beta`, the bow's speed `velocity(i)` at sample
/// `i`; `stiff` false takes the strings' dispersion filter out.
fn bare_cello_probe(
    note: u8,
    force_n: f64,
    beta: f64,
    n: usize,
    stiff: bool,
    velocity: impl Fn(usize) -> f64,
) -> Vec<ContactSample> {
    use colophony::dsp::instrument::Instrument;
    let mut cello = Instrument::new(InstrumentKind::Cello, FS);
    cello.set_friction_model(FrictionModel::Hyperbolic);
    if !stiff {
        cello.set_dispersion_cap(0);
    }
    cello.note_on(note);
    (0..n)
        .map(|i| {
            if i % 256 == 0 {
                cello.update_sleep();
            }
            let bow = BowControl {
                velocity_m_per_s: velocity(i),
                force_n,
                position_beta: beta,
            };
            ContactSample::new(&cello.tick(bow), &bow)
        })
        .collect()
}

#[test]
#[ignore]
fn attacks_through_the_performer_survey() {
    for kind in InstrumentKind::ALL {
        for law in FrictionModel::ALL {
            let (low, high) = kind.note_range();
            let mut helm = 0;
            let mut total = 0;
            let mut line = String::new();
            for note in (low..=high.min(low + 36)).step_by(3) {
                for vel in [0.3f32, 0.55, 0.8, 1.0] {
                    let setup = Setup {
                        instrument: kind,
                        point_law: Some(law),
                        ..Setup::default()
                    };
                    let mut p = Performer::new(kind);
                    p.activate(&setup, FS).unwrap();
                    p.note_on(note, vel);
                    let bow = BowControl::default();
                    let n = (2.5 * FS) as usize;
                    let mut probe = Vec::with_capacity(n);
                    for i in 0..n {
                        if i % 256 == 0 {
                            p.configure(&setup);
                        }
                        let frame = p.tick(bow);
                        probe.push(ContactSample::new(&frame, &p.bow()));
                    }
                    let f0 = midi_to_hz(note as f64);
                    let r = classify_regime(&probe[(1.5 * FS) as usize..], FS as f32, f0 as f32);
                    total += 1;
                    if r == Some(Regime::Helmholtz) {
                        helm += 1;
                    } else {
                        line += &format!(" {note}@{vel}:{r:?}");
                    }
                }
            }
            println!(
                "{:?} {}: {helm} of {total} attacks in Helmholtz motion at 1.5-2.5 s;{line}",
                kind,
                law.name()
            );
        }
    }
}

/// Guettler's diagram on the bare instrument (no performer): cello D3 (or `NOTE`), the
/// hyperbolic law, beta 0.1 (or `BETA`), the bow from rest at constant acceleration to
/// 0.1 m/s (0: landing at speed) at constant force, 0.6 s; printed: the time from the
/// landing to established Helmholtz motion ([`helmholtz_since`]), ms. `FORCE_SCALE`
/// multiplies the forces (1: 0.25-6 N, 0.05-1.2 of the D string's `F_max`; the C string's
/// `F_max` is 3.77 times the D string's, the G string's 1.65, the A string's 1.0);
/// `STIFF=0` turns the strings' dispersion sections off.
/// `cargo test --release -p colophony-lab --test attack_survey guettler -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn guettler_diagram_survey() {
    use colophony::measure::regime::helmholtz_since;
    let note: u8 = std::env::var("NOTE").map_or(50, |s| s.parse().expect("NOTE: a MIDI note"));
    let beta: f64 = std::env::var("BETA").map_or(0.1, |s| s.parse().expect("BETA: 0.02-0.25"));
    let scale: f64 =
        std::env::var("FORCE_SCALE").map_or(1.0, |s| s.parse().expect("FORCE_SCALE: a factor"));
    let stiff = std::env::var("STIFF").map_or(true, |s| s != "0");
    let f0 = midi_to_hz(note as f64);
    let accels = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
    println!("cello note {note}, beta {beta}: rows bow force (N), columns acceleration (m/s^2; 0: landing at speed); ms to Helmholtz motion");
    println!(
        "      {}",
        accels.iter().map(|a| format!("{a:>7}")).collect::<String>()
    );
    for force_n in [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0].map(|f| f * scale) {
        let mut row = format!("{force_n:>5.2} ");
        for &a in &accels {
            let probe = bare_cello_probe(note, force_n, beta, (0.6 * FS) as usize, stiff, |i| {
                if a == 0.0 {
                    0.1
                } else {
                    (a * i as f64 / FS).min(0.1)
                }
            });
            row += &match helmholtz_since(&probe, FS as f32, f0 as f32) {
                Some(k) => format!("{:>7.0}", k as f64 / FS * 1e3),
                None => "  never".into(),
            };
        }
        println!("{row}");
    }
}

/// The smallest bowed string that has Guettler's attacks: two delay lines (cello D3 at
/// 48 kHz, `Z0` 0.506 kg/s), a rigid end and a lossy one whose one-pole filter
/// (`OnePoleLoss::for_string`, Q 500 at the fundamental and 250 at ten times it, as the
/// plugin's D string) sits at the bridge (`loss_at_bridge`) or at the nut, the bow at beta
/// 0.1 with the hyperbolic law; no torsion, hair, stiffness or fractional delay.
struct MinimalString {
    to_bridge: Vec<f64>,
    from_bridge: Vec<f64>,
    to_nut: Vec<f64>,
    from_nut: Vec<f64>,
    at_b: usize,
    at_n: usize,
    loss: colophony::dsp::filters::OnePoleLoss,
    loss_at_bridge: bool,
    friction: colophony::dsp::friction::HyperbolicFriction,
}

impl MinimalString {
    fn new(f0: f64, beta: f64, loss_at_bridge: bool) -> Self {
        let n_loop = (FS / f0).round() as usize;
        let nb = (beta * n_loop as f64 / 2.0).round().max(1.0) as usize;
        let nn = n_loop / 2 - nb;
        Self {
            to_bridge: vec![0.0; nb],
            from_bridge: vec![0.0; nb],
            to_nut: vec![0.0; nn],
            from_nut: vec![0.0; nn],
            at_b: 0,
            at_n: 0,
            loss: colophony::dsp::filters::OnePoleLoss::for_string(f0, FS, 500.0, 250.0, 1.0),
            loss_at_bridge,
            friction: Default::default(),
        }
    }

    /// One sample with the bow at `velocity` (m/s) and `force` (N): the contact sample.
    fn tick(&mut self, velocity: f64, force: f64) -> ContactSample {
        use colophony::dsp::friction::{BowInput, FrictionContact, LoadLine};
        const Z0: f64 = 0.506;
        let (arriving_b, arriving_n) = (self.from_bridge[self.at_b], self.from_nut[self.at_n]);
        let (at_bridge, at_nut) = (self.to_bridge[self.at_b], self.to_nut[self.at_n]);
        let (reflected_b, reflected_n) = if self.loss_at_bridge {
            (-self.loss.tick(at_bridge), -at_nut)
        } else {
            (-at_bridge, -self.loss.tick(at_nut))
        };
        let load = LoadLine {
            free_velocity_m_per_s: arriving_b + arriving_n,
            admittance_s_per_kg: 0.5 / Z0,
        };
        let f = self.friction.solve(
            load,
            BowInput {
                velocity_m_per_s: velocity,
                normal_force_n: force,
            },
        );
        let dv = f * load.admittance_s_per_kg;
        self.to_bridge[self.at_b] = arriving_n + dv;
        self.to_nut[self.at_n] = arriving_b + dv;
        self.from_bridge[self.at_b] = reflected_b;
        self.from_nut[self.at_n] = reflected_n;
        self.at_b = (self.at_b + 1) % self.to_bridge.len();
        self.at_n = (self.at_n + 1) % self.to_nut.len();
        contact_sample(load.free_velocity_m_per_s + dv, velocity, f, force)
    }
}

/// The contact sample of a bare string's tick: the string's velocity at the bow `v` and
/// the friction force `friction_n` under a bow at `bow_velocity` pressing with `force_n`
/// (what `ContactSample::new` reads from an instrument's frame).
fn contact_sample(v: f64, bow_velocity: f64, friction_n: f64, force_n: f64) -> ContactSample {
    ContactSample {
        string_velocity: v as f32,
        relative_velocity: (v - bow_velocity) as f32,
        mu: (friction_n / force_n) as f32,
    }
}

/// The first slip onset that begins `run` consecutive spans of one period (within 3 %):
/// when Helmholtz motion first appears, whether or not it lasts.
fn first_helmholtz_run(probe: &[ContactSample], f0: f64, run: usize) -> Option<usize> {
    let onsets = colophony::measure::regime::slip_onsets(probe);
    let period = FS / f0;
    let mut length = 0;
    for (k, w) in onsets.windows(2).enumerate() {
        if ((w[1] - w[0]) as f64 - period).abs() <= 0.03 * period {
            length += 1;
            if length == run {
                return Some(onsets[k + 1 - run]);
            }
        } else {
            length = 0;
        }
    }
    None
}

/// Guettler's diagram on [`MinimalString`] (cello D3, beta 0.1; forces as fractions of
/// Schelleng's `F_max` = 5.06 N, the bow from rest at constant acceleration to 0.1 m/s, 0:
/// landing at speed), with the loss at the bridge and at the nut, and the plugin's cello at
/// the same cells, with and without its string's stiffness (the nut's dispersion filter):
/// ms from the bow's start to the first six periods of Helmholtz motion
/// ([`first_helmholtz_run`]) and, in brackets, to Helmholtz motion that lasts to the end
/// of 0.8 s ([`helmholtz_since`]). `cargo test --release -p colophony-lab --test
/// attack_survey minimal -- --ignored --nocapture`.
#[test]
#[ignore]
fn minimal_string_guettler_survey() {
    use colophony::measure::regime::helmholtz_since;
    let f0 = midi_to_hz(50.0);
    let accels = [0.0, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0];
    let fractions = [0.05, 0.1, 0.2, 0.3, 0.5, 0.7];
    let n = (0.8 * FS) as usize;
    let ms = |k: Option<usize>| {
        k.map_or("never".to_string(), |k| {
            format!("{:.0}", k as f64 / FS * 1e3)
        })
    };
    for model in [
        "minimal, loss at the bridge",
        "minimal, loss at the nut",
        "the plugin's cello",
        "the plugin's cello without its stiffness (no dispersion filter)",
    ] {
        println!("{model}: rows F / F_max, columns acceleration (m/s^2); ms to six periods of Helmholtz motion (to lasting Helmholtz motion)");
        for &frac in &fractions {
            let force = frac * 5.06;
            let mut row = format!("{frac:>5}");
            for &a in &accels {
                let bow_velocity = |i: usize| {
                    if a == 0.0 {
                        0.1
                    } else {
                        (a * i as f64 / FS).min(0.1)
                    }
                };
                let probe: Vec<ContactSample> = if model.starts_with("minimal") {
                    let mut s = MinimalString::new(f0, 0.1, model.ends_with("bridge"));
                    (0..n).map(|i| s.tick(bow_velocity(i), force)).collect()
                } else {
                    let stiff = !model.ends_with("(no dispersion filter)");
                    bare_cello_probe(50, force, 0.1, n, stiff, bow_velocity)
                };
                let first = ms(first_helmholtz_run(&probe, f0, 6));
                let lasting = ms(helmholtz_since(&probe, FS as f32, f0 as f32));
                row += &format!(" {:>13}", format!("{first} ({lasting})"));
            }
            println!("{row}");
        }
    }
}

/// How long the bow drags the string before its first slip, against the quasi-static
/// estimate: bowed from rest at a constant acceleration `a`, the string follows the bow
/// until its pull, `K y` with `K = T / (beta (1 - beta) L)` (the two sides of the string
/// as springs) and `y = a t^2 / 2`, reaches the static friction `mu_s F`, so the first
/// slip comes at `t1 = sqrt(2 mu_s F / (K a))`. The plugin's cello D3 (hyperbolic law,
/// beta 0.1, the bow from rest to 0.1 m/s): ms to the first slip, `t1`, and ms to
/// Helmholtz motion that lasts to the end of 0.6 s. `cargo test --release -p
/// colophony-lab --test attack_survey first_slip -- --ignored --nocapture`.
#[test]
#[ignore]
fn first_slip_after_the_bow_drags_the_string() {
    use colophony::dsp::friction::HyperbolicFriction;
    use colophony::measure::regime::{helmholtz_since, slip_onsets};
    let (note, beta) = (50u8, 0.1);
    let f0 = midi_to_hz(note as f64);
    let d = InstrumentKind::Cello.strings()[2];
    let length = InstrumentKind::Cello.string_length_m() * d.open_hz / f0;
    let tension = d.z0_kg_per_s * 2.0 * length * f0;
    let k = tension / (beta * (1.0 - beta) * length);
    let mu_s = HyperbolicFriction::default().mu_s;
    println!(
        "cello D3, beta {beta}: K = {k:.0} N/m, mu_s {mu_s}; rows force (N), columns \
         acceleration (m/s^2): first slip / t1 / lasting Helmholtz motion, ms"
    );
    let accels = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0];
    let n = (0.6 * FS) as usize;
    let ms = |k: Option<usize>| k.map_or("never".into(), |k| format!("{:.0}", k as f64 / FS * 1e3));
    let mut spans = String::new();
    for force_n in [1.0, 2.0, 3.0, 4.0] {
        let mut row = format!("{force_n:>4}");
        for &a in &accels {
            let probe = bare_cello_probe(note, force_n, beta, n, true, |i| {
                (a * i as f64 / FS).min(0.1)
            });
            let first = slip_onsets(&probe).first().copied();
            let t1 = (2.0 * mu_s * force_n / (k * a)).sqrt() * 1e3;
            let lasting = helmholtz_since(&probe, FS as f32, f0 as f32);
            row += &format!(
                " {:>16}",
                format!("{} / {t1:.0} / {}", ms(first), ms(lasting))
            );
            if force_n == 3.0 && a == 2.0 {
                // The spans between slips up to the lasting motion, in periods.
                let onsets = slip_onsets(&probe);
                let end = lasting.unwrap_or(n);
                spans = onsets
                    .windows(2)
                    .take_while(|w| w[0] <= end)
                    .map(|w| format!("{:.2}", (w[1] - w[0]) as f64 * f0 / FS))
                    .collect::<Vec<_>>()
                    .join(" ");
            }
        }
        println!("{row}");
    }
    println!("3 N at 2 m/s^2, spans between slips up to the lasting motion (periods): {spans}");
}

/// The first slip along Guettler's rays, in periods. Dragged from rest by a bow
/// accelerating at `a` with force `F`, the string first slips at `t1 = sqrt(2 mu_s F / (K
/// a))` ([`first_slip_after_the_bow_drags_the_string`]). If that slip is to launch a corner
/// as tall as Helmholtz motion's at the bow's speed then, `F = rho F_max(a t1)` with `rho`
/// of order 1 (Schelleng's `F_max = 2 Z0 v / (beta (mu_s - mu_d))` is the force whose friction
/// drop makes the jump `v / beta`); with `K = T / (beta (1 - beta) L)` and `Z0 = T / c`
/// the two give `t1 = 2 rho (1 - beta) mu_s / (mu_s - mu_d)` periods of the note: 3.6
/// `rho` for paper A's coefficients at beta 0.1, whatever the string. The bare cello
/// (hyperbolic law, beta 0.1, 0.1 m/s) on rays of constant `F / a`: the bow reaches its
/// speed in `k T / r` (`T` the period) at `r F_max(0.1 m/s)`, so `rho = sqrt(k / 3.6)`
/// at the first slip; printed per note, the first slip / Helmholtz motion that lasts to
/// 0.6 s, both in periods from the bow's start; then the same rays on [`MinimalString`]
/// (cello D3), with its loss at the bridge and at the nut. `cargo test --release -p colophony-lab
/// --test attack_survey rays -- --ignored --nocapture`.
#[test]
#[ignore]
fn first_slip_along_guettlers_rays_survey() {
    use colophony::measure::regime::{helmholtz_since, slip_onsets};
    use colophony::measure::window::SchellengWindow;
    let (beta, speed) = (0.1, 0.1);
    let notes = [36u8, 40, 43, 47, 50, 53, 57, 60, 64, 69];
    let n = (0.6 * FS) as usize;
    println!(
        "cello, notes {notes:?}; first slip / lasting Helmholtz motion, periods from the bow's start"
    );
    for k in [1.0, 2.0, 4.0, 9.0] {
        for r in [0.5, 0.7, 0.85] {
            let mut line = format!("k {k:>3}, r {r:.2} (rho {:.2}):", (k / 3.6f64).sqrt());
            let mut within_four = 0;
            for &note in &notes {
                let f0 = midi_to_hz(note as f64);
                let f_max = SchellengWindow::for_note(InstrumentKind::Cello, note, beta)
                    .expect("a cello note")
                    .max_force_n(speed);
                let ramp = k / f0 / r * FS;
                let probe = bare_cello_probe(note, r * f_max, beta, n, true, |i| {
                    speed * (i as f64 / ramp).min(1.0)
                });
                let periods = |i: usize| i as f64 * f0 / FS;
                let first = slip_onsets(&probe)
                    .first()
                    .map_or(f64::NAN, |&i| periods(i));
                let lasting = helmholtz_since(&probe, FS as f32, f0 as f32).map(periods);
                within_four += usize::from(lasting.is_some_and(|p| p <= 4.0));
                let lasting = lasting.map_or("never".into(), |p| format!("{p:.1}"));
                line += &format!(" {:>10}", format!("{first:.1}/{lasting}"));
            }
            println!("{line}; lasting within 4 periods: {within_four}");
        }
    }
    // The same rays on the bare digital waveguide (cello D3, `F_max` 5.06 N).
    let f0 = midi_to_hz(50.0);
    for at_bridge in [true, false] {
        let mut line = format!(
            "minimal string, loss at the {}:",
            if at_bridge { "bridge" } else { "nut" }
        );
        for k in [1.0, 2.0, 4.0, 9.0] {
            for r in [0.5, 0.7, 0.85] {
                let ramp = k / f0 / r * FS;
                let mut s = MinimalString::new(f0, beta, at_bridge);
                let probe: Vec<ContactSample> = (0..n)
                    .map(|i| s.tick(speed * (i as f64 / ramp).min(1.0), r * 5.06))
                    .collect();
                line += &helmholtz_since(&probe, FS as f32, f0 as f32)
                    .map_or(" never".into(), |i| format!(" {:.1}", i as f64 * f0 / FS));
            }
        }
        println!("{line} (periods to lasting Helmholtz motion, rays as above in order)");
    }
}

/// Guettler's own attacks: the bow accelerating at a constant rate the whole time (no
/// speed to settle at) with a constant force, on the bare cello's D3 (hyperbolic law, beta
/// 0.1; or `NOTE`, its forces scaled by `FORCE_SCALE` as in [`guettler_diagram_survey`]),
/// with the string's stiffness (the nut's dispersion sections) and without; printed:
/// the first slip / the first of six slips one period apart ([`first_helmholtz_run`]), in
/// periods from the bow's start. A perfect attack has the two equal. `cargo test
/// --release -p colophony-lab --test attack_survey constant_acceleration -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn guettlers_constant_acceleration_with_and_without_stiffness_survey() {
    use colophony::measure::regime::slip_onsets;
    let note: u8 = std::env::var("NOTE").map_or(50, |s| s.parse().expect("NOTE: a MIDI note"));
    let scale: f64 =
        std::env::var("FORCE_SCALE").map_or(1.0, |s| s.parse().expect("FORCE_SCALE: a factor"));
    let beta = 0.1;
    let f0 = midi_to_hz(note as f64);
    let n = (0.5 * FS) as usize;
    let accels = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0];
    for stiff in [true, false] {
        println!(
            "cello note {note}, {}: rows force (N), columns acceleration {accels:?} (m/s^2)",
            if stiff {
                "as played"
            } else {
                "without stiffness"
            }
        );
        for force_n in [0.5, 1.0, 1.5, 2.5, 3.5, 5.0, 7.5].map(|f| f * scale) {
            let mut row = format!("{force_n:>5.2}");
            for &a in &accels {
                let probe = bare_cello_probe(note, force_n, beta, n, stiff, |i| a * i as f64 / FS);
                let periods = |i: usize| format!("{:.1}", i as f64 * f0 / FS);
                let first = slip_onsets(&probe)
                    .first()
                    .map_or("-".into(), |&i| periods(i));
                let six = first_helmholtz_run(&probe, f0, 6).map_or("-".into(), periods);
                row += &format!(" {:>9}", format!("{first}/{six}"));
            }
            println!("{row}");
        }
    }
}

/// The slip against the bow position, landed: the violin's open D string (D4) on the bare
/// instrument (no performer), 0.1 m/s and 0.84 N (`F_max / 2` at beta 0.18), 1.2 s at
/// 48 kHz; the slip fraction (the map's `slip_stats`, over the last 0.6 s) and its ratio
/// to beta, for the hyperbolic law with and without torsion and hair, for the static
/// (Stribeck) law, and for the string alone (one `WaveguideString` with the hyperbolic
/// law: no body, fingers or resampler). Printed, not asserted: which limit cycle a
/// landing falls into is read as a table. `cargo test --release -p colophony-lab --test
/// attack_survey short_slip -- --ignored --nocapture`.
#[test]
#[ignore]
fn short_slip_against_the_bow_position_survey() {
    use colophony::analysis::slip_stats;
    use colophony::dsp::instrument::Instrument;
    let (note, force_n, v_b) = (62u8, 0.84, 0.1);
    let f0 = midi_to_hz(note as f64);
    let n = (1.2 * FS) as usize;
    let slip = |law: FrictionModel, extras: bool, beta: f64| {
        let mut violin = Instrument::new(InstrumentKind::Violin, FS);
        violin.set_friction_model(law);
        violin.set_torsion(extras);
        violin.set_bow_hair(extras);
        violin.note_on(note);
        let bow = BowControl {
            velocity_m_per_s: v_b,
            force_n,
            position_beta: beta,
        };
        let v: Vec<f64> = (0..n)
            .map(|i| {
                if i % 256 == 0 {
                    violin.update_sleep();
                }
                violin.tick(bow).bow_point_velocity_m_per_s
            })
            .collect();
        slip_stats(&v[n / 2..], v_b, FS, f0, 0.05 * v_b).slip_fraction
    };
    // The string alone: one `WaveguideString` (no body, no fingers, no resampling), the
    // hyperbolic law, at the bank's 96 kHz.
    let bare = |beta: f64| {
        use colophony::dsp::friction::{BowInput, HyperbolicFriction};
        use colophony::dsp::waveguide::WaveguideString;
        let fs = 2.0 * FS;
        let spec = InstrumentKind::Violin.strings()[1];
        let mut string = WaveguideString::new(spec, fs, 60.0);
        string.stop_at(spec.open_hz);
        string.set_bow_position(beta);
        let mut contact = HyperbolicFriction::default();
        let bow = BowInput {
            velocity_m_per_s: v_b,
            normal_force_n: force_n,
        };
        let m = (1.2 * fs) as usize;
        let v: Vec<f64> = (0..m)
            .map(|_| string.tick(&mut contact, bow).bow_point_velocity_m_per_s)
            .collect();
        slip_stats(&v[m / 2..], v_b, fs, spec.open_hz, 0.05 * v_b).slip_fraction
    };
    println!("violin D4 landed at {force_n} N, {v_b} m/s: slip fraction (over beta)");
    println!(
        "  beta  hyperbolic     no torsion or hair  static (Stribeck)  the bare string, hyperbolic"
    );
    for beta in [0.1, 0.12, 0.15, 0.165, 0.18, 0.2, 0.21, 0.25, 0.3, 0.35] {
        let cells = [
            slip(FrictionModel::Hyperbolic, true, beta),
            slip(FrictionModel::Hyperbolic, false, beta),
            slip(FrictionModel::Stribeck, true, beta),
            bare(beta),
        ];
        let row: Vec<String> = cells
            .iter()
            .map(|s| format!("{s:.3} ({:.2})", s / beta))
            .collect();
        println!("  {beta:<5} {}", row.join("   "));
    }
}

/// Attacks on the bare string against the friction curve's shape: one `WaveguideString`
/// (torsion and hair on, no body, fingers or resampler) at 48 kHz, the cello's D string at
/// beta 0.1 and 0.07, its G at 0.1, its C at 0.12 and its A at 0.1; the hyperbolic law
/// with the plugin's curve (`mu_s` 0.4, `mu_d` 0.2, `v0` 0.1 m/s), a sharper one, a higher
/// one, and the levels of the exponential steady-sliding fit to rosin (1.2 at rest, 0.35
/// fast; docs/literature-values.md §1.2) with a fall over 0.03 or 0.01 m/s; forces
/// 0.1-0.7 of each curve's `F_max`, the bow from rest at
/// 1-20 m/s^2 or landing at 0.1 m/s. Printed per curve: attacks in Helmholtz motion that
/// lasts to 0.5 s, those that speak within 50 ms, and the median speaking time.
/// `cargo test --release -p colophony-lab --test attack_survey friction_curve --
/// --ignored --nocapture`.
#[test]
#[ignore]
fn attacks_against_the_friction_curve_survey() {
    use colophony::dsp::friction::{BowInput, HyperbolicFriction};
    use colophony::dsp::waveguide::WaveguideString;
    use colophony::measure::regime::helmholtz_since;
    let v_b = 0.1;
    let n = (0.5 * FS) as usize;
    let places = [(2usize, 0.1), (2, 0.07), (1, 0.1), (0, 0.12), (3, 0.1)];
    let fractions = [0.1, 0.2, 0.3, 0.5, 0.7];
    let accels = [1.0, 2.0, 5.0, 10.0, 20.0, 0.0];
    println!("law (mu_s, mu_d, v0): attacks in Helmholtz motion / within 50 ms / median ms");
    for (mu_s, mu_d, v0) in [
        (0.4, 0.2, 0.1),
        (0.4, 0.2, 0.03),
        (0.8, 0.3, 0.1),
        (0.8, 0.3, 0.03),
        (1.2, 0.35, 0.03),
        (1.2, 0.35, 0.01),
    ] {
        let mut spoke = Vec::new();
        let mut attacks = 0;
        for &(index, beta) in &places {
            let spec = InstrumentKind::Cello.strings()[index];
            let f_max = 2.0 * spec.z0_kg_per_s * v_b / (beta * (mu_s - mu_d));
            for &fraction in &fractions {
                for &a in &accels {
                    let mut string = WaveguideString::new(spec, FS, 60.0);
                    string.stop_at(spec.open_hz);
                    string.set_bow_position(beta);
                    let mut contact = HyperbolicFriction::default();
                    (contact.mu_s, contact.mu_d, contact.v0_m_per_s) = (mu_s, mu_d, v0);
                    let force = fraction * f_max;
                    let probe: Vec<ContactSample> = (0..n)
                        .map(|i| {
                            let v = if a == 0.0 {
                                v_b
                            } else {
                                (a * i as f64 / FS).min(v_b)
                            };
                            let bow = BowInput {
                                velocity_m_per_s: v,
                                normal_force_n: force,
                            };
                            let out = string.tick(&mut contact, bow);
                            contact_sample(
                                out.bow_point_velocity_m_per_s,
                                v,
                                out.friction_force_n,
                                force,
                            )
                        })
                        .collect();
                    attacks += 1;
                    if let Some(k) = helmholtz_since(&probe, FS as f32, spec.open_hz as f32) {
                        spoke.push(k as f64 / FS * 1e3);
                    }
                }
            }
        }
        spoke.sort_by(f64::total_cmp);
        let quick = spoke.iter().filter(|&&ms| ms <= 50.0).count();
        let median = spoke.get(spoke.len() / 2).copied().unwrap_or(f64::NAN);
        println!(
            "  ({mu_s}, {mu_d}, {v0}): {} of {attacks} / {quick} / {median:.0}",
            spoke.len()
        );
    }
}
