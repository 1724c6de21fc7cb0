//! The crate's error type: every variant names what is wrong and how to fix it.

use crate::friction::ParamError;

/// Everything that can go wrong in `lugre` (with `std`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A model parameter is out of range.
    #[error("parameter {name} = {value} is invalid: it {requirement}")]
    Parameter {
        /// Path of the parameter, e.g. `friction.positive.vs`.
        name: String,
        /// The offending value.
        value: f64,
        /// What it must satisfy.
        requirement: String,
    },
    /// The model description is malformed (missing key, wrong type, unknown effect).
    #[error("model: {path}: {message}")]
    Model {
        /// Where in the model, e.g. `effects[2].pitch`.
        path: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// An input array is unusable (NaN, wrong length, empty, time not increasing).
    #[error("input {name}: {message}")]
    Input {
        /// The argument, e.g. `t` or `x_ref`.
        name: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The data cannot support the requested estimate.
    #[error("data: {0}")]
    Data(String),
    /// The run was interrupted (Ctrl-C).
    #[error("interrupted")]
    Interrupted,
}

impl From<ParamError> for Error {
    fn from(e: ParamError) -> Self {
        Error::Parameter {
            name: e.name.to_string(),
            value: e.value,
            requirement: e.requirement.to_string(),
        }
    }
}

impl Error {
    /// Shorthand for [`Error::Input`].
    pub fn input(name: &str, message: impl Into<String>) -> Self {
        Error::Input {
            name: name.to_string(),
            message: message.into(),
        }
    }
    /// Shorthand for [`Error::Model`].
    pub fn model(path: &str, message: impl Into<String>) -> Self {
        Error::Model {
            path: path.to_string(),
            message: message.into(),
        }
    }
    /// Shorthand for [`Error::Parameter`] with a free-form name.
    pub fn parameter(name: &str, value: f64, requirement: impl Into<String>) -> Self {
        Error::Parameter {
            name: name.to_string(),
            value,
            requirement: requirement.into(),
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T> = core::result::Result<T, Error>;

/// Check that every element of `a` is finite.
pub fn check_finite(name: &str, a: &[f64]) -> Result<()> {
    if let Some(k) = a.iter().position(|x| !x.is_finite()) {
        return Err(Error::input(
            name,
            format!(
                "element {k} is {} : remove or interpolate non-finite samples",
                a[k]
            ),
        ));
    }
    Ok(())
}

/// Check a time vector: non-empty, finite, strictly increasing.
pub fn check_time(name: &str, t: &[f64]) -> Result<()> {
    if t.is_empty() {
        return Err(Error::input(name, "is empty: give at least one sample"));
    }
    check_finite(name, t)?;
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::input(
            name,
            format!(
                "time is not strictly increasing at element {} ({} after {}): sort the record and drop repeated samples",
                k + 1,
                t[k + 1],
                t[k]
            ),
        ));
    }
    Ok(())
}

/// Check that `a` has the length `n` of `t`.
pub fn check_len(name: &str, a: &[f64], n: usize, of: &str) -> Result<()> {
    if a.len() != n {
        return Err(Error::input(
            name,
            format!(
                "has {} samples but {of} has {n}: give arrays of the same length",
                a.len()
            ),
        ));
    }
    Ok(())
}

/// A per-sample friction `scale` (the `s` of `g`): as long as `of`, finite, positive.
pub fn check_scale(sc: &[f64], n: usize, of: &str) -> Result<()> {
    check_len("scale", sc, n, of)?;
    check_finite("scale", sc)?;
    if let Some(k) = sc.iter().position(|&s| s <= 0.0) {
        return Err(Error::input(
            "scale",
            format!(
                "element {k} is {}: the friction scale must be greater than zero",
                sc[k]
            ),
        ));
    }
    Ok(())
}
