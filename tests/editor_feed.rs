//! What the audio thread does for the editor's live views, checked for allocation: the
//! contact samples into the scope and the thermal bow's nodes into the node ring, as
//! `Colophony::process` does while an open editor listens. The host tests cannot open an
//! editor, so this drives the same calls with a counting allocator.

use colophony::dsp::bridge_data::shipped_cello_bridge;
use colophony::dsp::instrument::{BowControl, InstrumentKind};
use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
use colophony::editor::live::ContactSample;
use colophony::editor::nodes::NodeProbe;
use colophony::editor::EditorLink;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the allocations of threads that ask it to.
struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // `try_with`: a thread being torn down has no locals left, and counts nothing.
        if COUNTING.try_with(Cell::get).unwrap_or(false) {
            let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        }
        // SAFETY: forwarded unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Allocations `f` makes on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    COUNT.with(Cell::get)
}

#[test]
fn feeding_the_live_and_thermal_views_does_not_allocate() {
    let fs = 48_000.0;
    let bridge = shipped_cello_bridge().modes;
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
    // Allocations, if any, happen on the first uses: count from the first sample.
    let count = allocations(|| {
        for i in 0..(fs as usize / 2) {
            if i % 256 == 0 {
                cello.update_sleep();
            }
            let frame = cello.tick(bow);
            link.scope.push(ContactSample::new(&frame, &bow));
            probe.add_from(
                cello.probed_string().node_temperatures(),
                cello.probed_string().slipping(),
                &link,
            );
        }
    });
    assert_eq!(count, 0);
    // The views were fed: 0.5 s of samples, one node record every 5 ms.
    assert_eq!(link.scope.written(), 24_000);
    assert_eq!(link.nodes.written(), 100);
    // The counter itself works.
    assert_eq!(allocations(|| drop(std::hint::black_box(vec![0u8; 16]))), 1);
}
