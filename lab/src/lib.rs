//! Colophony's tools, beside the plugin crate (`colophony`), which links none of them.
//! Everything here plays through the plugin's own engines and performer:
//!
//! - [`render`]: one bowed note on an engine, to a WAV file (`colophony render`);
//! - [`midi_file`]: a standard MIDI file through the plugin's performer
//!   (`colophony render --midi`);
//! - [`figures`], [`playing_space::figure`]: the papers' figures and the maps, as PNG;
//! - [`bench`](mod@bench), [`precision`], [`playing_space`], [`measured_window`],
//!   [`intonation_fit`]: real-time ratios, the work-precision benchmark, the playing-space
//!   map, the window each model plays and the intonation table;
//! - [`admittance_fit`]: fitting a passive modal bridge to measured admittance;
//! - [`timbre`]: the played notes' long-term spectrum against a real instrument's;
//! - [`timing`]: a timing floor that other load on the machine cannot raise.

pub mod admittance_fit;
pub mod bench;
pub mod figures;
pub mod intonation_fit;
pub mod measured_window;
pub mod midi_file;
pub mod playing_space;
pub mod precision;
pub mod render;
pub mod thermal_constants;
pub mod timbre;
pub mod timing;
