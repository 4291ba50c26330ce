//! The tail the host hears about: keep alive while a bow is on, the ring-out time once
//! lifted, silence after.

use super::*;

/// Samples between two tail estimates (see [`Performer::status`]).
const TAIL_EVERY: usize = 2048;

impl Performer {
    /// What the host hears about a block of `block` samples (CLAP process status and tail
    /// extension, VST3 `getTailSamples`):
    /// - `KeepAlive` while a bow or an exciter is on;
    /// - `Tail(samples)` while lifted strings or rubbed objects ring out (the waveguide
    ///   body's last blocks after its strings slept count as one sample, renewed while it
    ///   rings);
    /// - `Normal` once silent, so a CLAP host may stop calling `process` until input.
    pub fn status(&mut self, block: usize) -> Status {
        if let Some((left, since)) = self.tail {
            if since + block < TAIL_EVERY {
                let left = (left - block as f64).max(1.0);
                self.tail = Some((left, since + block));
                return Status::Tail(left as u32);
            }
        }
        self.tail = None;
        let mut tail_s = 0.0f64;
        let mut sounding = false;
        for engine in self.engines() {
            if !engine.is_ringing() {
                continue;
            }
            sounding = true;
            match engine.ring_out_s() {
                Some(s) => tail_s = tail_s.max(s),
                None => return Status::KeepAlive,
            }
        }
        if !sounding {
            return Status::Normal;
        }
        // At least one sample while anything rings; below CLAP's "infinite" (i32::MAX).
        let samples = (tail_s * self.sample_rate_hz)
            .ceil()
            .clamp(1.0, (i32::MAX - 1) as f64);
        self.tail = Some((samples, 0));
        Status::Tail(samples as u32)
    }
}
