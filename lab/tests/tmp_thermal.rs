use colophony::analysis::{cents, peak_frequency_hz, rms};
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony::measure::contact::ContactSample;
use colophony::measure::regime::classify_regime;
use colophony::performer::{Performer, Setup};
const FS: f64 = 48_000.0;
#[test]
#[ignore]
fn tmp_thermal() {
    for note in [48u8, 60] {
        for cc in [0u8, 10, 21, 32, 42, 64, 85] {
            let kind = InstrumentKind::Cello;
            let setup = Setup {
                instrument: kind,
                point_law: None,
                ..Setup::default()
            };
            let mut p = Performer::new(kind);
            p.activate(&setup, FS).expect("activate");
            p.set_controller(11, cc as f32 / 127.0);
            p.note_on(note, 100.0 / 127.0);
            let n = (1.6 * FS) as usize;
            let from = (0.8 * FS) as usize;
            let mut audio = vec![];
            let mut probe = vec![];
            for i in 0..n {
                if i % 256 == 0 {
                    p.configure(&setup);
                }
                let frame = p.tick(BowControl::default());
                if i >= from {
                    audio.push(frame.audio);
                    probe.push(ContactSample::new(&frame, &p.bow()));
                }
            }
            let f0 = midi_to_hz(note as f64);
            println!(
                "note {note} cc {cc}: bow {:?} level {:.1} cents {:+.1} {:?}",
                p.bow(),
                20.0 * rms(&audio).log10(),
                cents(peak_frequency_hz(&audio, FS, f0, 100.0), f0),
                classify_regime(&probe, FS as f32, f0 as f32)
            );
        }
    }
}
