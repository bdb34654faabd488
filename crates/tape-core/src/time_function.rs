//! Time functions: how the magnitude of a load or of a prescribed motion evolves with time.
//!
//! A load acts as `value * f(t)`; a prescribed DOF moves by `value * (f(t) - f(t_on))` from where
//! it was when the constraint was switched on. In static steps the load factor plays the role of
//! time, so the default [`TimeFunction::Linear`] (`f(t) = t`) reproduces the classical
//! "load proportional to the load factor".
//!
//! | function   | `f(t)`                                                        |
//! |------------|---------------------------------------------------------------|
//! | `Linear`   | `t`                                                           |
//! | `Constant` | `1`                                                           |
//! | `Ramp`     | `0` for `t <= start`, `1` for `t >= end`, linear in between   |
//! | `Table`    | piecewise linear through `(t_i, f_i)`, constant beyond the ends |

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A scalar function of time (or of the load factor in static steps).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeFunction {
    /// `f(t) = t`: proportional to the load factor (the default).
    #[default]
    Linear,
    /// `f(t) = 1`: a dead load present at all times (gravity, say).
    Constant,
    /// From 0 at `start` to 1 at `end`, constant outside; `end > start`.
    Ramp {
        /// Time at which the ramp leaves 0 [s, or load factor].
        start: f64,
        /// Time at which it reaches 1.
        end: f64,
    },
    /// Piecewise linear through `points = [(t_0, f_0), (t_1, f_1), ...]` (times strictly
    /// increasing), constant before the first and after the last point.
    Table {
        /// `(t_i, f_i)` pairs.
        points: Vec<(f64, f64)>,
    },
}

impl TimeFunction {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for non-finite values, `end <= start`, or a table without
    /// points or with non-increasing times.
    pub fn validate(&self) -> Result<()> {
        let bad = |msg: String| Err(Error::InvalidParameter(msg));
        match self {
            Self::Linear | Self::Constant => Ok(()),
            Self::Ramp { start, end } => {
                if !(start.is_finite() && end.is_finite() && end > start) {
                    return bad(format!(
                        "ramp time function needs finite start < end (got {start}, {end})"
                    ));
                }
                // Its span and slope enter every value and rate: overflowing, they would make the
                // function silently zero, or infinitely steep.
                if !(end - start).is_finite() || !(1.0 / (end - start)).is_finite() {
                    return bad(format!(
                        "ramp time function's span end - start overflows or its slope does (start \
                         {start:e}, end {end:e})"
                    ));
                }
                Ok(())
            }
            Self::Table { points } => {
                if points.is_empty() {
                    return bad("table time function needs at least one point".into());
                }
                if let Some((t, f)) = points
                    .iter()
                    .find(|(t, f)| !(t.is_finite() && f.is_finite()))
                {
                    return bad(format!("table time function has a non-finite point ({t}, {f})"));
                }
                if let Some(w) = points.windows(2).find(|w| w[1].0 <= w[0].0) {
                    return bad(format!(
                        "table time function needs strictly increasing times ({} then {})",
                        w[0].0, w[1].0
                    ));
                }
                if let Some(w) = points.windows(2).find(|w| {
                    let (dt, df) = (w[1].0 - w[0].0, w[1].1 - w[0].1);
                    !(dt.is_finite() && df.is_finite() && (df / dt).is_finite())
                }) {
                    return bad(format!(
                        "table time function's segment from ({:e}, {:e}) to ({:e}, {:e}) has a span \
                         or slope that overflows",
                        w[0].0, w[0].1, w[1].0, w[1].1
                    ));
                }
                Ok(())
            }
        }
    }

    /// `f(t)`.
    #[must_use]
    pub fn value(&self, t: f64) -> f64 {
        match self {
            Self::Linear => t,
            Self::Constant => 1.0,
            Self::Ramp { start, end } => ((t - start) / (end - start)).clamp(0.0, 1.0),
            Self::Table { points } => {
                let i = points.partition_point(|p| p.0 <= t);
                if i == 0 {
                    points[0].1
                } else if i == points.len() {
                    points[i - 1].1
                } else {
                    let (a, b) = (points[i - 1], points[i]);
                    a.1 + (t - a.0) / (b.0 - a.0) * (b.1 - a.1)
                }
            }
        }
    }

    /// One-sided slope `df/dt` at `t` in the direction of travel `direction` (> 0: forward):
    /// the slope of the piece that a step from `t` in that direction starts on.
    #[must_use]
    pub fn derivative(&self, t: f64, direction: f64) -> f64 {
        let forward = direction >= 0.0;
        match self {
            Self::Linear => 1.0,
            Self::Constant => 0.0,
            Self::Ramp { start, end } => {
                let inside = if forward {
                    t >= *start && t < *end
                } else {
                    t > *start && t <= *end
                };
                if inside {
                    1.0 / (end - start)
                } else {
                    0.0
                }
            }
            Self::Table { points } => {
                let i = if forward {
                    points.partition_point(|p| p.0 <= t)
                } else {
                    points.partition_point(|p| p.0 < t)
                };
                if i == 0 || i == points.len() {
                    0.0
                } else {
                    let (a, b) = (points[i - 1], points[i]);
                    (b.1 - a.1) / (b.0 - a.0)
                }
            }
        }
    }

    /// `f(t + dt) - f(t)`; exactly `dt` for [`TimeFunction::Linear`], so that load-factor
    /// increments are not rounded through `t`.
    #[must_use]
    pub fn increment(&self, t: f64, dt: f64) -> f64 {
        match self {
            Self::Linear => dt,
            Self::Constant => 0.0,
            _ => self.value(t + dt) - self.value(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_slopes() {
        let ramp = TimeFunction::Ramp { start: 1.0, end: 3.0 };
        assert_eq!(ramp.value(0.0), 0.0);
        assert_eq!(ramp.value(2.0), 0.5);
        assert_eq!(ramp.value(5.0), 1.0);
        assert_eq!(ramp.derivative(1.0, 1.0), 0.5);
        assert_eq!(ramp.derivative(1.0, -1.0), 0.0);
        assert_eq!(ramp.derivative(3.0, 1.0), 0.0);
        assert_eq!(ramp.derivative(3.0, -1.0), 0.5);
        let table = TimeFunction::Table {
            points: vec![(0.0, 0.0), (1.0, 2.0), (2.0, 2.0), (3.0, 0.0)],
        };
        assert_eq!(table.value(-1.0), 0.0);
        assert_eq!(table.value(0.5), 1.0);
        assert_eq!(table.value(1.5), 2.0);
        assert_eq!(table.value(2.5), 1.0);
        assert_eq!(table.value(9.0), 0.0);
        assert_eq!(table.derivative(1.0, 1.0), 0.0);
        assert_eq!(table.derivative(1.0, -1.0), 2.0);
        assert_eq!(table.derivative(2.5, 1.0), -2.0);
        assert_eq!(table.increment(0.5, 1.0), 1.0);
        assert_eq!(TimeFunction::Linear.increment(0.1, 0.2), 0.2);
        assert_eq!(TimeFunction::Constant.value(7.0), 1.0);
    }

    #[test]
    fn derivative_matches_finite_differences_away_from_kinks() {
        let functions = [
            TimeFunction::Linear,
            TimeFunction::Constant,
            TimeFunction::Ramp { start: -0.5, end: 0.7 },
            TimeFunction::Table {
                points: vec![(0.0, 1.0), (0.4, -1.0), (1.0, 3.0)],
            },
        ];
        for f in &functions {
            for t in [-1.0, 0.1, 0.3, 0.6, 2.0] {
                let h = 1e-6;
                let fd = (f.value(t + h) - f.value(t - h)) / (2.0 * h);
                assert!((fd - f.derivative(t, 1.0)).abs() < 1e-6, "{f:?} at {t}");
                assert!((fd - f.derivative(t, -1.0)).abs() < 1e-6, "{f:?} at {t}");
            }
        }
    }

    #[test]
    fn invalid_functions_are_refused() {
        assert!(TimeFunction::Ramp { start: 1.0, end: 1.0 }
            .validate()
            .is_err());
        assert!(TimeFunction::Ramp {
            start: f64::NAN,
            end: 1.0
        }
        .validate()
        .is_err());
        assert!(TimeFunction::Table { points: vec![] }.validate().is_err());
        assert!(TimeFunction::Table {
            points: vec![(0.0, 0.0), (0.0, 1.0)]
        }
        .validate()
        .is_err());
        assert!(TimeFunction::Table {
            points: vec![(0.0, f64::INFINITY)]
        }
        .validate()
        .is_err());
    }
}
