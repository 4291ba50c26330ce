//! What the audio thread does for the editor's live views, checked for allocation: the
//! contact samples into the scope and the thermal bow's nodes into the node ring, as
//! `Colophony::process` does while an open editor listens. The host tests cannot open an
//! editor, so this drives the same calls inside nice-plug's allocation checker
//! (`assert_no_alloc`, the global allocator of the test build: Cargo.toml's
//! dev-dependencies), which aborts the test binary on any allocation.

use colophony::dsp::bridge_data::shipped_bridge;
use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
use colophony::editor::nodes::NodeProbe;
use colophony::editor::EditorLink;
use colophony::measure::contact::ContactSample;
use nice_assert_no_alloc::assert_no_alloc;
use std::process::Command;

/// Set in the child process of
/// [`an_allocation_inside_the_checker_aborts_the_test_binary`]: the child allocates inside
/// the checker.
const CHILD_ENV: &str = "COLOPHONY_EDITOR_FEED_ALLOCATING_CHILD";

#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "the allocation checker needs debug assertions"
)]
fn feeding_the_live_and_thermal_views_does_not_allocate() {
    let fs = 48_000.0;
    let bridge = shipped_bridge(InstrumentKind::Cello).modes;
    let mut cello = ThermalInstrument::new(
        InstrumentKind::Cello,
        &bridge,
        fs,
        ThermalSettings::default(),
    )
    .unwrap();
    let link = EditorLink::default();
    link.scope.set_sample_rate(fs as f32);
    let mut probe = NodeProbe::default();
    cello.note_on(50);
    let bow = BowControl::default();
    // Allocations, if any, happen on the first uses: checked from the first sample.
    assert_no_alloc(|| {
        for i in 0..(fs as usize / 2) {
            if i % 256 == 0 {
                cello.update_sleep();
            }
            let frame = cello.tick(bow);
            link.scope.push(ContactSample::new(&frame, &bow));
            probe.add_from(
                cello.probed_string().node_temperatures(),
                cello.probed_string().node_sliding_velocities(),
                &link,
            );
        }
    });
    // The views were fed: 0.5 s of samples, one node record every 5 ms.
    assert_eq!(link.scope.written(), 24_000);
    assert_eq!(link.nodes.written(), 100);
}

/// The checker the test above relies on is live in this binary: an allocation inside it
/// aborts the process (run in a child of this test binary, which must not exit cleanly).
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "the allocation checker needs debug assertions"
)]
fn an_allocation_inside_the_checker_aborts_the_test_binary() {
    if std::env::var_os(CHILD_ENV).is_some() {
        // The child: this allocation must abort before the line after it.
        assert_no_alloc(|| drop(std::hint::black_box(vec![0u8; 16])));
        println!("allocated inside the checker and went on");
        return;
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "an_allocation_inside_the_checker_aborts_the_test_binary",
            "--nocapture",
            "--test-threads",
            "1",
        ])
        .env(CHILD_ENV, "1")
        .output()
        .expect("running this test binary again");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        !out.status.success() && !stdout.contains("went on"),
        "an allocation inside assert_no_alloc did not abort: {:?}\n{stdout}",
        out.status
    );
}
