//! Friction feed-forward for C firmware, from the `no_std` core of `lugre`.
//!
//! The static library holds one [`Compensator`] per axis (up to [`AXES`]); the firmware
//! sets its parameters once, then calls [`lugre_ff_step`] once per control period with
//! the reference velocity and adds the returned force to the current command:
//!
//! ```c
//! #include "lugre_ff.h"
//! static const LugreFfParams p = {1e5f, 31.62f, {28.7f, 60.2f, 332.5f, 0.01f},
//!                                               {28.7f, 60.2f, 332.5f, 0.01f}};
//! if (lugre_ff_init(0, &p) != 0) { /* parameters out of range */ }
//! /* in the 10 kHz control interrupt */
//! force_cmd += lugre_ff_step(0, v_ref, 1e-4f);
//! ```
//!
//! Every function is for one execution context (the control interrupt, or the main loop
//! before interrupts start): the state is not guarded against concurrent calls. Nothing
//! here allocates or panics.
#![no_std]

use core::cell::UnsafeCell;
use lugre::friction::{Compensator, LugreParams, StaticSet};

/// Number of axes the library holds a compensator for.
pub const AXES: usize = 4;

/// One direction's static (Stribeck) friction, SI units.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct LugreFfStatic {
    /// Coulomb force [N].
    pub fc: f32,
    /// Static (breakaway) force [N].
    pub fs: f32,
    /// Viscous coefficient [N s/m].
    pub sigma2: f32,
    /// Stribeck velocity [m/s].
    pub vs: f32,
}

/// The LuGre parameters of one axis.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct LugreFfParams {
    /// Bristle stiffness [N/m].
    pub sigma0: f32,
    /// Bristle damping [N s/m].
    pub sigma1: f32,
    /// Static friction for positive velocity.
    pub positive: LugreFfStatic,
    /// Static friction for negative velocity.
    pub negative: LugreFfStatic,
}

/// The compensators, one slot per axis; `None` until initialised.
struct Axes(UnsafeCell<[Option<Compensator<f32>>; AXES]>);

// SAFETY: the functions below are documented for one execution context; nothing runs
// them concurrently, so the cell is never accessed from two places at once.
unsafe impl Sync for Axes {}

static STATE: Axes = Axes(UnsafeCell::new([None; AXES]));

/// The slot of `axis`, or `None` out of range.
fn slot(axis: u32) -> Option<&'static mut Option<Compensator<f32>>> {
    let i = usize::try_from(axis).ok()?;
    // SAFETY: single execution context (see the crate documentation); the reference
    // does not outlive the calling function.
    unsafe { (*STATE.0.get()).get_mut(i) }
}

fn static_set(s: &LugreFfStatic) -> Option<StaticSet<f32>> {
    StaticSet::new(s.fc, s.fs, s.sigma2, s.vs).ok()
}

fn params_of(p: &LugreFfParams) -> Option<LugreParams<f32>> {
    let pos = static_set(&p.positive)?;
    let neg = static_set(&p.negative)?;
    LugreParams::new(p.sigma0, p.sigma1, pos, neg).ok()
}

/// Set the parameters of `axis` and put its bristle state at rest.
///
/// Returns 0 on success, -1 for an axis out of range or a null pointer, -2 for
/// parameters out of range (the axis is then left as it was).
///
/// # Safety
/// `params` is null or points to a valid `LugreFfParams`.
#[no_mangle]
pub unsafe extern "C" fn lugre_ff_init(axis: u32, params: *const LugreFfParams) -> i32 {
    // SAFETY: the caller passes null or a valid pointer.
    let (Some(s), Some(p)) = (slot(axis), unsafe { params.as_ref() }) else {
        return -1;
    };
    match params_of(p) {
        Some(lp) => {
            *s = Some(Compensator::new(lp));
            0
        }
        None => -2,
    }
}

/// The friction feed-forward force [N] of `axis` at velocity `v` [m/s], then the bristle
/// state advanced over `dt` [s]: call once per control period. An axis out of range or
/// not initialised gives 0.
#[no_mangle]
pub extern "C" fn lugre_ff_step(axis: u32, v: f32, dt: f32) -> f32 {
    match slot(axis) {
        Some(Some(c)) => c.step(v, dt),
        _ => 0.0,
    }
}

/// Put the bristle state of `axis` at rest (e.g. after the drive was disabled).
#[no_mangle]
pub extern "C" fn lugre_ff_reset(axis: u32) {
    if let Some(Some(c)) = slot(axis) {
        c.reset();
    }
}

/// The bristle deflection [m] of `axis` (0 when out of range or not initialised).
#[no_mangle]
pub extern "C" fn lugre_ff_state(axis: u32) -> f32 {
    match slot(axis) {
        Some(Some(c)) => c.state(),
        _ => 0.0,
    }
}

/// Firmware has no unwinding: a panic (none is reachable above) stops here.
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
