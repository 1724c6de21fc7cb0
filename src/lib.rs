//! # lugre
//!
//! LuGre friction, servo-axis simulation and robust friction identification for
//! linear-motor and ball-screw axes.
//!
//! - [`friction`]: the LuGre model with one static (Stribeck) set per direction, the
//!   exact bristle update and an allocation-free [`friction::Compensator`]. This part
//!   builds without `std` (`--no-default-features`) for embedded controllers, in `f32`
//!   or `f64`.
//! - [`servo`] (feature `std`): model files, closed- and open-loop simulation of the
//!   axis under a PID position or PI speed controller, with friction feed-forward,
//!   current loop and extra physics (cogging, springs, offsets, ...).
//! - [`estimate`] (feature `std`): robust (IRLS) Nelder-Mead identification.
//! - [`inverse`] (feature `std`): inverse dynamics of a recorded axis, the force
//!   residual against a model and its sensitivities (the numerics of the diagnosis).
//! - The Python bindings are the workspace crate `lugre-python` (`bindings/`), built by
//!   maturin as `lugre._core`.
//!
//! The numerical algorithms are fixed in `docs/DESIGN.md`; the NumPy reference
//! `lugre.reference` implements the same steps.
#![cfg_attr(all(not(feature = "std"), not(test)), no_std)]
#![warn(missing_docs)]

pub mod friction;

#[cfg(feature = "std")]
pub mod error;
#[cfg(feature = "std")]
pub mod estimate;
#[cfg(feature = "std")]
pub mod inverse;
#[cfg(feature = "std")]
pub mod servo;

#[cfg(feature = "std")]
pub use error::{Error, Result};
pub use friction::{Compensator, LugreParams, ParamError, StaticSet};
