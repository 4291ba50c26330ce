//! Paper A (Serafin, Avanzini, Rocchesso): elasto-plastic, LuGre and static friction, solved
//! by the K-method and Newton-Raphson, on the waveguide cello D string and on modal objects.

use colophony::analysis::{cents, peak_frequency_hz, rms, slip_stats};
use colophony::dsp::friction::bristle::{BristleFriction, BristleLaw, BristleParams};
use colophony::dsp::friction::{BowInput, FrictionContact, FrictionModel, LoadLine};
use colophony::dsp::instrument::Instrument;
use colophony::dsp::modal::{ModalObject, ModeSpec};
use colophony::dsp::rubbed::{RubbedPreset, RubbedScene};
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony_lab::render::{render, RenderSettings};

const FS: f64 = 48_000.0;

/// Paper A's waveguide scenario: cello D (147 Hz), v_b 0.1 m/s, F_N 1.1 N, beta 0.1.
fn cello_d(friction: FrictionModel, seconds: f64) -> RenderSettings {
    RenderSettings {
        instrument: InstrumentKind::Cello,
        note: 50,
        seconds,
        bow: BowControl {
            velocity_m_per_s: 0.1,
            force_n: 1.1,
            position_beta: 0.1,
        },
        sample_rate_hz: FS,
        friction,
        // Paper A's scene's bristle (the plugin's is stiffer); its string is purely
        // transverse, bowed by a rigid point, tuned by its free decay.
        bristle: BristleParams::waveguide_string(),
        torsion: false,
        bow_hair: false,
        intonation: false,
        ..RenderSettings::default()
    }
}

#[test]
fn elasto_plastic_bowing_of_the_cello_d_string_is_helmholtz_motion_at_the_right_pitch() {
    let out = render(&cello_d(FrictionModel::ElastoPlastic, 2.5)).unwrap();
    let v = &out.bow_point_velocity_m_per_s[(1.5 * FS) as usize..];
    // 1e-3 m/s (1 % of v_s): presliding creep keeps the bristle model off exact sticking.
    let stats = slip_stats(v, 0.1, FS, midi_to_hz(50.0), 1e-3);
    let f = peak_frequency_hz(&out.audio[FS as usize..], FS, midi_to_hz(50.0), 50.0);
    let bowed_cents = cents(f, midi_to_hz(50.0));
    println!("elasto-plastic, cello D at 1.1 N: {stats:?}; bowed pitch {bowed_cents:+.2} cents from the free string");
    // Slip fraction within 10 % of beta: the rounded corners and the bow position rounded
    // to the grid (under 1 %) move it, measured 0.108 (docs/papers-reproduced.md). One slip
    // per period over ~147 periods: only the window edges add a fraction.
    assert!(
        (stats.slip_fraction - 0.1).abs() < 0.01,
        "slip fraction {}",
        stats.slip_fraction
    );
    assert!(
        (stats.slips_per_period - 1.0).abs() < 0.02,
        "{} slips per period",
        stats.slips_per_period
    );
    // 10 % of v_b, the playing-space map's Helmholtz criterion; presliding creep keeps
    // sticking off v_b by about 1e-3 m/s.
    assert!((stats.stick_velocity_m_per_s - 0.1).abs() < 0.01);
    // Bowed pitch within 10 cents of the free string (tuned to 0.002 cents: see
    // model_physics.rs), so this is the bowing's own shift.
    assert!(
        bowed_cents.abs() < 10.0,
        "bowed pitch {bowed_cents:+.2} cents"
    );
}

#[test]
fn newton_needs_at_most_7_iterations_for_99_percent_of_samples_in_the_cello_d_scenario() {
    for model in [FrictionModel::ElastoPlastic, FrictionModel::LuGre] {
        let out = render(&cello_d(model, 2.0)).unwrap();
        let stats = out.newton;
        let hist: Vec<String> = stats
            .histogram
            .iter()
            .enumerate()
            .filter(|(_, n)| **n > 0)
            .map(|(k, n)| format!("{k}: {n}"))
            .collect();
        println!(
            "{}: iterations histogram {{{}}}, fallbacks {} ({} evaluations of g), within 7: {:.4} %",
            model.name(),
            hist.join(", "),
            stats.fallbacks,
            stats.fallback_evaluations,
            100.0 * stats.fraction_within(7)
        );
        assert_eq!(stats.samples(), (2.0 * FS) as u64);
        // Paper A reports fewer than 7 iterations a sample (docs/papers-reproduced.md);
        // measured 99.96 % within 7.
        assert!(stats.fraction_within(7) >= 0.99, "{stats:?}");
        assert_eq!(
            stats.fallbacks, 0,
            "the bracketing fallback should be rare here"
        );
    }
}

/// A free mass (no spring) held by a contact whose other side is at rest, pushed by
/// `push(n)`. Returns the mass's displacement after `samples`.
fn pushed_mass_displacement(
    law: BristleLaw,
    push: impl Fn(usize) -> f64,
    samples: usize,
) -> (f64, f64) {
    let mut contact = BristleFriction::new(BristleParams::modal_scenario(), law, FS).unwrap();
    let mut mass = ModalObject::new(
        &[ModeSpec {
            freq_hz: 0.0,
            q: 1.0,
            mass_kg: 0.01,
            weight: 1.0,
        }],
        FS,
    )
    .unwrap();
    let bow = BowInput {
        velocity_m_per_s: 0.0,
        normal_force_n: 1.0,
    };
    let mut max_z = 0.0f64;
    for n in 0..samples {
        let load = mass.begin(push(n));
        let f = contact.solve(load, bow);
        mass.finish(f);
        max_z = max_z.max(contact.bristle_displacement_m().abs());
    }
    (mass.displacement_m(), max_z)
}

#[test]
fn under_a_small_vibrating_force_elasto_plastic_does_not_drift_but_lugre_does() {
    // Dupont et al.'s motivation, repeated by paper A: a bias force plus a vibration, all
    // below the breakaway force sigma0 z_ba = 0.7 f_c = 0.14 N. LuGre creeps a little each
    // cycle (its bristles always slide plastically); elasto-plastic stays elastic.
    let push = |n: usize| 0.05 + 0.05 * (2.0 * std::f64::consts::PI * 50.0 * n as f64 / FS).sin();
    let breakaway = 0.7 * 0.2 / 1e4;
    let mut drift = Vec::new();
    for law in [BristleLaw::ElastoPlastic, BristleLaw::LuGre] {
        // Displacement after 1 s and after 2 s (whole cycles of 50 Hz).
        let (x1, max_z) = pushed_mass_displacement(law, push, FS as usize);
        let (x2, _) = pushed_mass_displacement(law, push, 2 * FS as usize);
        println!("{law:?}: displacement {x1:.3e} m after 1 s, {x2:.3e} m after 2 s, max |z| {max_z:.3e} (z_ba {breakaway:.3e})");
        drift.push(x2 - x1);
    }
    // Elasto-plastic: the second second adds nothing beyond rounding (1e-12 m against
    // presliding of ~1e-5 m).
    assert!(
        drift[0].abs() < 1e-12,
        "elasto-plastic drifted {:e} m",
        drift[0]
    );
    // LuGre: a steady creep in the bias direction, orders of magnitude larger.
    assert!(drift[1] > 1e-7, "LuGre drift {:e} m", drift[1]);
}

#[test]
fn presliding_below_breakaway_is_purely_elastic() {
    // With a rigid bow moving a rigid support (admittance 0), v = v_b exactly; below z_ba
    // the elasto-plastic bristles follow the relative displacement exactly (z = integral
    // of v by the trapezoid rule) and return to zero with it: no plastic slip, and the
    // force is sigma0 z + (sigma1 + sigma2) v, single valued.
    let p = BristleParams::modal_scenario();
    let mut ep = BristleFriction::new(p, BristleLaw::ElastoPlastic, FS).unwrap();
    let mut lugre = BristleFriction::new(p, BristleLaw::LuGre, FS).unwrap();
    let load = LoadLine {
        free_velocity_m_per_s: 0.0,
        admittance_s_per_kg: 0.0,
    };
    let z_ba = ep.breakaway_displacement_m(1.0);
    // Displacement amplitude 0.9 z_ba at 100 Hz: velocity amplitude 0.9 z_ba w.
    let w = 2.0 * std::f64::consts::PI * 100.0;
    let mut x = 0.0;
    let mut v_prev = 0.0;
    let mut worst = 0.0f64;
    let mut lugre_gap = 0.0f64;
    for n in 1..=(FS as usize / 100) * 3 {
        let v = 0.9 * z_ba * w * (w * n as f64 / FS).cos();
        x += 0.5 / FS * (v + v_prev);
        v_prev = v;
        let bow = BowInput {
            velocity_m_per_s: v,
            normal_force_n: 1.0,
        };
        let f = ep.solve(load, bow);
        lugre.solve(load, bow);
        let z = ep.bristle_displacement_m();
        worst = worst.max((z - x).abs() / z_ba);
        let elastic = p.sigma0_n_per_m * z + (p.sigma1_kg_per_s + p.sigma2_kg_per_s) * v;
        // Rounding only, as for z below: the forces stay under 0.2 N.
        assert!((f - elastic).abs() < 1e-9, "sample {n}: {f} vs {elastic}");
        lugre_gap = lugre_gap.max((lugre.bristle_displacement_m() - x).abs() / z_ba);
    }
    println!(
        "presliding: max |z - x| = {worst:.2e} z_ba (elasto-plastic), {lugre_gap:.2e} z_ba (LuGre)"
    );
    // Rounding only for elasto-plastic; LuGre's plastic creep is visible.
    assert!(worst < 1e-9);
    assert!(lugre_gap > 1e-3);
}

#[test]
fn per_sample_and_block_processing_give_identical_output() {
    let bow = BowControl {
        velocity_m_per_s: 0.1,
        force_n: 1.1,
        position_beta: 0.1,
    };
    let mut a = Instrument::new(InstrumentKind::Cello, FS);
    let mut b = a.clone();
    for inst in [&mut a, &mut b] {
        inst.set_friction_model(FrictionModel::ElastoPlastic);
        inst.note_on(50);
    }
    let n = 20_000;
    let ticks: Vec<f64> = (0..n).map(|_| a.tick(bow).audio).collect();
    let mut block = vec![0.0; n];
    for chunk in block.chunks_mut(97) {
        b.process(bow, chunk);
    }
    // -60 dBFS: a bowed note at 1.1 N is far louder.
    assert!(rms(&ticks) > 1e-3);
    assert!(ticks
        .iter()
        .zip(&block)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
}

/// Asleep, a block is zeros without a per-sample call: the same bits as ticking, through
/// an asleep start, a note, its release and the string falling asleep again (violin E6:
/// its energy falls to the sleep threshold within the run), with `update_sleep` at every
/// block boundary as the plugin calls it.
#[test]
fn block_processing_through_sleep_gives_the_same_bits_as_ticking() {
    let bow = BowControl::default();
    let mut a = Instrument::new(InstrumentKind::Violin, FS);
    let mut b = a.clone();
    let block = 256;
    let (mut ticks, mut blocks) = (Vec::new(), Vec::new());
    let mut slept = 0;
    for k in 0..(8.0 * FS) as usize / block {
        let t = k * block;
        for inst in [&mut a, &mut b] {
            inst.update_sleep();
            if t == block * 20 {
                inst.note_on(100);
            }
            if t == block * 20 + (0.3 * FS) as usize / block * block {
                inst.note_off(100);
            }
        }
        if !a.is_ringing() {
            slept += 1;
        }
        ticks.extend((0..block).map(|_| a.tick(bow).audio));
        let mut out = vec![1.0; block];
        b.process(bow, &mut out);
        blocks.extend(out);
    }
    // -80 dBFS: a bowed note is far louder.
    assert!(rms(&ticks) > 1e-4, "the note did not sound");
    assert!(!a.is_ringing(), "the string never fell asleep again");
    // 20 blocks before the note, and the rest of the 8 s once the string rings out
    // (within 3.2 s of its release: tests/plugin_host.rs).
    assert!(slept > 40, "asleep for only {slept} blocks");
    assert!(ticks
        .iter()
        .zip(&blocks)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
}

#[test]
fn switching_friction_law_while_a_note_sounds_gives_no_click_or_blow_up() {
    let bow = BowControl {
        velocity_m_per_s: 0.1,
        force_n: 1.1,
        position_beta: 0.1,
    };
    let mut inst = Instrument::new(InstrumentKind::Cello, FS);
    inst.note_on(50);
    let mut audio = Vec::new();
    let order = [
        FrictionModel::ElastoPlastic,
        FrictionModel::Stribeck,
        FrictionModel::LuGre,
        FrictionModel::Hyperbolic,
        FrictionModel::ElastoPlastic,
    ];
    let segment = (0.4 * FS) as usize;
    for model in order {
        inst.set_friction_model(model);
        audio.extend((0..segment).map(|_| inst.tick(bow).audio));
    }
    let steady = rms(&audio[segment / 2..segment]);
    // A click shows as a sample-to-sample jump far beyond the waveform's own steps.
    let step = |range: std::ops::Range<usize>| {
        audio[range]
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0f64, f64::max)
    };
    let normal = step(segment / 2..segment);
    for k in 1..order.len() {
        let at = k * segment;
        let jump = step(at - 2..at + 2);
        println!(
            "switch to {:?}: largest step {jump:.4} (steady steps up to {normal:.4})",
            order[k]
        );
        // The switch itself is no louder than the Helmholtz corners (2x margin).
        assert!(
            jump <= 2.0 * normal,
            "click at the switch to {:?}",
            order[k]
        );
    }
    let peak = audio.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(audio.iter().all(|x| x.is_finite()));
    // No blow-up: the peak stays within a few times the steady level.
    assert!(
        peak < 5.0 * steady * 2f64.sqrt() * 2.0,
        "peak {peak}, steady RMS {steady}"
    );
}

#[test]
fn the_authors_modal_scenario_sticks_and_slips_while_the_bow_accelerates() {
    let mut scene = RubbedScene::new(RubbedPreset::PaperModal, 44_100.0).unwrap();
    let frames: Vec<_> = (0..44_100)
        .map(|_| scene.tick(scene.preset_bow()))
        .collect();
    let bow_end = frames.last().unwrap().contact.exciter_velocity_m_per_s;
    // 1e-3 m/s, as for the cello above: bristle creep keeps the contact off exact
    // sticking.
    let sticking: Vec<bool> = frames
        .iter()
        .map(|f| f.relative_velocity_m_per_s.abs() < 1e-3)
        .collect();
    let stick = sticking.iter().filter(|&&s| s).count();
    // Sticks that begin after a slip: stick-slip, not the start from rest.
    let sticks = sticking.windows(2).filter(|w| !w[0] && w[1]).count();
    let peak = frames.iter().fold(0.0f64, |m, f| {
        m.max(f.contact.resonator_velocity_m_per_s.abs())
    });
    println!(
        "paper modal: bow velocity after 1 s {bow_end:.4} m/s, {stick} sticking samples in {sticks} sticks after a slip, resonator peak {peak:.4} m/s, Newton within 7: {:.4}",
        scene.solver_stats().fraction_within(7)
    );
    // The pushed bow reaches the target sliding velocity (0.5 m/s) within 5 %: it closes on
    // it at sigma2's time constant (the 50 g bow over 0.4 kg/s, 0.125 s), measured
    // 0.4998 m/s after 1 s and within 5 % from about 0.4 s.
    assert!((bow_end - 0.5).abs() < 0.025);
    // On the way there the contact stuck and slipped (the bow dragged the resonator
    // along): measured 470 samples, 142 from rest to the first slip and 328 in 40 sticks
    // over the first 0.13 s; 100 samples asks for sticking, 10 sticks after a slip for
    // stick-slip rather than the start from rest alone.
    assert!(stick > 100);
    assert!(sticks >= 10, "{sticks} sticks after a slip");
    // Measured 0.378 m/s; 0.01 m/s (2 % of the bow's 0.5 m/s) tells a resonator the
    // contact drives from one left still.
    assert!(peak > 0.01 && peak.is_finite());
    assert_eq!(scene.solver_stats().fallbacks, 0);
}

#[test]
fn every_friction_sound_effect_preset_sounds_and_stays_bounded_with_every_law() {
    use colophony::dsp::rubbed::RubbedInstrument;
    let mut failures = Vec::new();
    for preset in RubbedPreset::ALL {
        if preset == RubbedPreset::PaperModal {
            continue;
        }
        for model in [
            FrictionModel::ElastoPlastic,
            FrictionModel::LuGre,
            FrictionModel::Stribeck,
        ] {
            // As the plugin plays it: exciter landing over 20 ms, at the preset's own
            // velocity and force.
            let mut inst = RubbedInstrument::new(FS);
            inst.set_preset(preset);
            inst.set_friction_model(model);
            inst.note_on();
            let audio: Vec<f64> = (0..(2.0 * FS) as usize)
                .map(|_| inst.tick_scaled(1.0, 1.0))
                .collect();
            let late = rms(&audio[FS as usize..]);
            let peak = audio.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            println!(
                "{:14} {:15} RMS {late:.3} peak {peak:.3}",
                preset.name(),
                model.name()
            );
            assert!(audio.iter().all(|x| x.is_finite()));
            // Self-sustained with the bristle laws: still sounding after a second (-40 dBFS
            // at least). The static law may settle into steady sliding (silence).
            if model != FrictionModel::Stribeck && late <= 0.01 {
                failures.push(format!(
                    "{} with {}: died away",
                    preset.name(),
                    model.name()
                ));
            }
            // Never beyond a float output's full scale.
            if peak >= 1.0 {
                failures.push(format!(
                    "{} with {}: peak {peak}",
                    preset.name(),
                    model.name()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn elasto_plastic_and_lugre_converge_to_the_static_curve_as_the_bristles_stiffen() {
    // The static Stribeck curve is the sigma0 -> infinity limit of both bristle laws (with
    // sigma1 = sigma2 = 0). Sweep the sliding velocity slowly from -0.5 to 0.5 m/s against
    // a rigid support and compare the friction force with mu(v) F_N sgn(v) away from v = 0
    // (where the static law is set valued): the lag of the bristles shrinks as 1/sigma0.
    let static_mu = |v: f64| 0.2 + 0.2 * (-(v / 0.1f64).powi(2)).exp();
    let load = LoadLine {
        free_velocity_m_per_s: 0.0,
        admittance_s_per_kg: 0.0,
    };
    for law in [BristleLaw::ElastoPlastic, BristleLaw::LuGre] {
        let errors: Vec<(f64, f64)> = [1e3, 1e4, 1e5, 1e6]
            .into_iter()
            .map(|sigma0_n_per_m| {
                let p = BristleParams {
                    sigma0_n_per_m,
                    sigma1_kg_per_s: 0.0,
                    sigma2_kg_per_s: 0.0,
                    ..BristleParams::modal_scenario()
                };
                let mut c = BristleFriction::new(p, law, FS).unwrap();
                let n = FS as usize / 10;
                let mut worst = 0.0f64;
                for k in 0..=n {
                    let v = -0.5 + k as f64 / n as f64;
                    let bow = BowInput {
                        velocity_m_per_s: v,
                        normal_force_n: 1.0,
                    };
                    let f = c.solve(load, bow);
                    if v.abs() > 0.05 {
                        worst = worst.max((f - v.signum() * static_mu(v)).abs());
                    }
                }
                (sigma0_n_per_m, worst)
            })
            .collect();
        println!("{law:?}: largest force error against the static curve by sigma0: {errors:.3?}");
        let orders: Vec<f64> = errors
            .windows(2)
            .map(|w| (w[0].1 / w[1].1).log10())
            .collect();
        println!("{law:?}: observed orders per decade of sigma0: {orders:.2?}");
        // Monotone convergence; over three decades at least a 30-fold reduction (average
        // order 0.5: the worst case sits just after each velocity reversal, where the
        // bristles are still crossing from -z_ss to +z_ss, which is pre-asymptotic at the
        // softer settings; the rate rises toward first order in the last decade).
        assert!(orders.iter().all(|o| *o > 0.0), "{law:?}: {errors:?}");
        assert!(errors[0].1 / errors[3].1 > 30.0, "{law:?}: {errors:?}");
    }
}
