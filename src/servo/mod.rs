//! The servo axis: model description and simulation.

pub mod coupling;
pub mod effects;
pub(crate) mod fast;
pub mod model;
pub mod sim;

pub(crate) use coupling::coupling_force;
pub use coupling::{load_coupling, Coupling, CouplingOptions, LoadTrajectory};
pub use effects::{Sine, EFFECT_NAMES};
pub use model::{
    Axis, AxisKind, ControlLaw, Controller, CurrentLoop, Effect, Feedforward, FeedforwardKind,
    Model,
};
pub use sim::{
    simulate, simulate_batch, simulate_batch_with, Drive, Integrator, SimOptions, SimResult,
};
