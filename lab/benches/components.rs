//! Criterion benches per component, for profiling (`cargo bench --bench components`;
//! `-- --quick` for a fast pass): one friction solve per law on the cello D load line, one
//! waveguide string sample, one thermal string sample at N_B 10 and 60, and one modal
//! bridge junction solve (four strings, the shipped 14-mode cello bridge), and one sample
//! of the cello bowing D3 bare and through the performer, one sample at a time, as a block
//! and as a run with the bow given per sample (the performance layer's cost is their
//! difference). Whole-model costs against precision are `colophony bench precision`.

use colophony::dsp::bridge::{solve_junction, ModalBridge};
use colophony::dsp::friction::bristle::{BristleFriction, BristleLaw, BristleParams};
use colophony::dsp::friction::stribeck::StribeckFriction;
use colophony::dsp::friction::{
    AnyFriction, BowInput, FrictionContact, FrictionModel, HyperbolicFriction, LoadLine,
};
use colophony::dsp::thermal::{
    HairParams, ThermalBowControl, ThermalParams, ThermalString, ThermalStringSpec,
};
use colophony::dsp::vocabulary::InstrumentKind;
use colophony::dsp::waveguide::WaveguideString;
use colophony_lab::admittance_fit::shipped_bridge;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

const FS: f64 = 48_000.0;
/// Cello D, bow at one point: the two half-strings in parallel, `Y = 1 / (2 Z0)`.
const CELLO_D_ADMITTANCE_S_PER_KG: f64 = 1.0 / (2.0 * 0.506);

/// Free velocities across one Helmholtz period (sticking near the bow velocity, slipping
/// far below it), so each solve sees a changing load as in the string.
fn load_lines() -> Vec<LoadLine> {
    (0..64)
        .map(|i| LoadLine {
            free_velocity_m_per_s: if i < 58 {
                0.1 - 0.002 * (i % 7) as f64
            } else {
                -0.9
            },
            admittance_s_per_kg: CELLO_D_ADMITTANCE_S_PER_KG,
        })
        .collect()
}

fn friction_solve(c: &mut Criterion) {
    let bow = BowInput {
        velocity_m_per_s: 0.1,
        normal_force_n: 1.1,
    };
    let loads = load_lines();
    let mut group = c.benchmark_group("friction solve (one sample)");
    let mut bench = |name: &str, contact: &mut dyn FrictionContact| {
        let mut i = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                i = (i + 1) % loads.len();
                black_box(contact.solve(black_box(loads[i]), bow))
            })
        });
    };
    bench("hyperbolic", &mut HyperbolicFriction::default());
    bench("static (Stribeck)", &mut StribeckFriction::default());
    for (name, law) in [
        ("lugre", BristleLaw::LuGre),
        ("elasto-plastic", BristleLaw::ElastoPlastic),
    ] {
        let mut contact =
            BristleFriction::new(BristleParams::waveguide_string(), law, FS).expect("valid");
        bench(name, &mut contact);
    }
    group.finish();
}

fn waveguide_tick(c: &mut Criterion) {
    let spec = InstrumentKind::Cello.strings()[2];
    let mut string = WaveguideString::new(spec, FS, 60.0);
    let mut contact = AnyFriction::new(
        FrictionModel::Hyperbolic,
        BristleParams::waveguide_string(),
        FS,
    )
    .expect("valid");
    let bow = BowInput {
        velocity_m_per_s: 0.1,
        normal_force_n: 1.1,
    };
    // Into Helmholtz motion first, so the bench times the steady loop.
    for _ in 0..FS as usize / 2 {
        string.tick(&mut contact, bow);
    }
    c.bench_function("waveguide string tick (cello D, hyperbolic)", |b| {
        b.iter(|| black_box(string.tick(&mut contact, black_box(bow))))
    });
}

fn performer_tick(c: &mut Criterion) {
    use colophony::dsp::instrument::Instrument;
    use colophony::dsp::vocabulary::BowControl;
    use colophony::performer::{Performer, Setup};
    let bow = BowControl::default();
    let mut group = c.benchmark_group("cello D3 bowed, one sample");
    let mut bare = Instrument::new(InstrumentKind::Cello, FS);
    bare.note_on(50);
    for _ in 0..FS as usize / 2 {
        bare.tick(bow);
    }
    group.bench_function("instrument", |b| {
        b.iter(|| black_box(bare.tick(black_box(bow))))
    });
    let setup = Setup::default();
    let mut performer = Performer::new(InstrumentKind::Cello);
    performer
        .activate(&setup, FS)
        .expect("the default setup activates");
    performer.configure(&setup);
    performer.note_on(50, 0.8);
    for _ in 0..FS as usize / 2 {
        performer.tick(bow);
    }
    group.bench_function("through the performer", |b| {
        b.iter(|| black_box(performer.tick(black_box(bow))))
    });
    group.finish();
    // As the plugin plays a settled block: the strings' own loop against the performer's
    // block path (the gesture steady).
    let mut group = c.benchmark_group("cello D3 bowed, a block of 512");
    let mut block = [0.0f64; 512];
    group.bench_function("instrument", |b| {
        b.iter(|| {
            bare.process(black_box(bow), &mut block);
            black_box(block[511])
        })
    });
    group.bench_function("through the performer", |b| {
        b.iter(|| {
            performer.process(black_box(bow), &mut block);
            black_box(block[511])
        })
    });
    group.finish();
    // As the plugin plays while automation moves or a live view listens: the bow handed
    // over sample by sample, the strings' own loop against the performer's run.
    let mut group = c.benchmark_group("cello D3 bowed, a run of 512 with the bow per sample");
    let played = performer.bow();
    group.bench_function("instrument", |b| {
        b.iter(|| {
            for sample in block.iter_mut() {
                *sample = bare.tick(black_box(played)).audio;
            }
            black_box(block[511])
        })
    });
    group.bench_function("through the performer", |b| {
        b.iter(|| {
            performer.process_run(
                block.len(),
                || (black_box(bow), ()),
                |k, (), frame, _, _| block[k] = frame.audio,
            );
            black_box(block[511])
        })
    });
    group.finish();
}

fn thermal_tick(c: &mut Criterion) {
    let bow = ThermalBowControl {
        velocity_m_per_s: 0.15,
        force_n_per_m: 300.0,
        position_beta: 0.1,
    };
    let mut group = c.benchmark_group("thermal string tick (internal rate)");
    for nodes in [10, 60] {
        let mut string = ThermalString::new(
            ThermalStringSpec::cello_c(),
            nodes,
            0.01,
            ThermalParams::default(),
            HairParams::default(),
        )
        .expect("valid");
        // A tenth of a second into the note.
        for _ in 0..(0.1 * string.internal_rate_hz()) as usize {
            string.tick(bow);
        }
        group.bench_function(format!("N_B {nodes}"), |b| {
            b.iter(|| black_box(string.tick(black_box(bow))))
        });
    }
    group.finish();
}

fn bridge_junction(c: &mut Criterion) {
    let modes = shipped_bridge(InstrumentKind::Cello).modes;
    let mut bridge = ModalBridge::new(&modes, FS).expect("valid");
    let z = [0.9, 0.7, 0.5, 0.35];
    let mut leaving = [[0.0; 2]; 4];
    let mut n = 0u32;
    c.bench_function("modal bridge junction (4 strings, 14 modes)", |b| {
        b.iter(|| {
            n = n.wrapping_add(1);
            let s = (n % 97) as f64 * 1e-3;
            let arriving = [[s, -s], [0.5 * s, 0.0], [0.0, s], [-s, 0.2 * s]];
            black_box(solve_junction(
                &mut bridge,
                black_box(&arriving),
                &z,
                &mut leaving,
            ))
        })
    });
}

criterion_group!(
    components,
    friction_solve,
    waveguide_tick,
    performer_tick,
    thermal_tick,
    bridge_junction
);
criterion_main!(components);
