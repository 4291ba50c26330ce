//! The DSP core. It never imports the plugin framework: it takes plain settings in SI
//! units. Parts: friction contacts ([`friction`]), resonators ([`waveguide`]), the body
//! ([`body`]), the instrument that wires them to notes and a bow ([`instrument`]).

pub mod body;
pub mod bridge;
pub mod filters;
pub mod friction;
pub mod instrument;
pub mod modal;
pub mod resample;
pub mod rubbed;
pub mod thermal;
pub mod waveguide;
