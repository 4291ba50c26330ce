//! The plugin editor (nice-plug-egui): an XY pad for bow velocity and force with the
//! Schelleng window behind it, the bow position and the model selectors.

pub mod mapping;
