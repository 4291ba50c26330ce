//! Paper B (Maestre, Spa and Smith, "A bowed string physical model including finite-width
//! thermal friction and hair dynamics"; docs/models.md §B): a bow of `N_B` hair nodes across its
//! width `w` on a string with two transverse polarisations, run at the internal rate
//! `fs = c / dx` (`dx = w / N_B`) so that the waveguide segments between nodes are one
//! sample long.
//!
//! **Horizontal plane, per node** (eqs. 3-8): load line `v_s = v_s^p + F / (2 Z)`, hair as a
//! massless spring-dashpot by the trapezoid rule, `v_h = -a F + b` with
//! `a = 1 / (c_h + k_h T / 2)`, `b = -a k_h (x_h + T v_h / 2)` from the previous sample.
//! Sticking means `v_s = v_b + v_h`, so the sticking force is
//! `F_stick = (v_b + b - v_s^p) / (1 / (2Z) + a)`; the node sticks if
//! `|F_stick| <= mu(T) F_N`, else it slips with `F = sgn(F_stick) mu(T) F_N`. Friction does
//! not depend on velocity, so the crossing is unique: no iteration, no hysteresis rule
//! (hysteresis comes from the temperature). `F` is the force of the bow on the string,
//! positive along the bow's motion.
//!
//! **Thermal friction** (eq. 1): `dT/dt = alpha d2T/dx2 - C_C T |v_D| + C_H |f v_D|` on a grid
//! of spacing `dx` covering the bow plus a margin each side, `T = 0` beyond it, with `f`
//! the friction force per unit length (`F / dx`). Forward Euler in time, centred in space:
//! stable only if `alpha dt / dx^2 < 1/2` (eq. 2). Every change of the grid checks it and
//! sub-steps the update (`ceil(r / 0.45)` steps of `dt / n`), so it never runs unstable.
//! `mu(T)` is piecewise linear: `mu_cold` below `T_cold`, `mu_hot` above `T_hot`. Two
//! terms paper B does not have are on by default: a bulk cooling `- T / tau_b` and the
//! heating referred to a reference load, `C_H (p_ref / p) |f v_D|`; without them (paper
//! B's eq. 1 as written, [`ThermalParams::paper_b_eq1`]) steady sliding is stable at every
//! force and speed (see [`ThermalParams::default`] and [`bulk_cooled`]).
//!
//! **Vertical plane, per node** (eqs. 9-10): a lumped junction loaded by the hair's vertical
//! admittance, a mass on a parallel spring-dashpot discretised by the trapezoid rule. The
//! dynamic hair force `F_h^y` adds to the player's force: `F_N = F_b + F_h^y` (clamped at
//! zero: the string can leave the hair), which couples the planes.
//!
//! **Terminations.** At each end the two polarisations reflect through a real 2x2
//! admittance `Y` (nut) or `Y` plus a one-pole loss per polarisation (bridge):
//! `R = -(I + Z Y)^-1 (I - Z Y)`, passive for any PSD `Y`. The four-string modal bridge of
//! paper B couples four of these strings in
//! [`super::thermal_instrument`].
//!
//! Values paper B does not publish are chosen here and justified in
//! [`ThermalParams::default`] and [`HairParams::default`].
//!
//! **Parts.** `waves` holds the string without its bow (both polarisations' travelling
//! waves, end filters and reflections, energy and sleep), `hair` the bow's nodes and their
//! stick/slip solve (both planes), `grid` the thermal grid of eq. (1) and its FTCS update;
//! this module joins them ([`ThermalString`]).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `N_B`, `w`, `dx` | nodes, bow width, node spacing `w / N_B` | 1, m, m |
//! | `Z` | string impedance | kg/s |
//! | `k_h`, `c_h` | hair stiffness and damping per metre of ribbon | N/m/m, kg/s/m |
//! | `m_y`, `k_y`, `c_y` | hair vertical mass, stiffness, damping per metre | kg/m, N/m/m, kg/s/m |
//! | `alpha` | thermal diffusivity | m^2/s |
//! | `C_C` | convective loss per metre slid | 1/m |
//! | `C_H` | heating per unit frictional power per length | K m/J |
//! | `tau_b` | bulk cooling time | s |
//! | `p_ref` | load per metre the heating is referred to | N/m |
//! | `F_b` | bow force per unit length | N/m |
//!
//! ```
//! use colophony::dsp::thermal::{
//!     HairParams, ThermalBowControl, ThermalParams, ThermalString, ThermalStringSpec,
//! };
//! // Paper B's Figure 6 bow on the cello's open C, 10 hair nodes over 1 cm.
//! let mut string = ThermalString::new(
//!     ThermalStringSpec::cello_c(),
//!     10,
//!     0.01,
//!     ThermalParams::default(),
//!     HairParams::default(),
//! )
//! .unwrap();
//! let bow = ThermalBowControl { velocity_m_per_s: 0.15, force_n_per_m: 300.0, position_beta: 0.07 };
//! let fs = string.internal_rate_hz();
//! let peak = (0..(0.1 * fs) as usize)
//!     .map(|_| string.tick(bow).bridge_force_n.abs())
//!     .fold(0.0, f64::max);
//! assert!(peak > 0.0);
//! ```

use super::delay::split_loop;
use super::filters::{Allpass1, OnePoleLoss};
use super::friction::{BowInput, FrictionContact, HyperbolicFriction, LoadLine};
use super::instrument::{STICK_MU_D, STICK_MU_S};
use super::vocabulary::InstrumentKind;
use super::waveguide::Striker;
use grid::ThermalGrid;
use hair::{solve_nodes, sum_lanes, NodeConsts, Nodes};
use waves::Waves;

mod grid;
mod hair;
mod waves;
use std::f64::consts::PI;

/// Largest `alpha dt / dx^2` used per thermal sub-step (the bound is 1/2).
pub const FTCS_TARGET: f64 = 0.45;
/// Most thermal sub-steps per sample before a configuration is refused.
pub const MAX_THERMAL_SUBSTEPS: usize = 64;
/// Fewest nodes a bow narrowed on a short string keeps (a point contact).
pub const MIN_BOW_NODES: usize = 1;
/// Samples of string the bow leaves free: one at the bridge, the rest toward the nut.
pub const BOW_CLEARANCE: usize = 4;

/// Largest factor by which [`ThermalParams::heating_scale`] raises the heating (a load
/// 1000 times below the reference: 0.3 N/m, 3 mN over a 1 cm bow, where friction is
/// nothing).
pub const MAX_LOAD_RATIO: f64 = 1000.0;

/// Temperature-dependent friction and heat (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalParams {
    pub mu_cold: f64,
    pub mu_hot: f64,
    pub t_cold_kelvin: f64,
    pub t_hot_kelvin: f64,
    pub diffusivity_m2_per_s: f64,
    pub c_c_per_m: f64,
    pub c_h_kelvin_m_per_j: f64,
    /// Cooling of the contact into the string's core and the rosin below it, `1 / tau_b`,
    /// 1/s: eq. (1) gains `- T / tau_b` (0: eq. 1 as paper B writes it).
    pub bulk_cooling_per_s: f64,
    /// Heating per unit of real contact area, N/m: the source becomes
    /// `C_H (p_ref / p) |f v_D|`, `p` the bow's load per metre (0: heating by the load, eq. 1
    /// as paper B writes it).
    pub heating_reference_load_n_per_m: f64,
    /// Grid margin beyond each edge of the bow, m.
    pub margin_m: f64,
}

impl Default for ThermalParams {
    /// Paper B publishes none of these (docs/literature-values.md §1.3: \[NF\]). Chosen by
    /// measurement (`colophony bench thermal-constants`, docs/playing-space.md, "Choosing
    /// the thermal constants") so that the contact sticks across each string's Schelleng
    /// window, the plugin's default 1 N lies inside every string's window, paper B's own
    /// checks hold (Figure 6, the window test, the hair, `lab/tests/paper_b.rs`), and the
    /// pitch falls with the force by cents below `F_max / 2`:
    /// - **bulk cooling in 33 us** (`- T / tau_b`, heat leaving the contact into the
    ///   string's core and the rosin layer). A contact that keeps its heat for
    ///   milliseconds, as eq. (1) alone does, slides steadily at every force (its sliding
    ///   equilibrium does not depend on the speed) and, where it sticks, flattens by a
    ///   semitone; cooling rates of 1e4-1e5 /s while sliding are the order of the
    ///   secondary source in docs/literature-values.md §1.3;
    /// - **heating per unit of real contact area**, referred to paper B's 300 N/m (rosin
    ///   junctions yield plastically, so the real contact area grows with the load: Smith
    ///   and Woodhouse 2000), so the contact's temperature does not grow with the force;
    /// - `C_C` 15000 /m and `C_H` 4500 K m/J: the sliding equilibrium
    ///   `T_eq(v) = C_H mu p_ref v / (C_C v + 1 / tau_b)` is about 2.5 K at 0.1 m/s,
    ///   11 K at 0.5 m/s and 18 K at 1 m/s (taking mu 0.6), so the steady sliding
    ///   friction falls with speed across the 2-14 K of `mu(T)`, a thermal counterpart of
    ///   the hyperbolic law;
    /// - `mu` falls from 0.8 when cool to 0.5 when hot: the 0.3 drop puts the violin's E
    ///   string's `F_max` at 1.15 N (beta 0.1, 0.1 m/s), above the default force (a 0.5 drop
    ///   gave 0.69 N); 0.55 and above break paper B's Figure 6;
    /// - diffusion over the grid as before: `alpha = 4e-3 m^2/s` (an equivalent
    ///   diffusivity) spreads heat across the 1.4 cm grid in about 5 ms.
    ///
    /// Paper B's eq. (1) as written (no bulk cooling, heating by the load, `mu` 0.8 to
    /// 0.3, `C_C` 2000, `C_H` 250): [`ThermalParams::paper_b_eq1`].
    fn default() -> Self {
        Self {
            mu_cold: 0.8,
            mu_hot: 0.5,
            t_cold_kelvin: 2.0,
            t_hot_kelvin: 14.0,
            diffusivity_m2_per_s: 4e-3,
            c_c_per_m: 15000.0,
            c_h_kelvin_m_per_j: 4500.0,
            bulk_cooling_per_s: 1.0 / 33e-6,
            heating_reference_load_n_per_m: 300.0,
            margin_m: 2e-3,
        }
    }
}

impl ThermalParams {
    /// Paper B's eq. (1) as written: no bulk cooling, heating by the load; the equilibrium temperature of
    /// steady sliding, `T_eq = C_H f / C_C`, is `250 * 0.4 * 300 / 2000 = 15 K` at paper B's
    /// 300 N/m (inside the 10-25 K swing reported for rosin) at every sliding speed; a
    /// slip of ~1 ms at ~0.5 m/s relaxes toward it (`C_C |v| ~ 1000 /s`); `mu` 0.8 to 0.3
    /// over 2-14 K. It slides steadily across most of the window (docs/playing-space.md,
    /// "Why the thermal model slides with eq. (1) as written").
    pub fn paper_b_eq1() -> Self {
        Self {
            mu_cold: 0.8,
            mu_hot: 0.3,
            t_cold_kelvin: 2.0,
            t_hot_kelvin: 14.0,
            diffusivity_m2_per_s: 4e-3,
            c_c_per_m: 2000.0,
            c_h_kelvin_m_per_j: 250.0,
            bulk_cooling_per_s: 0.0,
            heating_reference_load_n_per_m: 0.0,
            margin_m: 2e-3,
        }
    }
}

/// The thermal constants of the bulk-cooled contact (docs/playing-space.md, "Choosing the
/// thermal constants"): bulk cooling in 0.3 ms, heating per unit of contact area at
/// 300 N/m, `C_C` 5000 /m, `C_H` 1500 K m/J, the rest as [`ThermalParams::paper_b_eq1`].
/// Measured: it sticks in most of the window's upper two thirds, and flattens steeply
/// with the force.
pub fn bulk_cooled() -> ThermalParams {
    ThermalParams {
        c_c_per_m: 5000.0,
        c_h_kelvin_m_per_j: 1500.0,
        bulk_cooling_per_s: 1.0 / 3e-4,
        heating_reference_load_n_per_m: 300.0,
        ..ThermalParams::paper_b_eq1()
    }
}

impl ThermalParams {
    /// Piecewise-linear `mu(T)` (paper B, Figure 2).
    #[inline]
    pub fn mu(&self, t_kelvin: f64) -> f64 {
        let u = ((t_kelvin - self.t_cold_kelvin) / (self.t_hot_kelvin - self.t_cold_kelvin))
            .clamp(0.0, 1.0);
        self.mu_cold + (self.mu_hot - self.mu_cold) * u
    }

    /// The temperature at which a contact sliding steadily at `speed` (m/s) under a
    /// friction force of `friction_per_m` (N per metre of bow) on a load of `load_per_m`
    /// (N/m) loses heat as fast as it gains it, K above ambient (eq. 1 without
    /// diffusion): `C_H' |f| v / (C_C v + 1 / tau_b)`, with `C_H' = C_H p_ref / p` when the
    /// heating is referred to a load. Below it a sliding node warms, unless diffusion
    /// carries more away. Paper B's constants: `C_H |f| / C_C` at every speed.
    pub fn sliding_equilibrium_kelvin(
        &self,
        friction_per_m: f64,
        load_per_m: f64,
        speed: f64,
    ) -> f64 {
        let heating = self.c_h_kelvin_m_per_j * self.heating_scale(load_per_m);
        let v = speed.abs();
        let loss = self.c_c_per_m * v + self.bulk_cooling_per_s;
        if loss > 0.0 {
            heating * friction_per_m.abs() * v / loss
        } else {
            f64::INFINITY
        }
    }

    /// What the heating `C_H` is multiplied by at a load of `load_per_m` (N/m): 1 as
    /// paper B writes eq. (1), or `p_ref / p` when the heating is referred to a load
    /// ([`ThermalParams::heating_reference_load_n_per_m`]), capped at
    /// [`MAX_LOAD_RATIO`] so a bow barely touching cannot scale it out of range.
    #[inline]
    pub fn heating_scale(&self, load_per_m: f64) -> f64 {
        let p_ref = self.heating_reference_load_n_per_m;
        if p_ref > 0.0 && load_per_m > 0.0 {
            (p_ref / load_per_m).min(MAX_LOAD_RATIO)
        } else {
            1.0
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        let all = [
            self.mu_cold,
            self.mu_hot,
            self.t_cold_kelvin,
            self.t_hot_kelvin,
            self.diffusivity_m2_per_s,
            self.c_c_per_m,
            self.c_h_kelvin_m_per_j,
            self.bulk_cooling_per_s,
            self.heating_reference_load_n_per_m,
            self.margin_m,
        ];
        if all.iter().any(|x| !x.is_finite()) {
            return Err("thermal parameters must be finite".into());
        }
        if !(self.mu_cold >= 0.0 && self.mu_hot >= 0.0) {
            return Err("friction coefficients must be non-negative".into());
        }
        if !(self.t_hot_kelvin > self.t_cold_kelvin) {
            return Err("need T_hot > T_cold".into());
        }
        if !(self.diffusivity_m2_per_s > 0.0
            && self.c_c_per_m >= 0.0
            && self.c_h_kelvin_m_per_j >= 0.0)
        {
            return Err("need alpha > 0, C_C >= 0, C_H >= 0".into());
        }
        if !(self.bulk_cooling_per_s >= 0.0 && self.heating_reference_load_n_per_m >= 0.0) {
            return Err("need 1 / tau_b >= 0 and a reference load >= 0".into());
        }
        if !(self.margin_m >= 0.0) {
            return Err("the grid margin must be non-negative".into());
        }
        Ok(())
    }
}

/// Hair per metre of ribbon (divided among the nodes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairParams {
    pub k_n_per_m_per_m: f64,
    pub c_kg_per_s_per_m: f64,
    pub vertical_mass_kg_per_m: f64,
    pub vertical_k_n_per_m_per_m: f64,
    pub vertical_c_kg_per_s_per_m: f64,
}

impl Default for HairParams {
    /// Horizontal: the lumped ribbon of Matusiak's code (k 4.83e4 N/m, d 5.77 kg/s over
    /// 1 cm; docs/literature-values.md §1.5) per metre. Vertical: \[NF\] in paper B; a ribbon of ~50
    /// active hairs (0.1 g/m each, so 5 g/m) on the bow's vertical stiffness, chosen at the
    /// same per-metre stiffness and damping as the horizontal hair.
    fn default() -> Self {
        Self {
            k_n_per_m_per_m: 4.83e4 / 0.01,
            c_kg_per_s_per_m: 5.77 / 0.01,
            vertical_mass_kg_per_m: 5e-3,
            vertical_k_n_per_m_per_m: 4.83e4 / 0.01,
            vertical_c_kg_per_s_per_m: 5.77 / 0.01,
        }
    }
}

/// One string with a finite-width thermal bow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalStringSpec {
    pub f0_hz: f64,
    pub z0_kg_per_s: f64,
    pub length_m: f64,
    /// Quality factor of the fundamental (loss at the bridge).
    pub q1: f64,
    /// Quality factor at ten times the fundamental (the loop's loss falls log-linearly
    /// from `q1`: [`OnePoleLoss::for_string`], the waveguide string's design).
    pub q_hi: f64,
    /// Nut admittance (real, PSD), s/kg, [[hh, hv], [hv, vv]].
    pub nut_admittance: [[f64; 2]; 2],
    /// Bridge admittance (real, PSD), s/kg.
    pub bridge_admittance: [[f64; 2]; 2],
}

impl ThermalStringSpec {
    /// The cello's four strings C, G, D, A as the instrument's data gives them
    /// ([`InstrumentKind::Cello`]'s spec), with [`Self::cello_c`]'s terminations.
    pub fn cello_strings() -> [Self; 4] {
        InstrumentKind::Cello.strings().map(|s| Self {
            f0_hz: s.open_hz,
            z0_kg_per_s: s.z0_kg_per_s,
            ..Self::cello_c()
        })
    }

    /// Cello open C, from the cello's data ([`InstrumentKind::Cello`]: Z0 1.91 kg/s, within
    /// docs/literature-values.md §1.7's 1.85-1.91 kg/s; 0.69 m).
    pub fn cello_c() -> Self {
        let spec = InstrumentKind::Cello.spec();
        let c = InstrumentKind::Cello.strings()[0];
        Self {
            f0_hz: c.open_hz,
            z0_kg_per_s: c.z0_kg_per_s,
            length_m: spec.string_length_m,
            q1: c.q1,
            q_hi: c.q_hi,
            // Small resistive terminations with polarisation coupling (eigenvalues > 0),
            // losing less per round trip than Q1 allows (C string, horizontal: 0.5 % of
            // the amplitude against exp(-pi / 500) = 0.6 %), so the loop's loss filter
            // makes up the rest and the fundamental decays at Q1.
            nut_admittance: [[2e-4, 5e-5], [5e-5, 3e-4]],
            bridge_admittance: [[1e-3, 3e-4], [3e-4, 2e-3]],
        }
    }
}

/// The player's bow on a thermal string.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalBowControl {
    pub velocity_m_per_s: f64,
    /// Bow force per unit length, N/m (paper B's 300 N/m over 1 cm is 3 N).
    pub force_n_per_m: f64,
    /// Bow centre from the bridge over the string length.
    pub position_beta: f64,
}

/// Per-sample signals of the middle node and the contact (for figures and tests).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ThermalFrame {
    /// Horizontal force on the bridge, N (the audio source).
    pub bridge_force_n: f64,
    /// Horizontal string velocity at the bow's middle node, m/s.
    pub string_velocity_m_per_s: f64,
    /// Total friction force over the bow, N.
    pub friction_force_n: f64,
    /// Total normal force over the bow, N (effective bow force).
    pub normal_force_n: f64,
    /// Hair horizontal velocity at the middle node, m/s.
    pub hair_velocity_m_per_s: f64,
    /// Nodes slipping this sample.
    pub slipping_nodes: usize,
}

/// The float type of the contact: the nodes' state and solve and the thermal grid (the
/// waves, terminations and bridge stay f64). Chosen by measurement (docs/performance.md, "Paper B's instrument"): on
/// paper B's Figure 6 bow at N_B 60, f32 renders differ from f64 by -105 dB over the
/// attack and -93 dB in the steady motion, with the same pitch and harmonics (0.00001
/// dB), far below the node count's own error (-35 dB against N_B 120), and the node and
/// grid loops run eight lanes instead of four. (With f64 here every result is the same
/// bits as before the type was introduced.)
pub type NodeReal = f32;

/// Why a configuration of a thermal string was refused (no allocation: the audio thread
/// may ask).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ThermalConfigError {
    Nodes(usize),
    Width(f64),
    Rate(f64),
    /// Not even one bow node fits on the vibrating length (too high a note for this
    /// internal rate); a bow wider than the string but for that is narrowed instead
    /// ([`ThermalString::set_fundamental`]).
    BowWiderThanString,
    /// The FTCS bound would need more than [`MAX_THERMAL_SUBSTEPS`] sub-steps.
    GridTooFine {
        ratio: f64,
        substeps: usize,
    },
    /// More nodes, grid points or delay than the string was allocated for.
    Capacity,
}

impl std::fmt::Display for ThermalConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Nodes(n) => write!(f, "the node count must be 1..=200, got {n}"),
            Self::Width(w) => write!(f, "the bow width must be 0.1..30 mm, got {w} m"),
            Self::Rate(r) => write!(f, "invalid internal rate {r}"),
            Self::BowWiderThanString => {
                write!(
                    f,
                    "the string is too short for one bow node at this internal rate"
                )
            }
            Self::GridTooFine { ratio, substeps } => write!(
                f,
                "thermal grid too fine: alpha dt / dx^2 = {ratio:.3} needs {substeps} sub-steps \
                 (at most {MAX_THERMAL_SUBSTEPS}); use fewer nodes or a lower diffusivity"
            ),
            Self::Capacity => write!(f, "configuration beyond the allocated capacity"),
        }
    }
}

/// What a [`ThermalString`] allocates for, so later changes of node count, bow width,
/// rate and note never allocate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalCapacity {
    pub max_nodes: usize,
    pub max_rate_hz: f64,
    /// Lowest fundamental the string will be tuned to.
    pub lowest_hz: f64,
}

/// A string with a finite-width thermal bow (see the module doc).
#[derive(Debug, Clone)]
pub struct ThermalString {
    /// AVX2 available for the node loop (detected once, at construction).
    wide_simd: bool,
    /// The node solve's constants for the current configuration.
    consts: NodeConsts,
    /// `1 / 2Z`: the velocity a node's force adds to each travelling wave, m/s per N.
    half_y: f64,
    spec: ThermalStringSpec,
    thermal: ThermalParams,
    hair: HairParams,
    /// Transverse wave speed `2 L f0` (fixed by tension and density: stopping keeps it).
    c_m_per_s: f64,
    /// Nodes under the bow now: the configured count, or fewer where the stopped string is
    /// too short for the whole bow ([`ThermalString::set_fundamental_with_delay`]).
    nodes_count: usize,
    /// Nodes the bow was configured with.
    nodes_configured: usize,
    /// `nodes_configured / nodes_count`: a narrowed bow keeps its total force, so each of
    /// its nodes presses harder by this factor.
    narrowing: f64,
    width_m: f64,
    dx_m: f64,
    internal_rate_hz: f64,
    /// Position index of the first (bridge-side) bow node.
    bow_start: usize,
    /// The waves in both polarisations, their end filters and reflections.
    waves: Waves,
    nodes: Nodes,
    /// Temperature grid: margin, bow nodes, margin.
    grid: ThermalGrid,
    /// Whether the hair touched the string last sample (its state needs clearing on lift).
    contact_active: bool,
    /// Whether any grid point is above ambient (else the FTCS update is skipped).
    thermal_active: bool,
    /// Terminated by a modal bridge, not its own `bridge_admittance`.
    modal_bridge: bool,
    /// The bow's stick plays the string instead of its hair (col legno tratto,
    /// [`ThermalString::set_stick`]).
    stick: bool,
    /// The stick's contact on each node (allocated for the most nodes).
    stick_nodes: Vec<HyperbolicFriction>,
    /// A light finger touching the string (a harmonic, [`ThermalString::set_touch`]): the
    /// partial whose node it touches nearest the bridge (0: none) and its resistance over
    /// the string's two sides', `R / 2Z`.
    touch: (u32, f64),
    /// The bow's stick striking the string (col legno battuto, [`ThermalString::strike`]).
    striker: Striker,
}

/// The bow's stick on one node, at rest: the point-bow strings' stick (the hyperbolic
/// law with the wood's coefficients).
fn stick_contact() -> HyperbolicFriction {
    let mut stick = HyperbolicFriction::default();
    stick.mu_s = STICK_MU_S;
    stick.mu_d = STICK_MU_D;
    stick
}

/// `R = -(I + Z Y)^-1 (I - Z Y)` for a real 2x2 `Y`.
fn reflection(z: f64, y: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let a = [
        [1.0 + z * y[0][0], z * y[0][1]],
        [z * y[1][0], 1.0 + z * y[1][1]],
    ];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let inv = [
        [a[1][1] / det, -a[0][1] / det],
        [-a[1][0] / det, a[0][0] / det],
    ];
    let b = [
        [1.0 - z * y[0][0], -z * y[0][1]],
        [-z * y[1][0], 1.0 - z * y[1][1]],
    ];
    let mut r = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            r[i][j] = -(inv[i][0] * b[0][j] + inv[i][1] * b[1][j]);
        }
    }
    r
}

fn check_psd(name: &str, y: [[f64; 2]; 2]) -> Result<(), String> {
    let ok = y.iter().flatten().all(|v| v.is_finite())
        && (y[0][1] - y[1][0]).abs() <= 1e-12 * (y[0][1].abs() + 1e-30)
        && y[0][0] >= 0.0
        && y[1][1] >= 0.0
        && y[0][0] * y[1][1] >= y[0][1] * y[0][1];
    if ok {
        Ok(())
    } else {
        Err(format!(
            "the {name} admittance must be a finite symmetric PSD matrix, got {y:?}"
        ))
    }
}

/// The loop at `fs` for a fundamental `f0`: loss filter ([`OnePoleLoss::for_string`]: the
/// fundamental decays at `Q1`, ten times its frequency at `q_hi`, counting the real
/// terminations' own loss `termination_gain`, the horizontal wave's amplitude kept per
/// round trip), integer half-loop `m` and the Thiran coefficient of the remaining delay
/// `d` in `[0.5, 2.5)`: `2 m + d = fs / f0 - loss delay - extra`, `extra` being a
/// termination's phase delay at `f0` in samples (a modal bridge's; 0 for the real 2x2
/// terminations).
///
/// With `partial` above 1 (a harmonic) the loop's delay is matched at the fundamental's
/// `partial`-th multiple instead: the loop holds `partial` periods of the partial there,
/// the filters' phase delays and `extra_delay` taken at that frequency.
fn loop_tuning(
    fs: f64,
    f0: f64,
    partial: u32,
    (q1, q_hi): (f64, f64),
    extra_delay: f64,
    termination_gain: f64,
) -> (OnePoleLoss, usize, f64) {
    let w = 2.0 * PI * f0 * partial.max(1) as f64 / fs;
    let loss = OnePoleLoss::for_string(f0, fs, q1, q_hi, termination_gain);
    let remainder = fs / f0 - loss.phase_delay(w) - extra_delay;
    let (m, d) = split_loop(remainder);
    let a = Allpass1::coefficient_for_delay(d, w);
    (loss, m, a)
}

impl ThermalString {
    /// Builds the string with `nodes` bow nodes over `width_m`. Errors name the bad value.
    pub fn new(
        spec: ThermalStringSpec,
        nodes: usize,
        width_m: f64,
        thermal: ThermalParams,
        hair: HairParams,
    ) -> Result<Self, String> {
        let c = 2.0 * spec.length_m * spec.f0_hz;
        Self::at_rate(
            spec,
            nodes,
            width_m,
            c * nodes as f64 / width_m,
            thermal,
            hair,
        )
    }

    /// The string run at a given internal rate (several strings coupled at one bridge share
    /// one rate): the node spacing is then `c / fs`, so the bow spans `N_B c / fs`, which
    /// is `width_m` only on a string whose rate it set.
    pub fn at_rate(
        spec: ThermalStringSpec,
        nodes: usize,
        width_m: f64,
        internal_rate_hz: f64,
        thermal: ThermalParams,
        hair: HairParams,
    ) -> Result<Self, String> {
        let capacity = ThermalCapacity {
            max_nodes: nodes.max(1),
            max_rate_hz: internal_rate_hz,
            lowest_hz: spec.f0_hz,
        };
        let mut s = Self::with_capacity(spec, thermal, hair, capacity)?;
        s.configure(nodes, width_m, internal_rate_hz)
            .map_err(|e| e.to_string())?;
        Ok(s)
    }

    /// Allocates for every configuration within `capacity` (node counts, rates and notes)
    /// and configures the string at its open pitch with one node at the lowest rate that
    /// fits; call [`ThermalString::configure`] next.
    pub fn with_capacity(
        spec: ThermalStringSpec,
        thermal: ThermalParams,
        hair: HairParams,
        capacity: ThermalCapacity,
    ) -> Result<Self, String> {
        thermal.validate()?;
        check_psd("nut", spec.nut_admittance)?;
        check_psd("bridge", spec.bridge_admittance)?;
        if !(spec.f0_hz > 0.0
            && spec.z0_kg_per_s > 0.0
            && spec.length_m > 0.0
            && spec.q1 > 0.0
            && spec.q_hi > 0.0)
        {
            return Err("string frequency, impedance, length and Qs must be positive".into());
        }
        let ThermalCapacity {
            max_nodes,
            max_rate_hz,
            lowest_hz,
        } = capacity;
        if !(max_rate_hz.is_finite() && max_rate_hz > 0.0) {
            return Err(format!("invalid internal rate {max_rate_hz}"));
        }
        if !(lowest_hz.is_finite() && lowest_hz > 0.0) {
            return Err(format!("invalid lowest frequency {lowest_hz}"));
        }
        let c = 2.0 * spec.length_m * spec.f0_hz;
        let ring = (max_rate_hz / lowest_hz / 2.0).ceil() as usize + 4;
        let dx_min = c / max_rate_hz;
        let grid_capacity = max_nodes + 2 * ((thermal.margin_m / dx_min).round() as usize + 1);
        Ok(Self {
            wide_simd: super::detect_wide_simd(),
            consts: NodeConsts::default(),
            spec,
            thermal,
            hair,
            c_m_per_s: c,
            nodes_count: 0,
            nodes_configured: 0,
            narrowing: 1.0,
            width_m: 0.0,
            dx_m: dx_min,
            internal_rate_hz: max_rate_hz,
            bow_start: 0,
            waves: Waves::new(
                ring,
                reflection(spec.z0_kg_per_s, spec.nut_admittance),
                reflection(spec.z0_kg_per_s, spec.bridge_admittance),
            ),
            nodes: Nodes::with_capacity(max_nodes),
            grid: ThermalGrid::with_capacity(grid_capacity),
            contact_active: true,
            thermal_active: true,
            half_y: 0.5 / spec.z0_kg_per_s,
            modal_bridge: false,
            stick: false,
            stick_nodes: vec![stick_contact(); max_nodes],
            touch: (0, 0.0),
            striker: Striker::default(),
        })
    }

    /// Sets the node count, bow width and internal rate, and silences the string. Checks
    /// the FTCS bound (sub-steps, or refuses), the capacity and that the bow fits; on an
    /// error nothing changes. Never allocates.
    pub fn configure(
        &mut self,
        nodes: usize,
        width_m: f64,
        internal_rate_hz: f64,
    ) -> Result<(), ThermalConfigError> {
        if !(1..=200).contains(&nodes) {
            return Err(ThermalConfigError::Nodes(nodes));
        }
        if !(width_m.is_finite() && (1e-4..=0.03).contains(&width_m)) {
            return Err(ThermalConfigError::Width(width_m));
        }
        if !(internal_rate_hz.is_finite() && internal_rate_hz > 0.0) {
            return Err(ThermalConfigError::Rate(internal_rate_hz));
        }
        let fs = internal_rate_hz;
        let dx = self.c_m_per_s / fs;
        let margin_nodes = (self.thermal.margin_m / dx).round() as usize;
        let grid = nodes + 2 * margin_nodes;
        let r = self.thermal.diffusivity_m2_per_s / fs / (dx * dx);
        let substeps = (r / FTCS_TARGET).ceil().max(1.0) as usize;
        if substeps > MAX_THERMAL_SUBSTEPS {
            return Err(ThermalConfigError::GridTooFine { ratio: r, substeps });
        }
        if nodes > self.nodes.hair_x.capacity() || grid > self.grid.capacity() {
            return Err(ThermalConfigError::Capacity);
        }
        let (loss, m, a) = loop_tuning(
            fs,
            self.spec.f0_hz,
            1,
            (self.spec.q1, self.spec.q_hi),
            0.0,
            self.termination_gain(),
        );
        if m + 4 > self.waves.mask() {
            return Err(ThermalConfigError::Capacity);
        }
        if m < MIN_BOW_NODES + BOW_CLEARANCE {
            return Err(ThermalConfigError::BowWiderThanString);
        }
        self.nodes_configured = nodes;
        self.width_m = width_m;
        self.dx_m = dx;
        self.internal_rate_hz = fs;
        self.grid.set_layout(margin_nodes, substeps);
        self.set_nodes_under_bow(nodes.min(m - BOW_CLEARANCE));
        self.waves.set_loop(m, loss, a);
        self.consts = self.node_consts();
        self.grid
            .set_constants(&self.thermal, self.dx_m, self.internal_rate_hz);
        self.reset();
        Ok(())
    }

    /// Puts `n` nodes under the bow (at most the configured count), at rest, with a cool
    /// grid. Never allocates: the capacity covers the configured count.
    fn set_nodes_under_bow(&mut self, n: usize) {
        self.nodes_count = n;
        self.narrowing = self.nodes_configured as f64 / n as f64;
        self.nodes.resize(n);
        self.grid.cover(n);
    }

    /// The node solve's constants at the current rate and spacing (divisions done once
    /// per configuration, not per sample); the bow's force and velocity are filled in per
    /// sample.
    fn node_consts(&self) -> NodeConsts {
        let dt = 1.0 / self.internal_rate_hz;
        let dx = self.dx_m;
        let half_y = self.half_y;
        // Hair constants per node (trapezoid).
        let k_h = self.hair.k_n_per_m_per_m * dx;
        let c_h = self.hair.c_kg_per_s_per_m * dx;
        // The stick is stiff: no hair yields between it and the string (`v_h = 0`).
        let a = if self.stick {
            0.0
        } else {
            1.0 / (c_h + 0.5 * k_h * dt)
        };
        let m_y = self.hair.vertical_mass_kg_per_m * dx;
        let k_y = self.hair.vertical_k_n_per_m_per_m * dx;
        let c_y = self.hair.vertical_c_kg_per_s_per_m * dx;
        let d_y = m_y / dt + 0.5 * c_y + 0.25 * k_y * dt;
        let e_y = m_y / dt - 0.5 * c_y - 0.25 * k_y * dt;
        let inv_d_y = 1.0 / d_y;
        let th = self.thermal;
        let r = |x: f64| x as NodeReal;
        NodeConsts {
            dt: r(dt),
            a: r(a),
            k_h: r(k_h),
            k_y: r(k_y),
            e_y: r(e_y),
            inv_d_y: r(inv_d_y),
            inv_y_load: r(1.0 / (half_y + 0.5 * inv_d_y)),
            inv_x_load: r(1.0 / (half_y + a)),
            half_y: r(half_y),
            f_b: 0.0,
            v_b: 0.0,
            mu_cold: r(th.mu_cold),
            mu_slope: r((th.mu_hot - th.mu_cold) / (th.t_hot_kelvin - th.t_cold_kelvin)),
            t_cold: r(th.t_cold_kelvin),
            mu_lo: r(th.mu_hot.min(th.mu_cold)),
            mu_hi: r(th.mu_hot.max(th.mu_cold)),
        }
    }

    /// Stops the string so its fundamental is `f0_hz` (the wave speed stays, the vibrating
    /// length shortens): new loss filter, half-loop and Thiran delay, waves kept where they
    /// are. Where the stopped string is too short for the whole bow (fewer than
    /// `nodes + 4` samples), the contact is narrowed to the nodes that fit, keeping the
    /// bow's total force (a player tilts the bow on a short string), and widened back on a
    /// longer note; changing the node count puts the bow's nodes at rest. Returns `false`,
    /// changing nothing, if the note does not fit at all (beyond the capacity, or not one
    /// node on the vibrating length at this rate). Never allocates.
    pub fn set_fundamental(&mut self, f0_hz: f64) -> bool {
        self.set_fundamental_with_delay(f0_hz, 0.0)
    }

    /// The stopping finger's reflection, 0..=1: 1 while it presses the string (the nut's
    /// own reflection), less while it leaves ([`crate::dsp::strings`]'s finger lift). Only
    /// takes energy out.
    pub fn set_finger_reflection(&mut self, reflection: f64) {
        self.waves.set_finger(reflection);
    }

    /// The stopping finger has left: the string sounds `f0_hz` (its open pitch), longer,
    /// the part between the old stopping point and the nut at rest (as
    /// [`ThermalString::set_fundamental_with_delay`] otherwise).
    pub fn release_to_with_delay(&mut self, f0_hz: f64, extra_delay: f64) -> bool {
        let old_m = self.waves.len();
        let ok = self.set_fundamental_with_delay(f0_hz, extra_delay);
        if ok {
            self.waves.rest_beyond(old_m);
        }
        ok
    }

    /// [`ThermalString::set_fundamental`] on an end whose reflection delays the
    /// fundamental by `extra_delay` samples more than the string's own terminations (a
    /// modal bridge's phase delay at `f0`): the loop is shortened by it.
    ///
    /// With a finger touching ([`ThermalString::set_touch`]) the loop is tuned at its
    /// partial `n` instead (`extra_delay` is then the end's delay at `n f0`), and the finger
    /// moves to that partial's node nearest the bridge.
    pub fn set_fundamental_with_delay(&mut self, f0_hz: f64, extra_delay: f64) -> bool {
        if !(f0_hz.is_finite() && f0_hz > 0.0 && extra_delay.is_finite()) {
            return false;
        }
        let fs = self.internal_rate_hz;
        let partial = self.touch.0.max(1);
        let (loss, m, a) = loop_tuning(
            fs,
            f0_hz,
            partial,
            (self.spec.q1, self.spec.q_hi),
            extra_delay,
            self.termination_gain(),
        );
        if m + 4 > self.waves.mask() || m < MIN_BOW_NODES + BOW_CLEARANCE {
            return false;
        }
        let fit = self.nodes_configured.min(m - BOW_CLEARANCE);
        if fit != self.nodes_count {
            self.set_nodes_under_bow(fit);
        }
        self.spec.f0_hz = f0_hz;
        self.spec.length_m = self.c_m_per_s / (2.0 * f0_hz);
        self.waves.retune(m, loss, a);
        if self.touch.0 >= 2 {
            // The round trip bridge-finger-bridge, `2 x + 1` samples plus the bridge end's
            // delays at the partial (its loss filter's and `extra_delay`), is one period
            // of the partial; the finger sits between the two samples around `x`.
            let w = 2.0 * PI * f0_hz * partial as f64 / fs;
            let period = fs / (f0_hz * partial as f64);
            let x = 0.5 * (period - 1.0 - loss.phase_delay(w) - extra_delay);
            let x = x.max(1.0);
            // A finger inside the bow's clearance or beyond the string touches nothing.
            let clear = x > BOW_CLEARANCE as f64 && (x as usize) + BOW_CLEARANCE + 1 < m;
            self.waves
                .set_touch(x, if clear { self.touch.1 } else { 0.0 });
        }
        true
    }

    /// The bow's stick drawn across the string instead of its hair (`true`, col legno
    /// tratto): on every node the point-bow strings' stick, the hyperbolic law with the
    /// wood's [`STICK_MU_S`] and [`STICK_MU_D`] (no rosin, so no thermal softening: the
    /// thermal grid idles), and no hair yields (the stick is stiff); the vertical plane
    /// is the hair's. `false` gives the hair back. The hair's state, the stick's and the
    /// grid's temperatures are put at rest at each change. Never allocates.
    pub fn set_stick(&mut self, stick: bool) {
        if stick == self.stick {
            return;
        }
        self.stick = stick;
        self.consts = self.node_consts();
        self.nodes.hair_x.fill(0.0);
        self.nodes.hair_v.fill(0.0);
        self.stick_nodes.fill(stick_contact());
        self.grid.clear();
        self.thermal_active = false;
    }

    /// The stick's horizontal contact on the `n_b` nodes just solved (their vertical
    /// junctions give the normal forces): each node's force from the hyperbolic law on
    /// its load line `v_s = v_p + F / 2Z`, replacing the thermal law's.
    #[cold]
    fn stick_solve(&mut self, n_b: usize, v_b: f64) {
        let nodes = &mut self.nodes;
        for (i, contact) in self.stick_nodes[..n_b].iter_mut().enumerate() {
            let v_p = f64::from(nodes.vp[i]);
            let f = contact.solve(
                LoadLine {
                    free_velocity_m_per_s: v_p,
                    admittance_s_per_kg: self.half_y,
                },
                BowInput {
                    velocity_m_per_s: v_b,
                    normal_force_n: f64::from(nodes.normal[i]),
                },
            );
            nodes.force[i] = f as NodeReal;
            nodes.v_delta[i] = (v_p + f * self.half_y - v_b) as NodeReal;
        }
    }

    /// A light finger touches the string at the node of its partial `partial` (2 or more)
    /// nearest the bridge, with a resistance of `resistance_kg_per_s`, or leaves it
    /// (`None`): a harmonic. The modes with a node there pass the finger untouched; the
    /// others lose energy at each pass. It is placed, and the loop tuned at the partial, by
    /// the next [`ThermalString::set_fundamental_with_delay`] (the end's delay is then
    /// asked at the partial's frequency). Only takes energy out; never allocates.
    pub fn set_touch(&mut self, touch: Option<(u32, f64)>) {
        self.touch = match touch {
            Some((partial, r)) if partial >= 2 && r.is_finite() && r > 0.0 => {
                (partial, r / (2.0 * self.spec.z0_kg_per_s))
            }
            _ => (0, 0.0),
        };
        if self.touch.0 == 0 {
            self.waves.set_touch(0.0, 0.0);
        }
    }

    /// Plucks the string (pizzicato) in its horizontal polarisation: pulled
    /// `displacement_m` aside at `position_beta` of its length from the bridge, the kink
    /// rounded over `width` of it (the finger's contact), and let go from rest; added to
    /// what the string already does. False (nothing changed) for a non-finite pluck or a
    /// string too short for it. Never allocates.
    pub fn pluck(&mut self, displacement_m: f64, position_beta: f64, width: f64) -> bool {
        if !(displacement_m.is_finite() && position_beta.is_finite() && width.is_finite()) {
            return false;
        }
        self.waves
            .pluck(displacement_m * self.internal_rate_hz, position_beta, width)
    }

    /// Strikes the string with the bow's stick (col legno battuto): a rigid `mass_kg`
    /// arriving at `velocity_m_per_s` in the bowing plane (as on the point-bow strings;
    /// from above the note is about 10 dB fainter, the instrument hearing the vertical
    /// polarisation only through the bridge's coupling: docs/articulations.md) at the
    /// bow's middle node, which pushes the string until the string would pull it back (the point-bow
    /// strings' stick, [`crate::dsp::waveguide::WaveguideString::strike`]). The string
    /// takes what the stick loses, momentum `m (u0 - u1)` and energy
    /// `m (u0^2 - u1^2) / 2`. While it is on, [`ThermalString::strike_contact`] replaces
    /// the bow's contact. False (nothing changed) for a mass or speed that is not finite
    /// and positive. Never allocates.
    pub fn strike(&mut self, mass_kg: f64, velocity_m_per_s: f64) -> bool {
        let striker = Striker::new(mass_kg, velocity_m_per_s, self.internal_rate_hz);
        if !striker.is_on() {
            return false;
        }
        self.striker = striker;
        self.waves.wake();
        true
    }

    /// Whether a striking stick is on the string.
    #[inline(always)]
    pub fn is_struck(&self) -> bool {
        self.striker.is_on()
    }

    /// The stick's velocity toward the string, m/s (negative once it rebounds).
    pub fn striker_velocity_m_per_s(&self) -> f64 {
        self.striker.velocity_m_per_s()
    }

    /// One sample of the striking stick's contact ([`ThermalString::strike`]) at the
    /// middle node of a bow at `position_beta`, instead of the bow's: the string's free
    /// horizontal velocity there meets the stick through the string's admittance,
    /// `1 / 2Z` (the stick is rigid: no hair between them). Returns the string's
    /// horizontal velocity there, m/s.
    #[cold]
    pub fn strike_contact(&mut self, position_beta: f64) -> f64 {
        let m = self.waves.len();
        let x = ((position_beta.clamp(0.01, 0.5) * m as f64 + 0.5) as usize).clamp(1, m - 2);
        let v_free = self.waves.velocity_h(x);
        let dt = 1.0 / self.internal_rate_hz;
        let dv = self.striker.push(v_free, self.half_y, dt) * self.half_y;
        self.waves.push_h(x, dv);
        v_free + dv
    }

    /// The partial a touching finger leaves sounding (1: no finger).
    pub fn touched_partial(&self) -> u32 {
        self.touch.0.max(1)
    }

    /// Where the touching finger is, samples from the bridge (`None`: no finger, or
    /// none that fits the string at this rate).
    pub fn touch_position(&self) -> Option<f64> {
        self.waves.touch_at()
    }

    /// The horizontal wave's amplitude kept per round trip by the string's real
    /// terminations: the nut's, and its own bridge's unless a modal bridge terminates it
    /// ([`ThermalString::use_modal_bridge`], whose loss is the body's, on top of `Q1`).
    fn termination_gain(&self) -> f64 {
        let rn = self.waves.nut_reflection();
        if self.modal_bridge {
            return rn[0][0].abs();
        }
        let rb = self.waves.bridge_reflection();
        (rb[0][0] * rn[0][0] + rb[0][1] * rn[1][0]).abs()
    }

    /// Marks the string as terminated by a modal bridge (four strings at one bridge,
    /// [`super::thermal_instrument`]): its own bridge admittance is unused, and the loop
    /// loss no longer makes up for it. Takes effect at the next tuning.
    pub fn use_modal_bridge(&mut self) {
        self.modal_bridge = true;
    }

    /// Quality factor of the fundamental.
    pub fn q1(&self) -> f64 {
        self.spec.q1
    }

    /// Fundamental the loop is tuned to, Hz.
    pub fn fundamental_hz(&self) -> f64 {
        self.spec.f0_hz
    }

    /// Transverse wave speed, m/s.
    pub fn wave_speed_m_per_s(&self) -> f64 {
        self.c_m_per_s
    }
    pub fn internal_rate_hz(&self) -> f64 {
        self.internal_rate_hz
    }

    /// Nodes under the bow now (fewer than configured on a note too short for the bow).
    pub fn nodes(&self) -> usize {
        self.nodes_count
    }

    /// Nodes the bow was configured with.
    pub fn nodes_configured(&self) -> usize {
        self.nodes_configured
    }

    pub fn width_m(&self) -> f64 {
        self.width_m
    }

    /// Thermal sub-steps per sample chosen from the FTCS bound.
    pub fn thermal_substeps(&self) -> usize {
        self.grid.substeps()
    }

    /// `alpha dt / dx^2` per sub-step (always below 1/2).
    pub fn ftcs_ratio(&self) -> f64 {
        self.thermal.diffusivity_m2_per_s
            / (self.internal_rate_hz * self.grid.substeps() as f64)
            / (self.dx_m * self.dx_m)
    }

    /// Integer part of the loop at the internal rate (the filters add the rest).
    pub fn loop_samples(&self) -> usize {
        2 * self.waves.len()
    }

    /// Temperatures of the bow nodes, K above ambient.
    pub fn node_temperatures(&self) -> &[NodeReal] {
        self.grid.under_bow(self.nodes_count)
    }

    /// The whole thermal grid (margins included).
    pub fn temperature_grid(&self) -> &[NodeReal] {
        self.grid.all()
    }

    /// Friction force per node on the last sample, N.
    pub fn node_forces(&self) -> &[NodeReal] {
        &self.nodes.force
    }

    /// Normal (vertical) force per node on the last sample, N: the bow's share plus what
    /// the hair's vertical motion adds.
    pub fn node_normal_forces(&self) -> &[NodeReal] {
        &self.nodes.normal
    }

    /// Which nodes slipped on the last sample (their sliding velocity is not zero).
    pub fn slipping(&self) -> impl ExactSizeIterator<Item = bool> + '_ {
        self.nodes.v_delta.iter().map(|v| *v != 0.0)
    }

    /// Sliding velocity per node on the last sample, m/s: zero where the node sticks (or
    /// the bow is lifted), so a node slipped where it is not zero.
    pub fn node_sliding_velocities(&self) -> &[NodeReal] {
        &self.nodes.v_delta
    }

    /// Wave energy of both polarisations, what the loss and Thiran filters at the ends
    /// hold (see [`OnePoleLoss::stored_energy`], [`Allpass1::stored_energy`]) and the
    /// hair's stored energy, J.
    pub fn energy_j(&self) -> f64 {
        let [h, v] = self.wave_energies_j();
        h + v + self.hair_energy_j()
    }

    /// Energy of each polarisation's waves and end filters, `[h, v]`, J.
    fn wave_energies_j(&self) -> [f64; 2] {
        self.waves
            .energies_j(self.spec.z0_kg_per_s, self.internal_rate_hz)
    }

    /// Energy the hair holds (horizontal spring, vertical mass and spring), J.
    fn hair_energy_j(&self) -> f64 {
        let dx = self.dx_m;
        (0..self.nodes_count)
            .map(|i| {
                let n = &self.nodes;
                let (hx, vy, y) = (
                    f64::from(n.hair_x[i]),
                    f64::from(n.vy[i]),
                    f64::from(n.y[i]),
                );
                0.5 * self.hair.k_n_per_m_per_m * dx * hx.powi(2)
                    + 0.5 * self.hair.vertical_mass_kg_per_m * dx * vy.powi(2)
                    + 0.5 * self.hair.vertical_k_n_per_m_per_m * dx * y.powi(2)
            })
            .sum()
    }

    /// Puts each polarisation whose waves hold less than `threshold_j / 2` to sleep: its
    /// lines and filters are cleared and no longer computed. A sleeping polarisation
    /// drops the waves the bridge (and the other polarisation, at the nut) send into it
    /// and wakes, exactly where it left off (zeros), once they add up to `threshold_j /
    /// 2`; a bow landing wakes both. So a polarisation that sleeps and wakes loses less
    /// than `threshold_j`. Only with the bow off this string (else nothing happens).
    /// Walks the delay lines: once per block.
    pub fn sleep_quiet_polarisations(&mut self, threshold_j: f64) {
        if self.contact_active || self.is_struck() {
            return;
        }
        self.waves
            .sleep_quiet(threshold_j, self.spec.z0_kg_per_s, self.internal_rate_hz);
    }

    /// `[h, v]`: which polarisations sleep.
    pub fn asleep(&self) -> [bool; 2] {
        self.waves.asleep()
    }

    /// Whether both polarisations sleep and the temperature grid has cooled (the string
    /// then costs only its ring index).
    #[inline(always)]
    pub fn is_asleep(&self) -> bool {
        let [h, v] = self.waves.asleep();
        h & v & !self.thermal_active
    }

    pub fn reset(&mut self) {
        self.waves.reset();
        self.striker = Striker::default();
        let n = &mut self.nodes;
        for v in [
            &mut n.hair_x,
            &mut n.hair_v,
            &mut n.vy,
            &mut n.y,
            &mut n.fy,
            &mut n.force,
            &mut n.v_delta,
        ] {
            v.fill(0.0);
        }
        self.grid.clear();
    }

    /// One sample at the internal rate with the string's own (2x2 admittance) bridge. A bow
    /// force of zero lifts the bow (no contact in either plane).
    pub fn tick(&mut self, bow: ThermalBowControl) -> ThermalFrame {
        let velocity = if self.is_struck() {
            self.strike_contact(bow.position_beta)
        } else {
            self.tick_contact(bow)
        };
        let mut frame = ThermalFrame {
            string_velocity_m_per_s: velocity,
            ..ThermalFrame::default()
        };
        self.contact_sums(&mut frame);
        self.terminate_alone(&mut frame);
        frame
    }

    /// Total friction force over the bow on the last sample, N (zero with the bow lifted).
    pub fn friction_force_n(&self) -> f64 {
        sum_lanes(&self.nodes.force)
    }

    /// The last sample's sums over the bow's nodes into `frame`: friction and normal
    /// force, nodes slipping, and the middle node's hair velocity (all zero with the bow
    /// lifted: the lift clears the nodes). Computed when asked, not every internal sample:
    /// the instrument reads only the probed string's friction force, once a host sample.
    pub fn contact_sums(&self, frame: &mut ThermalFrame) {
        let nodes = &self.nodes;
        frame.friction_force_n = self.friction_force_n();
        frame.normal_force_n = sum_lanes(&nodes.normal);
        frame.slipping_nodes = self.slipping().filter(|s| *s).count();
        frame.hair_velocity_m_per_s = nodes
            .hair_v
            .get(self.nodes_count / 2)
            .map_or(0.0, |v| f64::from(*v));
    }

    /// Whether [`ThermalString::tick_contact`] with the bow lifted would do nothing but
    /// report the string's velocity: the contact is cleared and the grid has cooled.
    #[inline(always)]
    pub fn contact_idle(&self) -> bool {
        !self.contact_active && !self.thermal_active
    }

    /// The bow contact and thermal update of one sample (no terminations). Returns the
    /// horizontal string velocity at the bow's middle node, m/s; the sums over the nodes
    /// are [`ThermalString::contact_sums`].
    #[inline(always)]
    pub fn tick_contact(&mut self, bow: ThermalBowControl) -> f64 {
        let m = self.waves.len();
        let n_b = self.nodes_count;
        // Round half up (beta * m >= 0), without a libm call per sample.
        let centre = (bow.position_beta.clamp(0.01, 0.5) * m as f64 + 0.5) as usize;
        self.bow_start = centre.saturating_sub(n_b / 2).clamp(1, m - n_b - 1);
        let dx = self.dx_m;
        let f_b = bow.force_n_per_m.max(0.0) * dx * self.narrowing;
        let on = f_b > 0.0;
        if on {
            // A landing bow wakes the string (its sleeping lines hold zeros).
            self.waves.wake();
            self.grid
                .set_load(&self.thermal, bow.force_n_per_m * self.narrowing);
        }
        let mut string_velocity = 0.0;
        let mid = n_b / 2;
        let half_y = self.half_y;

        let span = self.waves.span(self.bow_start, n_b);
        let nodes = &mut self.nodes;
        if !on {
            if !self.contact_active {
                // Already lifted and cleared: nothing to do (an unbowed string costs only
                // its waves).
            } else {
                for v in [
                    &mut nodes.force,
                    &mut nodes.fy,
                    &mut nodes.v_delta,
                    &mut nodes.hair_x,
                    &mut nodes.hair_v,
                    &mut nodes.y,
                    &mut nodes.vy,
                ] {
                    v.fill(0.0);
                }
                self.contact_active = false;
            }
        } else {
            self.contact_active = true;
            // Gather the incoming waves, solve every node (independent within a sample,
            // branch-free so it vectorises), scatter the outgoing waves.
            self.waves.gather(span, &mut nodes.vp, &mut nodes.vp_y);
            let temps = self.grid.under_bow(n_b);
            let k = NodeConsts {
                f_b: f_b as NodeReal,
                v_b: bow.velocity_m_per_s as NodeReal,
                ..self.consts
            };
            solve_nodes(self.wide_simd, k, nodes, temps, n_b);
            if self.stick {
                self.stick_solve(n_b, bow.velocity_m_per_s);
            }
            let nodes = &mut self.nodes;
            self.waves.scatter(span, &nodes.force, &nodes.fy, half_y);
            string_velocity = f64::from(nodes.vp[mid]) + f64::from(nodes.force[mid]) * half_y;
        }
        if !on {
            string_velocity = self.waves.velocity_h(self.bow_start + mid);
        }
        // The grid idles once the bow is off and the contact has cooled to nothing, and
        // while the stick plays (its friction does not depend on the temperature).
        let heated = on && !self.stick;
        if heated || self.thermal_active {
            self.grid.update(
                self.wide_simd,
                &self.nodes.v_delta[..n_b],
                &self.nodes.force[..n_b],
            );
            if !heated {
                self.thermal_active = self.grid.any_warm();
            }
        }
        if heated {
            self.thermal_active = true;
        }

        string_velocity
    }

    fn terminate_alone(&mut self, frame: &mut ThermalFrame) {
        let z = self.spec.z0_kg_per_s;
        // Terminations: the string's own bridge reflection.
        let at_bridge = self.arriving_at_bridge();
        let rb = self.waves.bridge_reflection();
        let outgoing = [
            rb[0][0] * at_bridge[0] + rb[0][1] * at_bridge[1],
            rb[1][0] * at_bridge[0] + rb[1][1] * at_bridge[1],
        ];
        self.touch_junction();
        self.finish_sample(outgoing);
        // Force on the bridge: incoming minus outgoing waves times Z, horizontal.
        frame.bridge_force_n = z * (at_bridge[0] - outgoing[0]);
    }

    /// The `[h, v]` velocity waves arriving at the bridge this sample (after the loss
    /// filter). Call once per sample, after [`ThermalString::tick_contact`] and before
    /// [`ThermalString::finish_sample`]; the bridge model answers with the outgoing waves.
    #[inline(always)]
    pub fn arriving_at_bridge(&mut self) -> [f64; 2] {
        self.waves.arriving_at_bridge()
    }

    /// Ends the sample: writes the waves leaving the bridge, reflects at the nut, and
    /// advances time.
    #[inline(always)]
    pub fn finish_sample(&mut self, leaving_bridge: [f64; 2]) {
        self.waves.finish_sample(leaving_bridge)
    }

    /// The touching finger's junction ([`ThermalString::set_touch`]) for this sample:
    /// call once per sample before [`ThermalString::finish_sample`] while a finger
    /// touches (nothing without one).
    #[inline]
    pub fn touch_junction(&mut self) {
        self.waves.touch_junction();
    }

    pub fn z0_kg_per_s(&self) -> f64 {
        self.spec.z0_kg_per_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflections_of_psd_admittances_are_passive() {
        let r = reflection(1.88, [[1e-2, 3e-3], [3e-3, 2e-2]]);
        // Singular values of R below 1: check ||R v|| < ||v|| on many directions.
        for k in 0..64 {
            let th = k as f64 * PI / 32.0;
            let v = [th.cos(), th.sin()];
            let rv = [
                r[0][0] * v[0] + r[0][1] * v[1],
                r[1][0] * v[0] + r[1][1] * v[1],
            ];
            assert!(rv[0].hypot(rv[1]) < 1.0);
        }
        // Rigid: -I.
        assert_eq!(reflection(1.0, [[0.0; 2]; 2]), [[-1.0, 0.0], [0.0, -1.0]]);
    }

    #[test]
    fn the_avx2_string_gives_the_same_bits_as_the_portable_one() {
        // Paper B's Figure 6 bow on 60 nodes for 0.1 s, then lifted while the grid
        // cools: every path of the node solve and the FTCS update, in both builds, with
        // paper B's eq. (1) as written, the bulk-cooled constants (lifted for 0.5 ms
        // there: its 0.3 ms leaves the grid warm) and the default ones (33 us: lifted for
        // 50 us).
        for (params, lifted_s) in [
            (ThermalParams::paper_b_eq1(), 0.05),
            (bulk_cooled(), 5e-4),
            (ThermalParams::default(), 5e-5),
        ] {
            let make = |wide_simd: bool| {
                let mut s = ThermalString::new(
                    ThermalStringSpec::cello_c(),
                    60,
                    0.01,
                    params,
                    HairParams::default(),
                )
                .unwrap();
                s.wide_simd = wide_simd;
                s
            };
            let (mut portable, mut wide) = (make(false), make(crate::dsp::detect_wide_simd()));
            let fs = portable.internal_rate_hz();
            for n in 0..((0.1 + lifted_s) * fs) as usize {
                let bow = ThermalBowControl {
                    velocity_m_per_s: 0.15,
                    force_n_per_m: if n < (0.1 * fs) as usize { 300.0 } else { 0.0 },
                    position_beta: 0.07,
                };
                let (a, b) = (portable.tick(bow), wide.tick(bow));
                assert_eq!(
                    a.bridge_force_n.to_bits(),
                    b.bridge_force_n.to_bits(),
                    "sample {n}"
                );
                assert_eq!(a.friction_force_n.to_bits(), b.friction_force_n.to_bits());
            }
            let bits = |s: &ThermalString| {
                s.temperature_grid()
                    .iter()
                    .map(|t| t.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&portable), bits(&wide));
            assert!(
                portable.temperature_grid().iter().any(|t| *t > 0.0),
                "the grid was heated"
            );
        }
    }
}
