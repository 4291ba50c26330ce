//! Rendering: one sample, a block, or a run with no event between, through the source's
//! engine and every engine still ringing; sleep and reset.

use super::*;

impl Performer {
    /// Whether every engine is asleep: [`Performer::tick`] would give silence (a zero
    /// frame) and change nothing but the gesture's clocks until a note lands.
    pub fn is_asleep(&self) -> bool {
        self.instrument.is_skipping()
            && !self.instrument.is_ringing()
            && self.thermal.iter().all(|e| !e.is_ringing())
            && !self.rubbed.is_sounding()
    }

    /// Stands in for `n` calls of [`Performer::tick`] with `bow` while
    /// [`Performer::is_asleep`]: the output would be `n` zeros, so only the gesture
    /// advances (sample by sample while a vibrato, an attack or the dynamics move, so the
    /// result is the same bits; once, at rest). What makes a silent block cost nothing.
    pub fn skip(&mut self, n: usize, bow: BowControl) {
        debug_assert!(self.is_asleep());
        let g = &self.gesture;
        let at_rest = g.vibrato_cents == 0.0
            && g.vibrato_now == 0.0
            && g.bow_scale == g.target
            && self.stroke.is_settled()
            && self.catch.is_none()
            && self.direct.is_settled();
        let steps = if at_rest { n.min(1) } else { n };
        for _ in 0..steps {
            self.bow_now = self.shape(bow);
        }
    }

    /// Silences every engine and forgets the held notes (the source and the controllers
    /// stay).
    pub fn reset(&mut self) {
        for engine in self.engines() {
            engine.reset();
        }
        self.held = [false; 128];
        self.refresh_others();
    }

    /// One sample. Every engine ticks while it sounds (the one just switched away from
    /// rings on); the contact probe is the source's.
    ///
    /// The commonest case, a steady gesture on the waveguide strings alone, is a few
    /// instructions here and inlined into the caller; everything else is out of line in
    /// `tick_general`, so its registers and stack do not weigh on the common
    /// path (callgrind: 521 instructions per sample this way, 561 with both in one
    /// function).
    #[inline]
    pub fn tick(&mut self, bow: BowControl) -> Frame {
        if !self.others_awake {
            if let Some(played) = self.steady_bow(bow) {
                self.bow_now = played;
                return self.instrument.tick(played);
            }
        }
        self.tick_general(bow)
    }

    /// [`Performer::tick`] with the gesture moving or other engines sounding.
    #[inline(never)]
    pub(super) fn tick_general(&mut self, bow: BowControl) -> Frame {
        let bow = match self.steady_bow(bow) {
            Some(played) => played,
            None => self.shape(bow),
        };
        self.bow_now = bow;
        let mut frame = self.instrument.tick(bow);
        if !self.others_awake {
            self.listen(&frame, &bow);
            return frame;
        }
        for (k, engine) in self.thermal.iter_mut().enumerate() {
            if engine.is_sounding() {
                let f = engine.tick(bow);
                frame.audio += f.audio;
                if self.source == Source::Thermal(k) {
                    frame.bow_point_velocity_m_per_s = f.bow_point_velocity_m_per_s;
                    frame.friction_force_n = f.friction_force_n;
                }
            }
        }
        if self.rubbed.is_sounding() {
            frame.audio += self.rubbed.tick(&bow);
        }
        self.listen(&frame, &bow);
        frame
    }

    /// The attack's catch hears the string just played ([`catch`]).
    #[inline]
    fn listen(&mut self, frame: &Frame, bow: &BowControl) {
        if let Some(catch) = &mut self.catch {
            catch.observe(&crate::measure::contact::ContactSample::new(frame, bow));
        }
    }

    /// The bow as played while the gesture is steady (see [`Performer::shape`]): the
    /// factors on `bow`; `None` while the gesture moves.
    #[inline]
    pub(super) fn steady_bow(&self, bow: BowControl) -> Option<BowControl> {
        Some(match self.steady? {
            (v, f, 1.0) => BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * v,
                force_n: bow.force_n * f,
                ..bow
            },
            (v, f, away) => BowControl {
                velocity_m_per_s: bow.velocity_m_per_s * v,
                force_n: bow.force_n * f,
                position_beta: (bow.position_beta * away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
            },
        })
    }

    /// `out.len()` samples of audio with the bow held at `bow` and no event between: the
    /// same samples as as many [`Performer::tick`]s. Once the gesture is steady and only
    /// the waveguide strings sound, the strings run alone over the rest (the gesture has
    /// nothing to do per sample), which is what makes the performance layer cost nothing
    /// per sample.
    pub fn process(&mut self, bow: BowControl, out: &mut [f64]) {
        let mut i = 0;
        while i < out.len() {
            if !self.others_awake {
                if let Some(played) = self.steady_bow(bow) {
                    self.bow_now = played;
                    for sample in &mut out[i..] {
                        *sample = self.instrument.tick(played).audio;
                    }
                    return;
                }
            }
            out[i] = self.tick(bow).audio;
            i += 1;
        }
    }

    /// `n` samples with no event between, the bow given sample by sample by `next` (a
    /// host's smoothed parameters) with a value `C` of the caller's riding along (its
    /// gain, say); `sink(k, c, frame, played, self)` takes sample `k` with the bow as
    /// played. The same samples as `n` calls of [`Performer::tick`], but once the gesture
    /// is steady and only the waveguide strings sound (which no sample of an event-free run
    /// can change), the rest of the run loops over the strings alone with the checks
    /// hoisted: the performance layer's per-sample work is then the two or three factors
    /// on the bow (the plugin's per-sample path while automation moves or a live view is
    /// open).
    #[inline]
    pub fn process_run<C>(
        &mut self,
        n: usize,
        mut next: impl FnMut() -> (BowControl, C),
        mut sink: impl FnMut(usize, C, &Frame, &BowControl, &Self),
    ) {
        let mut k = 0;
        while k < n {
            if !self.others_awake {
                if let Some((v, f, away)) = self.steady {
                    let mut played = self.bow_now;
                    if away == 1.0 {
                        for k in k..n {
                            let (bow, c) = next();
                            played = BowControl {
                                velocity_m_per_s: bow.velocity_m_per_s * v,
                                force_n: bow.force_n * f,
                                ..bow
                            };
                            let frame = self.instrument.tick(played);
                            sink(k, c, &frame, &played, self);
                        }
                    } else {
                        for k in k..n {
                            let (bow, c) = next();
                            played = BowControl {
                                velocity_m_per_s: bow.velocity_m_per_s * v,
                                force_n: bow.force_n * f,
                                position_beta: (bow.position_beta * away)
                                    .clamp(MIN_NOTE_BETA, MAX_NOTE_BETA),
                            };
                            let frame = self.instrument.tick(played);
                            sink(k, c, &frame, &played, self);
                        }
                    }
                    self.bow_now = played;
                    return;
                }
            }
            let (bow, c) = next();
            let frame = self.tick_general(bow);
            sink(k, c, &frame, &self.bow_now, self);
            k += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::performer::testing::*;

    #[test]
    fn skipping_silent_blocks_gives_the_same_bits_as_ticking_them() {
        // A phrase with gaps long enough for the strings to fall asleep, vibrato and
        // dynamics moving through the silences; one performer ticks every sample, the
        // other skips blocks while asleep, as the plugin does.
        // (A lifted string sleeps once its energy falls 120 dB or so: about 15 s for D3.)
        let events: [(usize, u8, Option<f32>); 4] = [
            (0, 50, Some(1.0)),
            (4_800, 50, None),
            (20 * 48_000, 69, Some(0.3)),
            (20 * 48_000 + 9_600, 69, None),
        ];
        let render = |skipping: bool| {
            let mut p = cello();
            p.set_controller(1, 0.7);
            let bow = BowControl::default();
            let (block, frames) = (512, 40 * 48_000);
            let mut out = Vec::with_capacity(frames);
            let mut skipped = 0;
            let mut next = 0;
            while out.len() < frames {
                let start = out.len();
                if start == 3 * 48_000 {
                    p.set_controller(11, 0.4);
                }
                let lands = next < events.len() && events[next].0 < start + block;
                if skipping && !lands && p.is_asleep() {
                    p.skip(block, bow);
                    out.resize(start + block, 0.0);
                    skipped += 1;
                    continue;
                }
                for i in start..start + block {
                    while next < events.len() && events[next].0 == i {
                        match events[next] {
                            (_, n, Some(v)) => p.note_on(n, v),
                            (_, n, None) => p.note_off(n),
                        }
                        next += 1;
                    }
                    out.push(p.tick(bow).audio);
                }
                p.configure(&Setup::default());
            }
            (out, skipped)
        };
        let (ticked, _) = render(false);
        let (skipped, blocks) = render(true);
        // D3 sleeps about 15 s after its release at 0.1 s and stays asleep to the next note
        // at 20 s: some 450 blocks of 512.
        assert!(blocks > 100, "only {blocks} blocks skipped");
        // -60 dBFS: the bowed notes are far louder.
        assert!(ticked.iter().any(|x| x.abs() > 1e-3));
        let differing = ticked
            .iter()
            .zip(&skipped)
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(differing, 0);
    }

    #[test]
    fn a_block_gives_the_same_samples_as_ticking_it() {
        // Through an attack, a steady stretch, a controller and a second note, with blocks
        // of every size from 1 to 700: the block path is only a shortcut.
        let bow = BowControl::default();
        let events = |p: &mut Performer, at: usize| match at {
            0 => p.note_on(50, 0.8),
            20_000 => p.set_controller(11, 0.6),
            30_000 => p.note_on(57, 0.4),
            40_000 => p.note_off(50),
            _ => {}
        };
        let marks = [0, 20_000, 30_000, 40_000, 48_000];
        let mut ticked = cello();
        let mut want = Vec::new();
        for at in 0..48_000 {
            events(&mut ticked, at);
            want.push(ticked.tick(bow).audio.to_bits());
        }
        for block in [1, 7, 64, 511, 700] {
            let mut p = cello();
            let mut got = Vec::new();
            for (at, n) in spans(&marks, block) {
                events(&mut p, at);
                let mut out = vec![0.0; n];
                p.process(bow, &mut out);
                got.extend(out.iter().map(|x| x.to_bits()));
            }
            assert_eq!(got, want, "blocks of {block}");
        }
    }

    #[test]
    fn a_run_with_the_bow_moving_gives_the_same_frames_as_ticking_it() {
        // As the plugin while automation moves: the bow changes every sample (a slow
        // force and position sweep, so the gesture's position factor is not 1 after the
        // ff controller), through an attack, a controller, a second note, a rubbed source
        // ringing on after a switch, with runs of every size from 1 to 700.
        let bow_at = |at: usize| {
            let t = at as f64 / FS;
            BowControl {
                velocity_m_per_s: 0.1 + 0.02 * (3.0 * t).sin(),
                force_n: 0.8 + 0.3 * (2.0 * t).sin(),
                position_beta: 0.1 + 0.02 * (5.0 * t).sin(),
            }
        };
        let events = |p: &mut Performer, at: usize| match at {
            0 => p.note_on(50, 0.8),
            20_000 => p.set_controller(11, 1.0),
            30_000 => p.note_on(57, 0.4),
            35_000 => p.configure(&Setup {
                rubbed: Some(RubbedPreset::ALL[0]),
                ..Setup::default()
            }),
            40_000 => p.note_off(50),
            _ => {}
        };
        let marks = [0, 20_000, 30_000, 35_000, 40_000, 48_000];
        let mut ticked = cello();
        let mut want = Vec::new();
        for at in 0..48_000 {
            events(&mut ticked, at);
            let f = ticked.tick(bow_at(at));
            let b = ticked.bow();
            want.push(
                [
                    f.audio,
                    f.bow_point_velocity_m_per_s,
                    b.force_n,
                    b.position_beta,
                ]
                .map(f64::to_bits),
            );
        }
        for run in [1, 7, 64, 511, 700] {
            let mut p = cello();
            let mut got = Vec::new();
            for (at, n) in spans(&marks, run) {
                events(&mut p, at);
                let mut k_next = at;
                p.process_run(
                    n,
                    || {
                        k_next += 1;
                        (bow_at(k_next - 1), k_next - 1)
                    },
                    |k, sample, f, b, _| {
                        assert_eq!(sample, at + k, "the caller's value rides with its sample");
                        got.push(
                            [
                                f.audio,
                                f.bow_point_velocity_m_per_s,
                                b.force_n,
                                b.position_beta,
                            ]
                            .map(f64::to_bits),
                        );
                    },
                );
            }
            assert_eq!(got, want, "runs of {run}");
        }
    }
}
