//! Physics of the point-bow waveguide model, checked through the offline renderer:
//! Raman's Helmholtz motion, tuning of the free string across every instrument's range,
//! bowed pitch, passivity with the bow lifted.

use colophony::analysis::{cents, peak_frequency_hz, rms, slip_stats};
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony_lab::render::{render, RenderSettings};

const FS: f64 = 48_000.0;

fn settings(instrument: InstrumentKind, note: u8) -> RenderSettings {
    RenderSettings {
        instrument,
        note,
        sample_rate_hz: FS,
        ..RenderSettings::default()
    }
}

fn window(x: &[f64], from_s: f64, to_s: f64, fs: f64) -> &[f64] {
    &x[(from_s * fs) as usize..(to_s * fs) as usize]
}

/// Slip statistics of cello D3 bowed for 2.5 s with `bow`, over 1.5..2.5 s.
fn cello_d3_slips(bow: BowControl) -> colophony::analysis::SlipStats {
    let out = render(&RenderSettings {
        seconds: 2.5,
        bow,
        ..settings(InstrumentKind::Cello, 50)
    })
    .unwrap();
    let v = window(&out.bow_point_velocity_m_per_s, 1.5, 2.5, FS);
    // Sticking is exact in the model (v_s = v_b to rounding): 1e-9 m/s separates it.
    slip_stats(v, bow.velocity_m_per_s, FS, midi_to_hz(50.0), 1e-9)
}

#[test]
fn helmholtz_slip_fraction_equals_beta_with_one_slip_per_period() {
    let s = settings(InstrumentKind::Cello, 50);
    let stats = cello_d3_slips(s.bow);
    let beta = s.bow.position_beta;
    println!("cello D3 at defaults: {stats:?}, beta {beta}");
    // Raman: the corners pass the bow beta of a period apart. The rounded corners' centres
    // measure 0.104 at beta 0.1 (docs/papers-reproduced.md) and the bow position is
    // rounded to the grid by under 1 %: 10 % holds both.
    assert!(
        (stats.slip_fraction - beta).abs() < 0.1 * beta,
        "corner-to-corner slip fraction {}",
        stats.slip_fraction
    );
    // One slip per period (over ~147 periods; only the window edges can add a fraction).
    assert!(
        (stats.slips_per_period - 1.0).abs() < 0.02,
        "slips/period {}",
        stats.slips_per_period
    );
    // Sticking velocity is the bow velocity (within 10 %).
    let vb = s.bow.velocity_m_per_s;
    // 10 %: the playing-space map's Helmholtz criterion (docs/playing-space.md); sticking
    // is exact in the model, and measures 0.100 m/s (docs/papers-reproduced.md).
    assert!((stats.stick_velocity_m_per_s - vb).abs() < 0.1 * vb);
    // Raman's slip velocity -v_b (1 - beta) / beta is not asserted: the rounded corners
    // take part of the slip plateau between the half-jump points (see the next test).
    println!(
        "slip plateau {:.3} m/s, Raman {:.3}; velocity jump {:.3} m/s, Raman v_b/beta {:.3}",
        stats.slip_velocity_m_per_s,
        -vb * (1.0 - beta) / beta,
        stats.jump_m_per_s,
        vb / beta
    );
}

#[test]
fn corner_rounding_shrinks_as_bow_force_rises() {
    // Cremer: the losses round the Helmholtz corner, the friction force sharpens it at each
    // slip; more force, sharper corners, so the strict slip time falls toward beta.
    // From 1 N (F_max / 5 on cello D3): at 0.5 N (F_max / 10) the string with the bow
    // hair and the intonation table still slips 1.2 times a period after
    // 1.5 s (docs/playing-space.md: below about F_max / 6 the point bow settles late or
    // not at all), so the corners there are not Helmholtz corners.
    let base = settings(InstrumentKind::Cello, 50).bow;
    let strict: Vec<(f64, f64)> = [1.0, 2.0, 3.0]
        .into_iter()
        .map(|force_n| {
            let stats = cello_d3_slips(BowControl { force_n, ..base });
            // One slip per period over ~147 periods, as above: only the window edges add a
            // fraction.
            assert!(
                (stats.slips_per_period - 1.0).abs() < 0.02,
                "{force_n} N: {stats:?}"
            );
            (force_n, stats.strict_slip_fraction)
        })
        .collect();
    println!(
        "strict slip fraction against bow force (beta {}): {strict:?}",
        base.position_beta
    );
    for pair in strict.windows(2) {
        assert!(pair[1].1 < pair[0].1, "rounding grew with force: {pair:?}");
    }
    // Always at least beta: the flanks only add time to the ideal slip.
    // 5 %: the slip (about 33 of 327 samples) is counted in whole samples, 3 % each,
    // and the bow position is rounded to the grid by under 1 %.
    assert!(strict.iter().all(|(_, f)| *f >= 0.95 * base.position_beta));
}

#[test]
fn helmholtz_amplitude_scales_as_bow_velocity_over_beta() {
    // Raman: the velocity jump at the bow is v_b / beta, so it doubles when v_b doubles or
    // beta halves.
    // Bow force scaled so each case sits at the same place in its Schelleng window
    // (F_max ~ v_b / beta, F_min ~ v_b / beta^2: force ~ v_b / beta^1.5), so the corner
    // rounding, which depends on that place, is comparable.
    let jump = |velocity_m_per_s: f64, position_beta: f64| {
        let bow = BowControl {
            velocity_m_per_s,
            force_n: 1.5 * (velocity_m_per_s / 0.1) * (0.12 / position_beta).powf(1.5),
            position_beta,
        };
        let stats = cello_d3_slips(bow);
        // One slip per period over ~147 periods: only the window edges add a fraction.
        assert!(
            (stats.slips_per_period - 1.0).abs() < 0.02,
            "{bow:?}: {stats:?}"
        );
        stats.jump_m_per_s
    };
    let base = jump(0.1, 0.12);
    let faster = jump(0.2, 0.12);
    let closer = jump(0.1, 0.06);
    println!(
        "velocity jump at the bow: base {base:.4}, 2 v_b {faster:.4}, beta/2 {closer:.4} m/s; \
         Raman v_b/beta = {:.4}",
        0.1 / 0.12
    );
    // 10 % of Raman's value for the base case, and the two doublings within 10 %. Measured
    // 0.828 m/s (0.6 % under Raman), ratios 1.93 (2 v_b) and 1.88 (beta/2): the jump is
    // sticking minus the slip plateau's mean, and the rounded corners take part of that
    // plateau (above), a larger part of beta 0.06's shorter slip.
    assert!((base - 0.1 / 0.12).abs() < 0.1 * (0.1 / 0.12));
    assert!((faster / base - 2.0).abs() < 0.2);
    assert!((closer / base - 2.0).abs() < 0.2);
}

/// Where the intonation table puts the free decay of `note` on `kind` (hyperbolic law,
/// the usual string): equal temperament moved by the table's correction, Hz.
fn tuned_free_decay_hz(kind: InstrumentKind, note: u8) -> f64 {
    use colophony::dsp::intonation::{shipped, TunedModel};
    let string = kind.string_for_note(note).unwrap();
    let above_open = (note - kind.open_notes()[string]) as f64;
    let c = shipped().correction_cents(
        TunedModel::Point(colophony::dsp::friction::FrictionModel::Hyperbolic).row(),
        kind,
        string,
        above_open,
    );
    midi_to_hz(note as f64 - c / 100.0)
}

/// Bows `note`, lifts the bow, and measures the first partial of the free decay against
/// where the intonation table tunes it.
fn free_decay_pitch_error_cents(instrument: InstrumentKind, note: u8) -> f64 {
    let s = RenderSettings {
        seconds: 3.7,
        release_s: Some(1.0),
        ..settings(instrument, note)
    };
    let out = render(&s).unwrap();
    let decay = window(&out.audio, 1.2, 3.7, FS);
    let want = tuned_free_decay_hz(instrument, note);
    let f = peak_frequency_hz(decay, FS, want, 50.0);
    cents(f, want)
}

#[test]
fn free_decay_sits_where_the_intonation_table_tunes_it_across_every_range() {
    for kind in InstrumentKind::ALL {
        let open = kind.open_notes();
        let mut notes: Vec<u8> = open.to_vec();
        notes.extend([open[0] + 5, open[1] + 7, open[3] + 12, open[3] + 24]);
        for note in notes {
            let err = free_decay_pitch_error_cents(kind, note);
            println!("{} note {note}: free decay {err:+.3} cents", kind.name());
            // 2 cents: below what players hear (tests/plugin_host.rs); the estimator itself
            // is good to 0.01 cent.
            assert!(
                err.abs() < 2.0,
                "{} note {note}: {err:+.3} cents",
                kind.name()
            );
        }
    }
}

#[test]
fn bowed_pitch_at_defaults_within_ten_cents() {
    let s = settings(InstrumentKind::Cello, 50);
    let out = render(&RenderSettings { seconds: 3.0, ..s }).unwrap();
    let steady = window(&out.audio, 1.0, 3.0, FS);
    let f = peak_frequency_hz(steady, FS, midi_to_hz(50.0), 50.0);
    let err = cents(f, midi_to_hz(50.0));
    println!("cello D3 bowed at defaults: {err:+.3} cents (bow-force flattening)");
    // 10 cents is where a note starts to sound out of tune (tests/plugin_host.rs);
    // measured +0.2 cents (docs/papers-reproduced.md).
    assert!(err.abs() < 10.0);
}

#[test]
fn energy_never_grows_with_bow_lifted() {
    let s = RenderSettings {
        seconds: 3.0,
        release_s: Some(1.0),
        ..settings(InstrumentKind::Violin, 69)
    };
    let out = render(&s).unwrap();
    // after the 20 ms bow lift, RMS over successive 50 ms windows (22 periods) decays
    let after = window(&out.audio, 1.05, 3.0, FS);
    let levels: Vec<f64> = after.chunks(2400).map(rms).collect();
    for pair in levels.windows(2) {
        // 1e-6 relative: windows hold whole-ish periods, so beating between partials
        // can only move the RMS by rounding-level amounts when nothing gains energy
        assert!(pair[1] <= pair[0] * (1.0 + 1e-6), "level grew: {pair:?}");
    }
    // At Q1 500, A4's amplitude falls by e in Q / (pi f) = 0.36 s: over 1.9 s, far
    // under 0.9.
    assert!(levels.last().unwrap() < &(levels[0] * 0.9));
}

#[test]
fn output_is_finite_and_free_of_subnormals_at_extreme_rates_and_settings() {
    for &fs in &[1000.0, 8000.0, 44_100.0, 384_000.0, 768_000.0] {
        for kind in InstrumentKind::ALL {
            let (low, high) = kind.note_range();
            for note in [low, high] {
                for bow in [
                    BowControl {
                        velocity_m_per_s: 1.5,
                        force_n: 10.0,
                        position_beta: 0.02,
                    },
                    BowControl {
                        velocity_m_per_s: -1.5,
                        force_n: 0.0,
                        position_beta: 0.5,
                    },
                    BowControl {
                        velocity_m_per_s: 0.0,
                        force_n: 10.0,
                        position_beta: 0.5,
                    },
                ] {
                    let seconds = if fs > 100_000.0 { 0.05 } else { 0.3 };
                    let s = RenderSettings {
                        instrument: kind,
                        note,
                        seconds,
                        bow,
                        sample_rate_hz: fs,
                        release_s: Some(seconds / 2.0),
                        ..RenderSettings::default()
                    };
                    let out = render(&s).unwrap();
                    for x in out.audio.iter().map(|&x| x as f32) {
                        assert!(
                            x == 0.0 || x.is_normal(),
                            "{fs} Hz {} note {note}: sample {x}",
                            kind.name()
                        );
                        // The bow's largest velocity jump, v_b / beta = 1.5 / 0.02 =
                        // 75 m/s, reaches the output as at most 15 (tests/stress.rs,
                        // `peak_bound`).
                        assert!(
                            x.abs() < 16.0,
                            "{fs} Hz {} note {note}: sample {x}",
                            kind.name()
                        );
                    }
                }
            }
        }
    }
}

/// Renders a score on an instrument with sleeping on or off (blocks of 256 like the plugin).
fn render_score(
    kind: InstrumentKind,
    score: &[(usize, bool, u8)],
    frames: usize,
    skipping: bool,
) -> (Vec<f64>, usize) {
    use colophony::dsp::instrument::Instrument;
    let mut inst = Instrument::new(kind, FS);
    inst.set_skipping(skipping);
    let mut out = Vec::with_capacity(frames);
    let mut next = 0;
    let mut slept_blocks = 0;
    for i in 0..frames {
        if i % 256 == 0 {
            inst.update_sleep();
            slept_blocks += (i > 0 && inst.awake_strings() == 0) as usize;
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
        out.push(inst.tick(BowControl::default()).audio);
    }
    (out, slept_blocks)
}

#[test]
fn waking_from_sleep_matches_never_sleeping_and_keeps_the_pitch() {
    // A high violin note rings out within a second, sleeps, and is bowed again. The note
    // must be one whose bowed motion is periodic at the defaults: in an irregular regime
    // (several high violin notes are) the attack is chaotic, and the 1e-16 J left in the
    // never-sleeping string grows into a different waveform within a period, sleep or
    // not. MIDI 99 is periodic.
    let s = |t: f64| (t * FS) as usize;
    let score = [
        (0, true, 99u8),
        (s(0.3), false, 99),
        (s(3.0), true, 99),
        (s(3.5), false, 99),
    ];
    let frames = s(4.0);
    let (slept, blocks) = render_score(InstrumentKind::Violin, &score, frames, true);
    let (full, none) = render_score(InstrumentKind::Violin, &score, frames, false);
    let peak = full.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = slept
        .iter()
        .zip(&full)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let db = 20.0 * (diff / peak).log10();
    println!("slept {blocks} blocks (none without skipping: {none}); largest difference {db:.0} dB below the peak");
    // The note rings out within a second of its release at 0.3 s and sleeps until 3.0 s:
    // about 1.7 s, some 300 blocks of 256.
    assert!(blocks > 100 && none == 0, "the string never slept");
    // The sleep threshold (1e-16 J against a few mJ bowed) is -130 dB in energy; the
    // difference can only be what was cleared at that level.
    assert!(db < -100.0, "waking differs by {db:.1} dB");
    let f = midi_to_hz(99.0);
    let after = |x: &[f64]| peak_frequency_hz(&x[s(3.1)..s(3.5)], FS, f, 50.0);
    let shift = cents(after(&slept), after(&full));
    println!("pitch after waking: {shift:+.4} cents from never sleeping");
    // The renders differ by under -100 dB, so the peak search finds the same pitch in both
    // to far better than 0.01 cents.
    assert!(shift.abs() < 0.01);
}

/// The plugin's point strings run at one internal rate whatever the host's: the same note,
/// bowing and friction law give the same motion and pitch at every host rate. Checked for
/// every point law on cello D3 (paper A's scene, 1.1 N, beta 0.1) and violin A5 (defaults),
/// host rates 22.05 to 384 kHz.
#[test]
fn the_bowed_string_plays_the_same_motion_and_pitch_at_every_host_rate() {
    use colophony::dsp::friction::FrictionModel;
    let bow = BowControl {
        velocity_m_per_s: 0.1,
        force_n: 1.1,
        position_beta: 0.1,
    };
    for friction in FrictionModel::ALL {
        for (instrument, note) in [(InstrumentKind::Cello, 50), (InstrumentKind::Violin, 81)] {
            let f0 = midi_to_hz(note as f64);
            let measure = |fs: f64| {
                let out = render(&RenderSettings {
                    instrument,
                    note,
                    seconds: 1.5,
                    bow,
                    sample_rate_hz: fs,
                    friction,
                    ..RenderSettings::default()
                })
                .unwrap();
                let v = window(&out.bow_point_velocity_m_per_s, 0.5, 1.5, fs);
                // 1e-3 m/s (1 % of the bow velocity): the bristle laws creep while sticking.
                let stats = slip_stats(v, bow.velocity_m_per_s, fs, f0, 1e-3);
                let pitch = peak_frequency_hz(window(&out.audio, 0.5, 1.5, fs), fs, f0, 50.0);
                (stats, pitch)
            };
            let (reference, reference_pitch) = measure(48_000.0);
            for fs in [22_050.0, 44_100.0, 96_000.0, 192_000.0, 384_000.0] {
                let (stats, pitch) = measure(fs);
                let label = format!("{} {instrument:?} {note} at {fs} Hz", friction.name());
                // The host rate only resamples the output. The probe holds the last
                // internal sample: above 48 kHz it sees every one (a slip's edges move by
                // up to one internal sample in a period of 327 or 55); below, it skips
                // some, so the motion is compared there through the pitch alone.
                if fs > 48_000.0 {
                    assert!(
                        (stats.slips_per_period - reference.slips_per_period).abs() < 0.05,
                        "{label}: {} slips per period against {} at 48 kHz",
                        stats.slips_per_period,
                        reference.slips_per_period
                    );
                    assert!(
                        (stats.strict_slip_fraction - reference.strict_slip_fraction).abs()
                            < 0.02 * reference.strict_slip_fraction.max(0.05),
                        "{label}: slip fraction {} against {}",
                        stats.strict_slip_fraction,
                        reference.strict_slip_fraction
                    );
                }
                // 0.1 cent: the same internal motion, only resampled; the peak search's own
                // resolution over 1 s is finer still.
                let moved = cents(pitch, reference_pitch).abs();
                assert!(
                    moved < 0.1,
                    "{label}: pitch moved {moved} cents from 48 kHz"
                );
            }
        }
    }
}

/// The bowed pitch (Hz, over 0.5-1.5 s) of `instrument`'s `note` with `friction` at 1 N,
/// beta 0.1, 0.1 m/s: the plugin's model at host rate `fs`, or (`native_rate`) the strings
/// at `fs`.
fn bowed_pitch(
    instrument: InstrumentKind,
    note: u8,
    friction: colophony::dsp::friction::FrictionModel,
    fs: f64,
    native_rate: bool,
) -> f64 {
    let out = render(&RenderSettings {
        instrument,
        note,
        seconds: 1.5,
        bow: BowControl {
            velocity_m_per_s: 0.1,
            force_n: 1.0,
            position_beta: 0.1,
        },
        sample_rate_hz: fs,
        friction,
        native_rate,
        ..RenderSettings::default()
    })
    .unwrap();
    peak_frequency_hz(
        window(&out.audio, 0.5, 1.5, fs),
        fs,
        midi_to_hz(note as f64),
        50.0,
    )
}

/// The violin's top octave against the same strings at 192 kHz (the refined reference).
/// A point bow's slip starts on a sample, so the Helmholtz period locks to the strings'
/// sample grid, by up to half a sample a period (docs/playing-space.md, "The sample-grid
/// lock"); the violin's strings run at 96 kHz inside for that
/// (`InstrumentKind::point_oversampling`). Every friction law, A5 to A6 every second
/// semitone, bowed at 1 N, beta 0.1, 0.1 m/s through the plugin's model at a 48 kHz host,
/// the 192 kHz strings, and the strings at 48 kHz themselves; the bowed pitch over
/// 0.5-1.5 s.
#[test]
fn the_violins_top_octave_plays_the_refined_models_pitch() {
    use colophony::dsp::friction::FrictionModel;
    let mut plugin = Vec::new();
    let mut coarse = Vec::new();
    for friction in FrictionModel::ALL {
        for note in (81..=93).step_by(2) {
            let pitch = |fs: f64, native_rate: bool| {
                bowed_pitch(InstrumentKind::Violin, note, friction, fs, native_rate)
            };
            let reference = pitch(192_000.0, true);
            let p = cents(pitch(48_000.0, false), reference);
            let c = cents(pitch(48_000.0, true), reference);
            println!(
                "{} violin {note}: plugin {p:+.1}, 48 kHz strings {c:+.1} cents from 192 kHz",
                friction.name()
            );
            plugin.push(p.abs());
            coarse.push(c.abs());
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (p, c) = (median(&mut plugin), median(&mut coarse));
    println!("median |difference| from 192 kHz: plugin {p:.2} cents, 48 kHz strings {c:.2}");
    // ±3 cents, the playing-space map's bound for a note in tune (docs/playing-space.md):
    // the plugin's discretisation may not move the median note by more.
    assert!(
        p < 3.0,
        "plugin median {p:.2} cents from the 192 kHz strings"
    );
    // The lock's width goes as the sample period, and the reference has its own quarter:
    // (1/96 + 1/192) / (1/48 + 1/192) = 0.6 of the 48 kHz strings' difference expected;
    // 0.75 leaves room for notes whose attack picks another limit cycle.
    assert!(
        p < 0.75 * c,
        "plugin {p:.2} cents against {c:.2} with 48 kHz strings"
    );
}

/// The violin's strings run at 96 kHz inside a 48 kHz instrument (ticked twice a sample,
/// their bridge force decimated by a half-band filter before the body): they must play
/// the same model as the violin's strings run natively at 96 kHz. The two differ only in
/// the body's rate, the bow held over two string samples and the decimator, none of which
/// moves the string's period; an error in the wiring (a string tuned or stepped at the
/// wrong rate) would move every note. Every point law, seven notes from the open G to A6,
/// 1 N, beta 0.1: the median |pitch difference| within 0.05 cents (the peak search's
/// resolution over 1 s is finer). A median, because an attack may fall into another limit
/// cycle in either (measured: 22 of 28 cells agree to 0.02 cents, the others are a double
/// slip or a longer slip in one of the two).
#[test]
fn the_violins_oversampled_strings_play_the_native_96_khz_model() {
    use colophony::dsp::friction::FrictionModel;
    let mut differences = Vec::new();
    for friction in FrictionModel::ALL {
        for note in [55u8, 62, 69, 76, 81, 86, 93] {
            let d = cents(
                bowed_pitch(InstrumentKind::Violin, note, friction, 48_000.0, false),
                bowed_pitch(InstrumentKind::Violin, note, friction, 96_000.0, true),
            );
            println!(
                "{} violin {note}: {d:+.3} cents from native 96 kHz",
                friction.name()
            );
            differences.push(d.abs());
        }
    }
    differences.sort_by(f64::total_cmp);
    let median = differences[differences.len() / 2];
    assert!(
        median < 0.05,
        "median {median:.3} cents from the native 96 kHz strings"
    );
}

/// The cello's A string runs at 96 kHz inside and its three lower strings at 48 kHz: each
/// must play the same model as its strings run natively at that rate (a string stepped or
/// tuned at the other rate would move every note of it). Every point law; the lower
/// strings' notes C2, G2, D3, F#3 against native 48 kHz strings, the A string's A3, A4,
/// F#5 and D#6 against native 96 kHz ones; the median |pitch difference| within 0.05
/// cents, as for the violin (measured: median 0.000 on both; the lower strings' 16 cells
/// all within 0.001, 12 of the A string's 16 within 0.03, the other four 2-4 cents off,
/// another limit cycle in one of the two).
#[test]
fn the_cellos_strings_each_play_the_native_model_of_their_rate() {
    use colophony::dsp::friction::FrictionModel;
    for (notes, rate) in [([36u8, 43, 50, 54], 48_000.0), ([57, 69, 78, 87], 96_000.0)] {
        let mut differences = Vec::new();
        for friction in FrictionModel::ALL {
            for note in notes {
                let d = cents(
                    bowed_pitch(InstrumentKind::Cello, note, friction, 48_000.0, false),
                    bowed_pitch(InstrumentKind::Cello, note, friction, rate, true),
                );
                println!(
                    "{} cello {note}: {d:+.3} cents from native {} kHz",
                    friction.name(),
                    rate / 1000.0
                );
                differences.push(d.abs());
            }
        }
        differences.sort_by(f64::total_cmp);
        let median = differences[differences.len() / 2];
        assert!(
            median < 0.05,
            "median {median:.3} cents from the native {} kHz strings",
            rate / 1000.0
        );
    }
}
