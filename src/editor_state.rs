//! The editor window's size, saved with the plugin state (`#[persist = "editor-state"]` in
//! [`crate::params::ColophonyParams`]). Here rather than in [`crate::editor`] so the
//! parameters do not depend on the editor; the editor re-exports both types.

use nice_plug::params::persist::PersistentField;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};

/// The editor window's size in logical points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EditorSize {
    pub width: f32,
    pub height: f32,
}

impl EditorSize {
    pub const DEFAULT: Self = Self {
        width: 880.0,
        height: 760.0,
    };
    pub const MIN: Self = Self {
        width: 640.0,
        height: 430.0,
    };
    pub const MAX: Self = Self {
        width: 4096.0,
        height: 4096.0,
    };

    /// Clamped to [`Self::MIN`] .. [`Self::MAX`]; the default if not finite (a damaged state).
    pub fn sanitized(self) -> Self {
        if !(self.width.is_finite() && self.height.is_finite()) {
            return Self::DEFAULT;
        }
        Self {
            width: self.width.clamp(Self::MIN.width, Self::MAX.width),
            height: self.height.clamp(Self::MIN.height, Self::MAX.height),
        }
    }
}

/// The persisted editor state: the window size, both halves in one atomic so a save never
/// sees half a resize.
#[derive(Debug)]
pub struct EditorState {
    bits: AtomicU64,
}

impl EditorState {
    fn pack(size: EditorSize) -> u64 {
        (size.width.to_bits() as u64) << 32 | size.height.to_bits() as u64
    }

    pub fn size(&self) -> EditorSize {
        let bits = self.bits.load(Ordering::Acquire);
        EditorSize {
            width: f32::from_bits((bits >> 32) as u32),
            height: f32::from_bits(bits as u32),
        }
    }

    pub fn set_size(&self, size: EditorSize) {
        self.bits
            .store(Self::pack(size.sanitized()), Ordering::Release);
    }
}

impl Default for EditorState {
    fn default() -> Self {
        Self {
            bits: AtomicU64::new(Self::pack(EditorSize::DEFAULT)),
        }
    }
}

impl<'a> PersistentField<'a, EditorSize> for EditorState {
    fn set(&self, new_value: EditorSize) {
        self.set_size(new_value);
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&EditorSize) -> R,
    {
        f(&self.size())
    }
}
