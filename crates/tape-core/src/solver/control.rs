//! Step-size control shared by the static and dynamic drivers: the increment grows or shrinks
//! towards a target Newton effort, is halved on rejection, and gives up after a number of
//! successive halvings or once it is below round-off.

use serde::{Deserialize, Serialize};

/// Adaptive increment: `size` is a load-factor increment, an arc length or a time step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepController {
    /// Current (signed) increment.
    pub size: f64,
    /// Largest magnitude of the increment.
    pub max_size: f64,
    /// Smallest magnitude worth trying (below it the increment is lost in round-off).
    pub min_size: f64,
    /// Newton iterations aimed at per increment.
    pub target_iterations: usize,
    /// Successive rejections allowed before giving up.
    pub max_cutbacks: usize,
    /// Successive rejections so far.
    pub cutbacks: usize,
}

/// Why the controller gives up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GiveUp {
    /// `max_cutbacks` successive rejections.
    Cutbacks,
    /// The increment fell below `min_size`.
    RoundOff,
}

impl StepController {
    /// Controller starting at `size`, never larger than `max_size` in magnitude.
    #[must_use]
    pub fn new(size: f64, max_size: f64, min_size: f64, target_iterations: usize, max_cutbacks: usize) -> Self {
        Self {
            size,
            max_size,
            min_size,
            target_iterations,
            max_cutbacks,
            cutbacks: 0,
        }
    }

    /// An increment converged in `iterations`: the next one grows or shrinks by
    /// `sqrt(target / iterations)`, within [1/2, 2], up to `max_size`.
    pub fn accept(&mut self, iterations: usize) {
        #[allow(clippy::cast_precision_loss)]
        let ratio = (self.target_iterations as f64 / iterations.max(1) as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        self.size = self.size.signum() * (self.size.abs() * ratio).min(self.max_size);
        self.cutbacks = 0;
    }

    /// An increment failed: halve it, or give up.
    ///
    /// # Errors
    /// [`GiveUp`] after `max_cutbacks` successive halvings, or when the halved increment is below
    /// `min_size`.
    pub fn reject(&mut self) -> Result<(), GiveUp> {
        self.cutbacks += 1;
        if self.cutbacks > self.max_cutbacks {
            return Err(GiveUp::Cutbacks);
        }
        self.size *= 0.5;
        if self.size.abs() < self.min_size {
            return Err(GiveUp::RoundOff);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_shrinks_and_gives_up() {
        let mut c = StepController::new(-0.1, 0.15, 1e-6, 4, 3);
        c.accept(1);
        assert!((c.size + 0.15).abs() < 1e-15, "capped at max_size with its sign");
        c.accept(16);
        assert!((c.size + 0.075).abs() < 1e-15);
        assert!(c.reject().is_ok() && c.reject().is_ok() && c.reject().is_ok());
        assert_eq!(c.reject(), Err(GiveUp::Cutbacks));
        let mut tiny = StepController::new(3e-6, 1.0, 1e-6, 4, 100);
        assert!(tiny.reject().is_ok());
        assert_eq!(tiny.reject(), Err(GiveUp::RoundOff));
    }
}
