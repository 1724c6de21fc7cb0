//! Robust identification (IRLS with Nelder-Mead).
