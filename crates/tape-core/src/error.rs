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
    /// An increment did not converge even after it was cut back to its minimum.
    #[error("no convergence{} at {}: {detail}", in_step(.step), at(*.clock, *.t))]
    NotConverged {
        /// Name of the analysis step, when run by [`crate::analysis::run`].
        step: Option<String>,
        /// Time \[s\] (load factor in static steps) of the last converged state.
        t: f64,
        /// What `t` is.
        clock: Clock,
        /// Newton iterations spent on the last failed attempt.
        iterations: usize,
        /// Residual norm at the last iteration of that attempt \[N\] (NaN if it had none).
        residual: f64,
        /// What was tried and why it failed.
        detail: String,
    },
    /// The analysis would need more memory than the machine has (see [`crate::memory`]).
    #[error("not enough memory: {0}")]
    OutOfMemory(String),
    /// An arc-length path came back onto a stretch it had already followed (it retraces itself,
    /// or closes a loop) and would only repeat it until the step limit.
    #[error("the path returned onto itself{} at load factor {}: {detail}", in_step(.step), at_value(*.t))]
    PathReturned {
        /// Name of the analysis step, when run by [`crate::analysis::run`].
        step: Option<String>,
        /// Time (load factor) of the last state recorded.
        t: f64,
        /// Where, and what to do about it.
        detail: String,
    },
    /// A step ran out of increments before reaching its end.
    #[error(
        "step limit reached{}: {steps} increments brought {} to {}, short of {}; raise the step's max_steps{}",
        in_step(.step),
        clock.name(),
        at_value(*.t),
        at_value(*.target),
        clock.step_hint()
    )]
    StepLimit {
        /// Name of the analysis step, when run by [`crate::analysis::run`].
        step: Option<String>,
        /// Time \[s\] (load factor in static steps) reached.
        t: f64,
        /// What `t` is.
        clock: Clock,
        /// Increments used.
        steps: usize,
        /// Where the step was going.
        target: f64,
    },
}

/// What the `t` of an error is: the time of a dynamic step or the load factor of a static one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// Time \[s\].
    Time,
    /// Load factor of a static step (its time-like parameter).
    LoadFactor,
}

impl Clock {
    /// `"t"` or `"the load factor"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Time => "t",
            Self::LoadFactor => "the load factor",
        }
    }

    /// The other setting that bounds a step's count of increments, for messages.
    #[must_use]
    pub fn step_hint(self) -> &'static str {
        match self {
            Self::Time => " (steps that stay far below max_step point to a motion the time steps cannot follow)",
            Self::LoadFactor => " (or its initial increment)",
        }
    }
}

/// A time or load factor for a message: seven significant digits, in their shortest form.
fn at_value(t: f64) -> String {
    shown(format!("{t:.6e}").parse().unwrap_or(t))
}

fn at(clock: Clock, t: f64) -> String {
    match clock {
        Clock::Time => format!("t = {} s", at_value(t)),
        Clock::LoadFactor => format!("load factor {}", at_value(t)),
    }
}

fn in_step(step: &Option<String>) -> String {
    step.as_ref()
        .map(|s| format!(" in step '{s}'"))
        .unwrap_or_default()
}

impl Error {
    /// The same error with its `t` read as `clock` (a modal step's state keeps the time of the
    /// step before it).
    #[must_use]
    pub fn on_clock(mut self, new: Clock) -> Self {
        if let Self::NotConverged { clock, .. } | Self::StepLimit { clock, .. } = &mut self {
            *clock = new;
        }
        self
    }

    /// The same error, attributed to the analysis step `name`.
    #[must_use]
    pub fn in_step(mut self, name: &str) -> Self {
        if let Self::NotConverged { step, .. } | Self::StepLimit { step, .. } | Self::PathReturned { step, .. } =
            &mut self
        {
            *step = Some(name.to_owned());
        }
        self
    }
}

impl Error {
    /// The same error with `context` prepended to its message (for the variants that carry one).
    #[must_use]
    pub fn context(self, context: &str) -> Self {
        match self {
            Self::InvalidParameter(m) => Self::InvalidParameter(format!("{context}: {m}")),
            Self::InvalidMesh(m) => Self::InvalidMesh(format!("{context}: {m}")),
            Self::InvalidModel(m) => Self::InvalidModel(format!("{context}: {m}")),
            Self::Factorisation(m) => Self::Factorisation(format!("{context}: {m}")),
            Self::OutOfMemory(m) => Self::OutOfMemory(format!("{context}: {m}")),
            other => other,
        }
    }
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Returns `Err(InvalidParameter)` unless `value` is finite and `value > 0`.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter(format!(
            "{name} must be finite and > 0 (got {})",
            shown(value)
        )))
    }
}

/// A number for a message: as written for ordinary magnitudes, in scientific notation for very
/// large or small ones (`{}` would print 1e300 with all its 301 digits).
pub(crate) fn shown(value: f64) -> String {
    let magnitude = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e9).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::{shown, Clock, Error};

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(shown(0.25), "0.25");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-1e-300), "-1e-300");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(0.0), "0");
    }

    #[test]
    fn a_failure_says_whether_it_stopped_at_a_time_or_a_load_factor() {
        let failed = |clock| Error::NotConverged {
            step: None,
            t: 0.123_456_789_123,
            clock,
            iterations: 3,
            residual: 1.0,
            detail: "why".into(),
        };
        let dynamic = failed(Clock::Time).in_step("release").to_string();
        assert_eq!(dynamic, "no convergence in step 'release' at t = 0.1234568 s: why");
        let fold = failed(Clock::Time).on_clock(Clock::LoadFactor).to_string();
        assert_eq!(fold, "no convergence at load factor 0.1234568: why");
        let limit = Error::StepLimit {
            step: None,
            t: 0.5,
            clock: Clock::Time,
            steps: 10,
            target: 1e300,
        };
        assert!(
            limit
                .to_string()
                .contains("brought t to 0.5, short of 1e300;"),
            "{limit}"
        );
    }
}
