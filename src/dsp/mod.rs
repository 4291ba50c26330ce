//! The DSP core. It never imports the plugin framework: it takes plain settings in SI
//! units. Parts: friction contacts ([`friction`]), resonators ([`waveguide`]), the body
//! ([`body`]), the instrument that wires them to notes and a bow ([`instrument`]); paper B's
//! finite-width thermal bow ([`thermal`]) and its four-string instrument at the modal bridge
//! ([`thermal_instrument`]).

pub mod body;
pub mod bridge;
pub mod filters;
pub mod friction;
pub mod instrument;
pub mod modal;
pub mod resample;
pub mod rubbed;
pub mod thermal;
pub mod thermal_instrument;
pub mod waveguide;
