//! The plugin's input event capacity, in a process of its own: nice-plug's wrappers
//! accept an event that overflows the buffer reserved at load (the push runs under
//! `permit_alloc`, so `assert_process_allocs` does not see it) and only log "Input event
//! buffer filled up! This will cause an allocation.". This test sends the log to a file
//! (`NICE_LOG`, read once per process when the plugin is first loaded) and reads it.

#[allow(dead_code)]
mod host;

use colophony::analysis::rms;
use host::{channel_f64, Event, HostedPlugin, Score};

#[test]
fn a_block_with_a_full_controller_flush_fits_the_reserved_event_buffer() {
    let log = std::env::temp_dir().join(format!("colophony-events-{}.log", std::process::id()));
    let _ = std::fs::remove_file(&log);
    // Before the plugin's first load in this process (its logger reads it then).
    std::env::set_var("NICE_LOG", &log);
    const BLOCK: usize = 512;
    let mut plugin = HostedPlugin::active_test_build(48_000.0, BLOCK);
    // A VST3 host that flushes nice-plug's 16 x 130 hidden MIDI-controller parameters
    // hands the plugin 2080 events in one block; CLAP delivers controllers as events
    // through the same capacity (`Plugin::INPUT_EVENT_CAPACITY`). Here 2080 controller
    // changes land in one block, twice, with a note sounding.
    let mut score = Score::new().at(0, Event::note_on(50));
    for block in [1u64, 3] {
        for i in 0..16 * 130u64 {
            // Controllers the performer ignores, and expression and the mod wheel.
            let cc = [20u8, 1, 11, 74][(i % 4) as usize];
            let value = (i % 128) as u8;
            score.push(
                block * BLOCK as u64 + i % BLOCK as u64,
                Event::Controller { cc, value },
            );
        }
    }
    let out = plugin.render(6 * BLOCK, BLOCK, &score);
    assert!(out.iter().flatten().all(|x| x.is_finite()));
    assert!(
        rms(&channel_f64(&out, 0)) > 0.0,
        "the note sounded through the flush"
    );
    drop(plugin);
    let logged = std::fs::read_to_string(&log).unwrap_or_default();
    let _ = std::fs::remove_file(&log);
    assert!(
        !logged.contains("filled up"),
        "the wrapper overflowed its event buffer:\n{logged}"
    );
}
