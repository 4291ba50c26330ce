//! The MIDI map: which controller moves which gesture of the performer, over what range
//! and with what curve. One controller may drive several targets, and a target may have
//! several controllers (the last to move wins).
//!
//! The default map:
//!
//! | CC | target |
//! |---|---|
//! | 1 (mod wheel) | vibrato depth |
//! | 2 (breath), 11 (expression) | dynamics |
//! | 19 | vibrato rate |
//! | 21, 22, 23 | bow speed, force, position ([`super::direct`]) |
//! | 65 (portamento pedal) | portamento (on at 64 and up) |
//! | 64 (sustain pedal) | sustain: released notes keep their fingers down (at 64 and up) |
//! | 102 | pizzicato (at 64 and up; arco below) |
//! | 103 | tremolo (at 64 and up; arco below) |
//! | 104 | spiccato (at 64 and up; arco below) |
//! | 105 | con sordino: a mute on the bridge (at 64 and up; none below) |
//!
//! Each mapping turns the controller's value `x` (0..=1) into `min + (max - min) x^e` with
//! `e = 3^-curve` (`curve` in -1..=1: 0 is linear, 1 rises fast from the bottom, -1 slowly);
//! `min > max` inverts the controller. The data bytes of registered parameters (CC 6, 38,
//! 100, 101: the pitch-bend range) and MPE's member channels are MIDI's own and not
//! mapped. The editor's mapping page edits the map and learns a controller
//! ([`crate::editor`]); the plugin keeps it in its state.
//!
//! ```
//! use colophony::performer::midi_map::{MidiMap, Target};
//! let map = MidiMap::default();
//! let routed: Vec<(Target, f64)> = map.route(11, 0.5).collect();
//! assert_eq!(routed, [(Target::Dynamics, 0.5)]);
//! ```

use serde::{Deserialize, Serialize};

/// The controller that switches pizzicato in the default map (an undefined one in the
/// MIDI specification).
pub const PIZZICATO_CC: u8 = 102;
/// The controller that switches tremolo in the default map (undefined in MIDI too).
pub const TREMOLO_CC: u8 = 103;
/// The controller that switches spiccato in the default map (undefined in MIDI too).
pub const SPICCATO_CC: u8 = 104;
/// The controller that puts the mute on in the default map (undefined in MIDI too).
pub const CON_SORDINO_CC: u8 = 105;
/// The controller that switches col legno in the default map (undefined in MIDI too).
pub const COL_LEGNO_CC: u8 = 106;
/// The controller that switches sautillé in the default map (undefined in MIDI too).
pub const SAUTILLE_CC: u8 = 107;
/// The controller that switches harmonics in the default map (undefined in MIDI too).
pub const HARMONICS_CC: u8 = 108;
/// The controller that switches col legno tratto in the default map (undefined in MIDI
/// too).
pub const COL_LEGNO_TRATTO_CC: u8 = 109;

/// Most mappings a map holds.
pub const MAX_MAPPINGS: usize = 24;

/// What a controller moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// The dynamics (bow speed and force together, in the window): as CC11.
    Dynamics,
    /// The finger vibrato's depth, 0..=1 of its largest.
    VibratoDepth,
    /// The vibrato's rate over its range.
    VibratoRate,
    /// The bow speed ([`super::direct`]).
    BowVelocity,
    /// The bow force ([`super::direct`]).
    BowForce,
    /// The bow position ([`super::direct`]).
    BowPosition,
    /// Portamento: a legato note glides while the value is 0.5 or more.
    Portamento,
    /// The sustain pedal: while the value is 0.5 or more, released notes keep their
    /// fingers down and ring on at their stopped pitch; below it, the fingers lift.
    Sustain,
    /// Pizzicato while the value is 0.5 or more, arco below it
    /// ([`super::articulation`]).
    Pizzicato,
    /// Tremolo while the value is 0.5 or more, arco below it.
    Tremolo,
    /// Spiccato while the value is 0.5 or more, arco below it.
    Spiccato,
    /// A mute on the bridge while the value is 0.5 or more (con sordino), none below.
    ConSordino,
    /// Col legno (battuto) while the value is 0.5 or more, arco below it.
    ColLegno,
    /// Sautillé while the value is 0.5 or more, arco below it.
    Sautille,
    /// Harmonics while the value is 0.5 or more, arco below it.
    Harmonics,
    /// Col legno tratto while the value is 0.5 or more, arco below it.
    ColLegnoTratto,
}

impl Target {
    /// In the order saved maps index them: new targets go at the end.
    pub const ALL: [Target; 16] = [
        Target::Dynamics,
        Target::VibratoDepth,
        Target::VibratoRate,
        Target::BowVelocity,
        Target::BowForce,
        Target::BowPosition,
        Target::Portamento,
        Target::Sustain,
        Target::Pizzicato,
        Target::Tremolo,
        Target::Spiccato,
        Target::ConSordino,
        Target::ColLegno,
        Target::Sautille,
        Target::Harmonics,
        Target::ColLegnoTratto,
    ];

    /// The name the editor shows.
    pub fn label(self) -> &'static str {
        match self {
            Target::Dynamics => "Dynamics",
            Target::VibratoDepth => "Vibrato depth",
            Target::VibratoRate => "Vibrato rate",
            Target::BowVelocity => "Bow speed",
            Target::BowForce => "Bow force",
            Target::BowPosition => "Bow position",
            Target::Portamento => "Portamento",
            Target::Sustain => "Sustain (fingers down)",
            Target::Pizzicato => "Pizzicato",
            Target::Tremolo => "Tremolo",
            Target::Spiccato => "Spiccato",
            Target::ConSordino => "Con sordino (mute)",
            Target::ColLegno => "Col legno",
            Target::Sautille => "Sautillé",
            Target::Harmonics => "Harmonics",
            Target::ColLegnoTratto => "Col legno tratto",
        }
    }

    /// Index in [`Target::ALL`].
    pub fn index(self) -> usize {
        Target::ALL.iter().position(|&t| t == self).unwrap_or(0)
    }
}

/// One controller driving one target.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mapping {
    /// Controller number, 0..=127.
    pub cc: u8,
    pub target: Target,
    /// The target's value (0..=1 of its range) at the controller's bottom and top.
    pub min: f32,
    pub max: f32,
    /// -1..=1: 0 linear, above 0 rising fast from the bottom, below 0 slowly.
    pub curve: f32,
}

impl Mapping {
    /// A linear mapping over the target's whole range.
    pub const fn new(cc: u8, target: Target) -> Self {
        Self {
            cc,
            target,
            min: 0.0,
            max: 1.0,
            curve: 0.0,
        }
    }

    /// Within the ranges: cc 0..=127, min and max 0..=1, curve -1..=1 (non-finite
    /// values go to the linear full range).
    pub fn sanitized(self) -> Self {
        let unit = |x: f32, default: f32| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                default
            }
        };
        Self {
            cc: self.cc.min(127),
            target: self.target,
            min: unit(self.min, 0.0),
            max: unit(self.max, 1.0),
            curve: if self.curve.is_finite() {
                self.curve.clamp(-1.0, 1.0)
            } else {
                0.0
            },
        }
    }

    /// The target's value for the controller at `x` (0..=1).
    #[inline]
    pub fn shape(&self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        let curved = if self.curve == 0.0 {
            x
        } else {
            x.powf(3f64.powf(-self.curve as f64))
        };
        if self.min == 0.0 && self.max == 1.0 {
            // Exactly the controller's value on the default full range.
            return curved;
        }
        self.min as f64 + (self.max as f64 - self.min as f64) * curved
    }
}

/// Up to [`MAX_MAPPINGS`] mappings (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MidiMap {
    #[serde(with = "mappings_serde")]
    slots: [Option<Mapping>; MAX_MAPPINGS],
}

impl Default for MidiMap {
    /// The default map (the module doc's table).
    fn default() -> Self {
        let mut map = Self::empty();
        for m in [
            Mapping::new(1, Target::VibratoDepth),
            Mapping::new(2, Target::Dynamics),
            Mapping::new(11, Target::Dynamics),
            Mapping::new(19, Target::VibratoRate),
            Mapping::new(21, Target::BowVelocity),
            Mapping::new(22, Target::BowForce),
            Mapping::new(23, Target::BowPosition),
            Mapping::new(65, Target::Portamento),
            Mapping::new(64, Target::Sustain),
            Mapping::new(PIZZICATO_CC, Target::Pizzicato),
            Mapping::new(TREMOLO_CC, Target::Tremolo),
            Mapping::new(SPICCATO_CC, Target::Spiccato),
            Mapping::new(CON_SORDINO_CC, Target::ConSordino),
            Mapping::new(COL_LEGNO_CC, Target::ColLegno),
            Mapping::new(SAUTILLE_CC, Target::Sautille),
            Mapping::new(HARMONICS_CC, Target::Harmonics),
            Mapping::new(COL_LEGNO_TRATTO_CC, Target::ColLegnoTratto),
        ] {
            map.add(m);
        }
        map
    }
}

impl MidiMap {
    /// No mapping at all: every controller but MIDI's own is ignored.
    pub const fn empty() -> Self {
        Self {
            slots: [None; MAX_MAPPINGS],
        }
    }

    /// Adds `mapping` (sanitized) in the first free slot; `false` when the map is full.
    pub fn add(&mut self, mapping: Mapping) -> bool {
        match self.slots.iter_mut().find(|s| s.is_none()) {
            Some(slot) => {
                *slot = Some(mapping.sanitized());
                true
            }
            None => false,
        }
    }

    /// The mapping in slot `i`, if any.
    pub fn get(&self, i: usize) -> Option<Mapping> {
        self.slots.get(i).copied().flatten()
    }

    /// Puts `mapping` (sanitized) in slot `i`, or empties it with `None`.
    pub fn set(&mut self, i: usize, mapping: Option<Mapping>) {
        if let Some(slot) = self.slots.get_mut(i) {
            *slot = mapping.map(Mapping::sanitized);
        }
    }

    /// The mappings, in slot order.
    pub fn mappings(&self) -> impl Iterator<Item = Mapping> + '_ {
        self.slots.iter().flatten().copied()
    }

    /// The targets controller `cc` moves for a value `x` (0..=1), each with its shaped
    /// value, in slot order.
    #[inline]
    pub fn route(&self, cc: u8, x: f64) -> impl Iterator<Item = (Target, f64)> + '_ {
        self.slots
            .iter()
            .flatten()
            .filter(move |m| m.cc == cc)
            .map(move |m| (m.target, m.shape(x)))
    }
}

/// The slots as a plain list of mappings (a saved map reads back into the first slots).
mod mappings_serde {
    use super::{Mapping, MAX_MAPPINGS};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(
        slots: &[Option<Mapping>; MAX_MAPPINGS],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let list: Vec<Mapping> = slots.iter().flatten().copied().collect();
        list.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<[Option<Mapping>; MAX_MAPPINGS], D::Error> {
        let list = Vec::<Mapping>::deserialize(d)?;
        let mut slots = [None; MAX_MAPPINGS];
        for (slot, m) in slots.iter_mut().zip(list) {
            *slot = Some(m.sanitized());
        }
        Ok(slots)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_map_passes_each_controller_through_unchanged() {
        // The defaults move their targets with the controller's own value, bit for bit
        // (each controller drives its target directly, as with no map at all).
        let map = MidiMap::default();
        for x in [0.0, 1.0 / 127.0, 0.5, 100.0 / 127.0, 1.0] {
            for (cc, target) in [
                (1, Target::VibratoDepth),
                (2, Target::Dynamics),
                (11, Target::Dynamics),
                (19, Target::VibratoRate),
                (21, Target::BowVelocity),
                (22, Target::BowForce),
                (23, Target::BowPosition),
                (65, Target::Portamento),
            ] {
                let routed: Vec<_> = map.route(cc, x).collect();
                assert_eq!(routed, [(target, x)], "CC{cc} at {x}");
            }
        }
        assert_eq!(map.route(74, 0.5).count(), 0, "CC74 is not mapped");
    }

    #[test]
    fn a_mapping_shapes_its_range_and_curve() {
        let mut m = Mapping::new(7, Target::BowForce);
        m.min = 0.25;
        m.max = 0.75;
        assert_eq!(m.shape(0.0), 0.25);
        assert_eq!(m.shape(1.0), 0.75);
        // f64 rounding only.
        assert!((m.shape(0.5) - 0.5).abs() < 1e-12);
        // Inverted.
        m.min = 1.0;
        m.max = 0.0;
        assert_eq!(m.shape(0.0), 1.0);
        assert_eq!(m.shape(1.0), 0.0);
        // Curves: +1 is x^(1/3) (fast from the bottom), -1 is x^3; the ends stay.
        let mut c = Mapping::new(7, Target::Dynamics);
        c.curve = 1.0;
        // The cube and cube root in f64: rounding only.
        assert!((c.shape(0.125) - 0.5).abs() < 1e-12);
        c.curve = -1.0;
        assert!((c.shape(0.5) - 0.125).abs() < 1e-12);
        assert_eq!((c.shape(0.0), c.shape(1.0)), (0.0, 1.0));
        // Out of range in, clamped.
        assert_eq!(c.shape(7.0), 1.0);
        assert_eq!(c.shape(f64::NEG_INFINITY), 0.0);
    }

    #[test]
    fn one_controller_drives_several_targets_and_a_full_map_refuses_more() {
        let mut map = MidiMap::empty();
        assert!(map.add(Mapping::new(4, Target::BowForce)));
        let mut pos = Mapping::new(4, Target::BowPosition);
        pos.min = 1.0;
        pos.max = 0.0;
        assert!(map.add(pos));
        let routed: Vec<_> = map.route(4, 0.25).collect();
        assert_eq!(
            routed,
            [(Target::BowForce, 0.25), (Target::BowPosition, 0.75)]
        );
        for _ in 2..MAX_MAPPINGS {
            assert!(map.add(Mapping::new(9, Target::Dynamics)));
        }
        assert!(!map.add(Mapping::new(9, Target::Dynamics)));
        map.set(0, None);
        assert!(map.add(Mapping::new(10, Target::Dynamics)));
        assert_eq!(map.get(0).map(|m| m.cc), Some(10));
    }

    #[test]
    fn a_saved_map_reads_back_and_bad_values_are_brought_into_range() {
        let mut map = MidiMap::default();
        let mut m = Mapping::new(74, Target::BowPosition);
        m.curve = 0.5;
        map.add(m);
        let json = serde_json::to_string(&map).unwrap();
        let back: MidiMap = serde_json::from_str(&json).unwrap();
        assert_eq!(back, map);
        let bad: MidiMap = serde_json::from_str(
            r#"{"slots":[{"cc":200,"target":"bow-force","min":-3,"max":9,"curve":4}]}"#,
        )
        .unwrap();
        assert_eq!(
            bad.get(0),
            Some(Mapping {
                cc: 127,
                target: Target::BowForce,
                min: 0.0,
                max: 1.0,
                curve: 1.0
            })
        );
        assert!(
            serde_json::from_str::<MidiMap>(r#"{"slots":[{"cc":1,"target":"nope"}]}"#).is_err()
        );
    }
}
