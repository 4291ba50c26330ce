//! Measurement, framework-free (no egui, no plugin framework): the contact sample the probe
//! records, the regime classifier that names the string's motion from it, and Schelleng's
//! window of bow forces. The editor shows them; the performer's tests and the tools'
//! playing-space map measure with them.

pub mod contact;
pub mod corner;
pub mod regime;
pub mod window;
