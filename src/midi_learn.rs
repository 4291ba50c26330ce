//! The MIDI map shared between the editor, the plugin state and the audio thread, and
//! what MIDI learn needs from the audio thread (the editor's MIDI map page).
//!
//! [`SharedMidiMap`] holds the performer's [`MidiMap`] in atomics behind a sequence
//! number: the editor (and a state load) writes it, the audio thread reads it once per
//! block only when the sequence number moved, and a read that overlaps a write is simply
//! tried again at the next block. Neither side waits for the other or allocates. It is
//! saved with the project (`midi-map`); a state without it plays the default map.
//!
//! [`LastController`] is the other direction: the audio thread stores each controller it
//! receives (number and a running count) in one atomic; the editor's **Learn** button
//! waits for the count to move and takes that controller.
//!
//! ```
//! use colophony::midi_learn::SharedMidiMap;
//! use colophony::performer::midi_map::{Mapping, MidiMap, Target};
//! let shared = SharedMidiMap::default();
//! let mut seen = 0;
//! assert_eq!(shared.read_if_changed(&mut seen), Some(MidiMap::default())); // first read
//! assert_eq!(shared.read_if_changed(&mut seen), None); // nothing new
//! let mut map = MidiMap::empty();
//! map.add(Mapping::new(74, Target::BowPosition));
//! shared.store(&map);
//! assert_eq!(shared.read_if_changed(&mut seen), Some(map));
//! ```

use crate::performer::midi_map::{Mapping, MidiMap, Target, MAX_MAPPINGS};
use atomic_float::AtomicF32;
use nice_plug::params::persist::PersistentField;
use std::sync::atomic::{fence, AtomicU32, Ordering};

/// One slot: `used << 16 | target << 8 | cc` and the three floats.
#[derive(Debug, Default)]
struct Slot {
    head: AtomicU32,
    min: AtomicF32,
    max: AtomicF32,
    curve: AtomicF32,
}

const USED: u32 = 1 << 16;

/// The MIDI map in atomics (see the module doc).
#[derive(Debug)]
pub struct SharedMidiMap {
    slots: [Slot; MAX_MAPPINGS],
    /// Even when stable, odd while a write is under way; starts at 2 so a reader that has
    /// seen nothing (0) takes the first map.
    sequence: AtomicU32,
}

impl Default for SharedMidiMap {
    fn default() -> Self {
        let shared = Self {
            slots: Default::default(),
            sequence: AtomicU32::new(0),
        };
        shared.store(&MidiMap::default());
        shared
    }
}

impl SharedMidiMap {
    /// Replaces the map (editor or state load; not the audio thread).
    pub fn store(&self, map: &MidiMap) {
        // Odd: a write is under way.
        let start = self.sequence.fetch_add(1, Ordering::AcqRel);
        let start = if start % 2 == 1 {
            // Another writer was interrupted (cannot happen: one editor); make it even.
            self.sequence.fetch_add(1, Ordering::AcqRel);
            start + 1
        } else {
            start
        };
        fence(Ordering::Release);
        for (i, slot) in self.slots.iter().enumerate() {
            match map.get(i) {
                Some(m) => {
                    let head = USED | (m.target.index() as u32) << 8 | m.cc as u32;
                    slot.min.store(m.min, Ordering::Relaxed);
                    slot.max.store(m.max, Ordering::Relaxed);
                    slot.curve.store(m.curve, Ordering::Relaxed);
                    slot.head.store(head, Ordering::Relaxed);
                }
                None => slot.head.store(0, Ordering::Relaxed),
            }
        }
        self.sequence.store(start + 2, Ordering::Release);
    }

    /// The map if it changed since `seen` (which it then updates) and no write overlapped
    /// the read; else `None`. Wait-free: for the audio thread, once per block.
    pub fn read_if_changed(&self, seen: &mut u32) -> Option<MidiMap> {
        let before = self.sequence.load(Ordering::Acquire);
        if before == *seen || before % 2 == 1 {
            return None;
        }
        let map = self.read_slots();
        fence(Ordering::Acquire);
        if self.sequence.load(Ordering::Relaxed) != before {
            return None;
        }
        *seen = before;
        Some(map)
    }

    /// The map now (retries while a write is under way: not for the audio thread).
    pub fn snapshot(&self) -> MidiMap {
        loop {
            let mut seen = u32::MAX;
            if let Some(map) = self.read_if_changed(&mut seen) {
                return map;
            }
            std::thread::yield_now();
        }
    }

    fn read_slots(&self) -> MidiMap {
        let mut map = MidiMap::empty();
        for (i, slot) in self.slots.iter().enumerate() {
            let head = slot.head.load(Ordering::Relaxed);
            if head & USED == 0 {
                continue;
            }
            let target = Target::ALL[((head >> 8) & 0xff) as usize % Target::ALL.len()];
            map.set(
                i,
                Some(Mapping {
                    cc: (head & 0x7f) as u8,
                    target,
                    min: slot.min.load(Ordering::Relaxed),
                    max: slot.max.load(Ordering::Relaxed),
                    curve: slot.curve.load(Ordering::Relaxed),
                }),
            );
        }
        map
    }
}

impl<'a> PersistentField<'a, MidiMap> for SharedMidiMap {
    fn set(&self, new_value: MidiMap) {
        self.store(&new_value);
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&MidiMap) -> R,
    {
        f(&self.snapshot())
    }
}

/// The last controller the audio thread received, for MIDI learn (see the module doc).
#[derive(Debug, Default)]
pub struct LastController(AtomicU32);

impl LastController {
    /// Audio thread: controller `cc` arrived.
    #[inline]
    pub fn record(&self, cc: u8) {
        let count = (self.0.load(Ordering::Relaxed) >> 8).wrapping_add(1);
        self.0.store(count << 8 | cc as u32, Ordering::Relaxed);
    }

    /// The running count and the controller (the count moves with every controller).
    pub fn get(&self) -> (u32, u8) {
        let v = self.0.load(Ordering::Relaxed);
        (v >> 8, (v & 0x7f) as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_read_overlapping_a_write_is_refused_and_the_next_one_sees_the_whole_map() {
        let shared = SharedMidiMap::default();
        let mut seen = 0;
        let first = shared.read_if_changed(&mut seen).unwrap();
        assert_eq!(first, MidiMap::default());
        // A write under way (odd sequence): the reader keeps what it had.
        shared.sequence.fetch_add(1, Ordering::AcqRel);
        assert_eq!(shared.read_if_changed(&mut seen), None);
        shared.sequence.fetch_add(1, Ordering::AcqRel);
        // Finished (the same content): read again, whole.
        assert_eq!(shared.read_if_changed(&mut seen), Some(MidiMap::default()));
    }

    #[test]
    fn the_map_survives_a_save_and_load_through_the_persistent_field() {
        let shared = SharedMidiMap::default();
        let mut map = MidiMap::empty();
        let mut m = Mapping::new(74, Target::BowPosition);
        m.min = 0.8;
        m.max = 0.1;
        m.curve = -0.5;
        map.add(m);
        map.add(Mapping::new(1, Target::Dynamics));
        PersistentField::set(&shared, map);
        let json = PersistentField::map(&shared, |m| serde_json::to_string(m).unwrap());
        let other = SharedMidiMap::default();
        PersistentField::set(&other, serde_json::from_str::<MidiMap>(&json).unwrap());
        assert_eq!(other.snapshot(), map);
    }

    #[test]
    fn the_learn_counter_moves_with_every_controller() {
        let last = LastController::default();
        assert_eq!(last.get(), (0, 0));
        last.record(74);
        last.record(74);
        assert_eq!(last.get(), (2, 74));
        last.record(1);
        assert_eq!(last.get(), (3, 1));
    }
}
