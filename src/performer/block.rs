//! A host block: the performance events at their samples, the bow and the output gain
//! sample by sample from the host's (smoothed) parameters, and the output stage (flush
//! subnormals, the safety limiter, the mono voice on every channel). What the plugin's
//! `process` calls once per block, free of the plugin framework.

use super::*;
use crate::dsp::filters::{flush_tiny, safety_limit};

/// A performance event, framework-free: what a host or a MIDI file hands the performer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// A key pressed on a MIDI channel, velocity 0..=1.
    NoteOn {
        channel: u8,
        note: u8,
        velocity: f32,
    },
    NoteOff {
        note: u8,
    },
    /// Every note released (a host's all-notes-off or choke).
    AllNotesOff,
    /// The pitch wheel, 0 (down) ..= 1 (up), 0.5 centred.
    PitchWheel {
        channel: u8,
        value: f32,
    },
    /// A MIDI controller, value 0..=1.
    Controller {
        channel: u8,
        cc: u8,
        value: f32,
    },
    /// Channel pressure, 0..=1.
    ChannelPressure {
        channel: u8,
        pressure: f32,
    },
    /// A note's own tuning (CLAP note expression, MPE), semitones.
    NoteTuning {
        note: u8,
        semitones: f32,
    },
    /// A note's own pressure (polyphonic aftertouch, CLAP, MPE), 0..=1.
    NotePressure {
        note: u8,
        pressure: f32,
    },
    /// A note's own brightness (CLAP, MPE's CC74), 0..=1.
    NoteBrightness {
        note: u8,
        brightness: f32,
    },
}

/// One output sample on every channel: subnormals flushed, the safety limiter applied.
#[inline]
fn write_frame(channels: &mut [&mut [f32]], sample: usize, audio: f64) {
    let out = safety_limit(flush_tiny(audio)) as f32;
    for channel in channels.iter_mut() {
        channel[sample] = out;
    }
}

/// Samples of the block rendered in one call to [`Performer::process`].
const CHUNK: usize = 64;

impl Performer {
    /// Plays one event.
    pub fn handle(&mut self, event: Event) {
        match event {
            Event::NoteOn {
                channel,
                note,
                velocity,
            } => self.note_on_channel(channel, note, velocity),
            Event::NoteOff { note } => self.note_off(note),
            Event::AllNotesOff => self.all_notes_off(),
            Event::PitchWheel { channel, value } => self.set_pitch_wheel_channel(channel, value),
            Event::Controller { channel, cc, value } => {
                self.set_controller_channel(channel, cc, value)
            }
            Event::ChannelPressure { channel, pressure } => {
                self.set_pressure_channel(channel, pressure)
            }
            Event::NoteTuning { note, semitones } => self.set_note_tuning(note, semitones),
            Event::NotePressure { note, pressure } => self.set_note_pressure(note, pressure),
            Event::NoteBrightness { note, brightness } => {
                self.set_note_brightness(note, brightness)
            }
        }
    }

    /// Renders one block into every channel of `out` (all of one length) and returns what
    /// the host should hear about it.
    ///
    /// - `next_event` gives the block's events in order with their sample (`None`: no
    ///   more); each is played at its sample (one at or past the block's end at its end);
    /// - `controls` gives the next sample's bow and linear output gain (the host's
    ///   smoothed parameters); `settled` says whether none of them is smoothing now, so
    ///   one call serves a whole run between events;
    /// - `live`, when the editor's live views listen, takes every sample's frame and the
    ///   bow as played.
    ///
    /// A block with nothing sounding and nothing landing is silence without a per-sample
    /// call (the gesture's clocks still advance). Otherwise the block is cut at its
    /// events into runs: a settled run renders in chunks ([`Performer::process`]), a
    /// moving or listened one sample by sample ([`Performer::process_run`]); the same samples
    /// either way.
    pub fn render_block(
        &mut self,
        out: &mut [&mut [f32]],
        mut next_event: impl FnMut() -> Option<(usize, Event)>,
        mut controls: impl FnMut() -> (BowControl, f64),
        settled: impl Fn() -> bool,
        mut live: Option<&mut dyn FnMut(&Frame, &BowControl, &Performer)>,
    ) -> Status {
        let samples = out.first().map_or(0, |c| c.len());
        let mut pending = next_event();
        if pending.is_none() && settled() && self.is_asleep() {
            out.iter_mut().for_each(|c| c.fill(0.0));
            self.skip(samples, controls().0);
            return self.status(samples);
        }
        let mut sample = 0;
        while sample < samples {
            while let Some((_, event)) = pending.filter(|(at, _)| *at <= sample) {
                self.handle(event);
                pending = next_event();
            }
            // Up to the next event nothing lands: one run.
            let end = pending.map_or(samples, |(at, _)| at.clamp(sample + 1, samples));
            match live.as_deref_mut() {
                None if settled() => self.play_settled(out, sample, end, controls()),
                live => self.play_moving(out, sample, end, &mut controls, live),
            }
            sample = end;
        }
        // Events at or after the block's end (none should be) are still played.
        while let Some((_, event)) = pending {
            self.handle(event);
            pending = next_event();
        }
        self.status(samples)
    }

    /// Samples `from..to` of `out` with the bow and gain settled.
    fn play_settled(
        &mut self,
        out: &mut [&mut [f32]],
        from: usize,
        to: usize,
        (bow, gain): (BowControl, f64),
    ) {
        let mut chunk = [0.0f64; CHUNK];
        let mut at = from;
        while at < to {
            let n = (to - at).min(CHUNK);
            self.process(bow, &mut chunk[..n]);
            for (k, audio) in chunk[..n].iter().enumerate() {
                write_frame(out, at + k, *audio * gain);
            }
            at += n;
        }
    }

    /// Samples `from..to` of `out` with the bow moving sample by sample, each frame handed
    /// to `live` when given.
    fn play_moving<'b>(
        &mut self,
        out: &mut [&mut [f32]],
        from: usize,
        to: usize,
        controls: &mut impl FnMut() -> (BowControl, f64),
        mut live: Option<&mut (dyn FnMut(&Frame, &BowControl, &Performer) + 'b)>,
    ) {
        self.process_run(to - from, controls, |k, gain, frame, played, performer| {
            if let Some(live) = live.as_deref_mut() {
                live(frame, played, performer);
            }
            write_frame(out, from + k, frame.audio * gain);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::performer::testing::*;

    /// The events of a short phrase: a note, a bend, a controller, a legato note, a
    /// release, at samples inside and across block boundaries.
    fn phrase() -> Vec<(usize, Event)> {
        vec![
            (
                0,
                Event::NoteOn {
                    channel: 0,
                    note: 50,
                    velocity: 0.8,
                },
            ),
            (
                700,
                Event::PitchWheel {
                    channel: 0,
                    value: 0.7,
                },
            ),
            (
                1500,
                Event::Controller {
                    channel: 0,
                    cc: 11,
                    value: 0.5,
                },
            ),
            (
                2100,
                Event::NoteOn {
                    channel: 0,
                    note: 52,
                    velocity: 0.8,
                },
            ),
            (2100, Event::NoteOff { note: 50 }),
            (3000, Event::NoteOff { note: 52 }),
        ]
    }

    /// Renders `total` samples of `events` in blocks of `block` through `render_block` on
    /// two channels, the bow from `bow_at(sample)`; returns the channels.
    fn rendered(
        events: &[(usize, Event)],
        total: usize,
        block: usize,
        settled: bool,
        bow_at: impl Fn(usize) -> BowControl,
    ) -> [Vec<f32>; 2] {
        let mut p = cello();
        let mut left = vec![0.0f32; total];
        let mut right = vec![0.0f32; total];
        let mut next = 0;
        let mut start = 0;
        while start < total {
            let n = block.min(total - start);
            let mut out = [&mut left[start..start + n], &mut right[start..start + n]];
            let mut k = start;
            p.render_block(
                &mut out,
                || {
                    let e = events.get(next).filter(|(at, _)| *at < start + n)?;
                    next += 1;
                    Some((e.0 - start, e.1))
                },
                || {
                    k += 1;
                    (bow_at(k - 1), 0.5)
                },
                || settled,
                None,
            );
            start += n;
        }
        [left, right]
    }

    /// The same, tick by tick: events at their samples, the output stage applied by hand.
    fn ticked(
        events: &[(usize, Event)],
        total: usize,
        bow_at: impl Fn(usize) -> BowControl,
    ) -> Vec<f32> {
        let mut p = cello();
        let mut next = 0;
        (0..total)
            .map(|i| {
                while next < events.len() && events[next].0 <= i {
                    p.handle(events[next].1);
                    next += 1;
                }
                safety_limit(flush_tiny(p.tick(bow_at(i)).audio * 0.5)) as f32
            })
            .collect()
    }

    #[test]
    fn a_block_plays_the_same_samples_as_ticking_with_the_output_stage_on_every_channel() {
        let total = 4096;
        let events = phrase();
        let bow = BowControl::default();
        let want = ticked(&events, total, |_| bow);
        for block in [1, 64, 512, 1000] {
            for settled in [true, false] {
                let [left, right] = rendered(&events, total, block, settled, |_| bow);
                assert_eq!(left, want, "block {block}, settled {settled}");
                assert_eq!(right, want, "block {block}, settled {settled}");
            }
        }
    }

    #[test]
    fn a_moving_bow_is_read_once_a_sample_and_a_silent_block_is_zeros() {
        let total = 2048;
        let events = phrase();
        let bow_at = |i: usize| BowControl {
            velocity_m_per_s: 0.05 + 1e-5 * i as f64,
            ..BowControl::default()
        };
        let want = ticked(&events, total, bow_at);
        let [left, _] = rendered(&events, total, 256, false, bow_at);
        assert_eq!(left, want);
        // Nothing held or ringing: the block is silence.
        let mut p = cello();
        let mut out_l = [1.0f32; 128];
        let mut out_r = [1.0f32; 128];
        let status = p.render_block(
            &mut [&mut out_l, &mut out_r],
            || None,
            || (BowControl::default(), 1.0),
            || true,
            None,
        );
        assert!(out_l.iter().chain(&out_r).all(|&x| x == 0.0));
        assert_eq!(status, Status::Normal);
    }
}
