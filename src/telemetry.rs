//! One telemetry ring for every live view: the audio thread writes plain records, the
//! editor reads the newest ones; neither waits, locks or allocates (the audio thread never may).
//!
//! [`Ring`] is a single-writer ring of seqlocked slots of atomics. A [`Record`] is a
//! plain `Copy` value stored as a fixed number of 32-bit words. To publish record `n` the
//! writer marks its slot `2 n + 1` (being written), stores the words, then marks it
//! `2 n + 2`; a reader keeps a record only if the slot held that record's even mark before
//! and after it copied the words, so it never sees a torn record, and a record the writer
//! overwrote during the copy is left out. The editor's contact scope
//! ([`crate::editor::live`]) and the thermal bow's node records
//! ([`crate::editor::nodes`]) are both rings of this kind. Framework-free: no plugin or
//! GUI type appears here.
//!
//! ```
//! use colophony::telemetry::{Record, Ring};
//! use std::sync::atomic::{AtomicU32, Ordering};
//! #[derive(Clone, Copy, Default, Debug, PartialEq)]
//! struct Level(f32);
//! impl Record for Level {
//!     const WORDS: usize = 1;
//!     fn store(&self, words: &[AtomicU32]) {
//!         words[0].store(self.0.to_bits(), Ordering::Relaxed);
//!     }
//!     fn load(words: &[AtomicU32]) -> Self {
//!         Level(f32::from_bits(words[0].load(Ordering::Relaxed)))
//!     }
//! }
//! let ring = Ring::<Level>::new(8);
//! for i in 0..10 {
//!     ring.push(&Level(i as f32));
//! }
//! let mut out = Vec::new();
//! ring.copy_latest(3, &mut out);
//! assert_eq!(out, [Level(7.0), Level(8.0), Level(9.0)]);
//! ```

use std::marker::PhantomData;
use std::sync::atomic::{fence, AtomicU32, AtomicU64, Ordering};

/// A plain value the ring carries as [`Record::WORDS`] 32-bit words.
pub trait Record: Copy + Default {
    /// Words per record.
    const WORDS: usize;
    /// Stores the record into `words` (exactly [`Self::WORDS`] of them), Relaxed.
    fn store(&self, words: &[AtomicU32]);
    /// Reads a record back from `words`, Relaxed.
    fn load(words: &[AtomicU32]) -> Self;
}

/// Wait-free single-producer ring of records (see the module doc).
pub struct Ring<R: Record> {
    /// Per slot: `2 n + 1` while record `n` is written into it, `2 n + 2` once it is whole.
    seq: Box<[AtomicU64]>,
    words: Box<[AtomicU32]>,
    mask: u64,
    /// Records published since creation.
    written: AtomicU64,
    record: PhantomData<R>,
}

impl<R: Record> std::fmt::Debug for Ring<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ring")
            .field("len", &self.seq.len())
            .field("written", &self.written())
            .finish_non_exhaustive()
    }
}

impl<R: Record> Ring<R> {
    /// A ring of `len` records (rounded up to a power of two). Allocates: call from a
    /// non-real-time context.
    pub fn new(len: usize) -> Self {
        let len = len.max(1).next_power_of_two();
        Self {
            seq: (0..len).map(|_| AtomicU64::new(0)).collect(),
            words: (0..len * R::WORDS).map(|_| AtomicU32::new(0)).collect(),
            mask: len as u64 - 1,
            written: AtomicU64::new(0),
            record: PhantomData,
        }
    }

    /// Records the ring holds.
    pub fn len(&self) -> usize {
        self.seq.len()
    }

    pub fn is_empty(&self) -> bool {
        self.seq.is_empty()
    }

    fn slot(&self, n: u64) -> (&AtomicU64, &[AtomicU32]) {
        let i = (n & self.mask) as usize;
        (&self.seq[i], &self.words[i * R::WORDS..(i + 1) * R::WORDS])
    }

    /// Audio thread (one writer only): publishes one record.
    #[inline]
    pub fn push(&self, record: &R) {
        let n = self.written.load(Ordering::Relaxed);
        let (seq, words) = self.slot(n);
        seq.store(2 * n + 1, Ordering::Relaxed);
        // Orders the odd mark before the words: a reader that sees any new word sees it.
        fence(Ordering::Release);
        record.store(words);
        seq.store(2 * n + 2, Ordering::Release);
        self.written.store(n + 1, Ordering::Release);
    }

    /// Records published so far.
    pub fn written(&self) -> u64 {
        self.written.load(Ordering::Acquire)
    }

    /// Editor: replaces `out` with up to the `max` newest whole records, oldest first and
    /// consecutive: if the writer overwrote some while they were copied, only the run
    /// after the last overwritten one is kept.
    pub fn copy_latest(&self, max: usize, out: &mut Vec<R>) {
        out.clear();
        let end = self.written();
        let start = end - (max.min(self.len()) as u64).min(end);
        for n in start..end {
            match self.read(n) {
                Some(record) => out.push(record),
                // The writer lapped the reader: this slot, and every older one, now holds
                // a newer record. Keep only what follows, so the records stay consecutive.
                None => out.clear(),
            }
        }
    }

    /// Record `n`, if its slot holds it whole.
    fn read(&self, n: u64) -> Option<R> {
        let (seq, words) = self.slot(n);
        let mark = seq.load(Ordering::Acquire);
        if mark != 2 * n + 2 {
            return None;
        }
        let record = R::load(words);
        // Orders the loads before the second look at the mark.
        fence(Ordering::Acquire);
        (seq.load(Ordering::Relaxed) == mark).then_some(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// Two words that must always agree: a torn read would show them differing.
    #[derive(Clone, Copy, Default, Debug, PartialEq)]
    struct Pair(u32, u32);

    impl Record for Pair {
        const WORDS: usize = 2;
        fn store(&self, words: &[AtomicU32]) {
            words[0].store(self.0, Ordering::Relaxed);
            words[1].store(self.1, Ordering::Relaxed);
        }
        fn load(words: &[AtomicU32]) -> Self {
            Pair(
                words[0].load(Ordering::Relaxed),
                words[1].load(Ordering::Relaxed),
            )
        }
    }

    #[test]
    fn the_newest_records_come_back_in_order_across_the_wrap() {
        let ring = Ring::<Pair>::new(5);
        assert_eq!(ring.len(), 8, "rounded up to a power of two");
        let mut out = Vec::new();
        ring.copy_latest(4, &mut out);
        assert!(out.is_empty());
        for i in 0..20 {
            ring.push(&Pair(i, i));
        }
        ring.copy_latest(100, &mut out);
        assert_eq!(out, (12..20).map(|i| Pair(i, i)).collect::<Vec<_>>());
    }

    #[test]
    fn a_reader_never_sees_a_torn_record_under_a_concurrent_writer() {
        let ring = Arc::new(Ring::<Pair>::new(16));
        let writer = {
            let ring = ring.clone();
            std::thread::spawn(move || {
                for i in 0..2_000_000u32 {
                    ring.push(&Pair(i, i.wrapping_mul(3)));
                }
            })
        };
        let mut out = Vec::with_capacity(16);
        let mut seen = 0;
        while !writer.is_finished() {
            ring.copy_latest(16, &mut out);
            for w in out.windows(2) {
                assert!(w[0].0 < w[1].0, "out of order: {w:?}");
            }
            for p in &out {
                assert_eq!(p.1, p.0.wrapping_mul(3), "torn: {p:?}");
            }
            seen += out.len();
        }
        writer.join().unwrap();
        // And once more at rest: the newest records, whole.
        ring.copy_latest(16, &mut out);
        assert_eq!(out.len(), 16);
        assert_eq!(out.last().unwrap().0, 1_999_999);
        seen += out.len();
        assert!(seen >= 16);
    }
}
