//! One error type for the crate: every fallible public function returns [`Result`].

/// Errors reported by tape-core. Messages name the offending item (node, element, parameter).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scalar parameter is outside its admissible range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The mesh is unusable (degenerate or inverted element, bad index, NaN coordinate ...).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// The model set-up is inconsistent (unknown node set, missing constraint, no load ...).
    #[error("invalid model: {0}")]
    InvalidModel(String),
    /// The sparse factorisation failed (singular tangent: a mechanism or an unconstrained rigid-body mode).
    #[error("factorisation failed: {0}")]
    Factorisation(String),
    /// Newton iterations did not converge even after the increment was cut back to its minimum.
    #[error(
        "no convergence at load factor {lambda:.6e} after {iterations} iterations (residual {residual:.3e}); {detail}"
    )]
    NotConverged {
        /// Load factor (or time) of the last converged state.
        lambda: f64,
        /// Newton iterations spent on the failed attempt.
        iterations: usize,
        /// Residual norm at the last iteration [N].
        residual: f64,
        /// What was tried.
        detail: String,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Returns `Err(InvalidParameter)` unless `value` is finite and `value > 0`.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter(format!(
            "{name} must be finite and > 0 (got {value})"
        )))
    }
}
