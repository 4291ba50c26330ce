//! A timing floor: the fastest of equal stretches of work, per sample. Other load on a
//! shared machine (another process, a virtual machine's stolen time) can only slow some
//! stretches down, so the fastest stretch measures the code, not the machine's load. The
//! processes `colophony bench peers` times print it on standard error as
//! `floor_ns_per_sample X` ([`FLOOR_TAG`]); `assets/peers/stk_bowed.cpp` prints STK's the
//! same way.

use std::time::Instant;

/// Samples a stretch holds (a third of a second at 48 kHz: long against the timer's
/// resolution, short enough that most stretches of a run see no other load).
pub const FLOOR_STRETCH: usize = 16_384;
/// What a timed process prints before its floor.
pub const FLOOR_TAG: &str = "floor_ns_per_sample";

/// The fastest stretch so far (see the module doc).
#[derive(Debug, Clone)]
pub struct Floor {
    started: Instant,
    samples: usize,
    best_s_per_sample: f64,
}

impl Default for Floor {
    fn default() -> Self {
        Self::new()
    }
}

impl Floor {
    /// Starts the first stretch now.
    pub fn new() -> Self {
        Self {
            started: Instant::now(),
            samples: 0,
            best_s_per_sample: f64::INFINITY,
        }
    }

    /// `samples` more samples are done; a stretch of at least [`FLOOR_STRETCH`] ends here.
    pub fn advance(&mut self, samples: usize) {
        self.samples += samples;
        if self.samples >= FLOOR_STRETCH {
            let now = Instant::now();
            let per_sample = (now - self.started).as_secs_f64() / self.samples as f64;
            self.best_s_per_sample = self.best_s_per_sample.min(per_sample);
            self.started = now;
            self.samples = 0;
        }
    }

    /// The fastest whole stretch's time a sample, ns (`None` before one has ended).
    pub fn ns_per_sample(&self) -> Option<f64> {
        self.best_s_per_sample
            .is_finite()
            .then_some(self.best_s_per_sample * 1e9)
    }

    /// The line a timed process prints (see the module doc); empty before a stretch ended.
    pub fn line(&self) -> String {
        self.ns_per_sample()
            .map_or(String::new(), |ns| format!("{FLOOR_TAG} {ns:.3}"))
    }
}

/// The floor a timed process printed (the last [`FLOOR_TAG`] line of `text`), ns a sample.
pub fn parse_floor(text: &str) -> Option<f64> {
    text.lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix(FLOOR_TAG)?.trim().parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_floor_is_the_fastest_whole_stretch_and_reads_back_from_its_line() {
        let mut floor = Floor::new();
        assert_eq!(floor.ns_per_sample(), None, "no stretch has ended");
        // Two stretches: one slowed by a sleep, one not. The floor is at most the quick
        // one's time (the sleep's stretch cannot be the fastest).
        std::thread::sleep(std::time::Duration::from_millis(20));
        floor.advance(FLOOR_STRETCH);
        let slow = floor.ns_per_sample().expect("a stretch ended");
        floor.advance(FLOOR_STRETCH);
        let quick = floor.ns_per_sample().expect("two stretches ended");
        // 20 ms over 16384 samples is 1220 ns a sample at least.
        assert!(slow >= 1220.0, "{slow}");
        assert!(quick < slow, "{quick} against {slow}");
        assert_eq!(
            parse_floor(&format!("noise\n{}\n", floor.line())).map(|x| (x * 1e3).round()),
            Some((quick * 1e3).round())
        );
        assert_eq!(parse_floor("no floor here"), None);
    }
}
