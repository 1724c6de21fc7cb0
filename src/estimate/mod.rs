//! Robust identification (IRLS with Nelder-Mead), the two steps of the seed paper.
//!
//! 1. [`fit_static`]: the Stribeck parameters `(fc, fs, sigma2, vs)` of each direction
//!    from steady-state points, which [`plateaus_from_recording`] extracts from a raw
//!    constant-velocity record.
//! 2. [`fit_dynamic`]: the bristle parameters `sigma0`, `sigma1` from a closed-loop
//!    position record, by simulating the loop ([`crate::servo::simulate`]) with the
//!    static sets held, with an identifiability verdict per parameter.
//!
//! Both minimise weighted objectives with [`nelder_mead::minimize`] inside an IRLS loop
//! whose weights come from a robust [`Weighting`] (IGG by default, as in the paper).
//! Problems linear in their unknowns (the inverse-dynamics fit of a recording) take
//! [`linear::irls_linear`], IRLS on the weighted normal equations.

pub mod dynamic_fit;
mod irls;
pub mod linear;
pub mod nelder_mead;
pub mod plateaus;
pub mod robust;
pub mod static_fit;

pub use dynamic_fit::{fit_dynamic, fit_dynamic_with, DynamicFit, DynamicFitOptions};
pub use linear::{irls_linear, irls_linear_grid, Design, GridFit, LinearFit, LinearIrlsOptions};
pub use plateaus::{plateaus_from_recording, PlateauOptions, Plateaus};
pub use robust::{median, quantile, robust_scale, Weighting};
pub use static_fit::{fit_static, DirectionFit, StaticFit, StaticFitOptions};
